"""Declared predicates and functions: unknown names, wrong arities and imports, in YAML and XML."""

from __future__ import annotations

import string
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.io import Loader
from alica.io.xml_format import write_xml
from alica.io.yaml_format import read_yaml
from alica.lang.ast import KEYWORDS
from alica.lang.vocabulary import ENGINE_FACTS
from alica.source import Diagnostic


def plan_yaml(condition: str, head: str = "") -> str:
    """A valid one-plan file whose only transition has ``condition``; ``head`` adds top-level sections."""
    return (
        head
        + "tasks: [T]\n"
        + "plans:\n"
        + "  - name: P\n"
        + "    entry_points: [{task: T, state: A}]\n"
        + "    states:\n"
        + "      - name: A\n"
        + "        transitions:\n"
        + f"          - {{to: B, condition: '{condition}'}}\n"
        + "      - {name: B, kind: success}\n"
    )


def problems(tmp_path: Path, files: dict[str, str], entry: str = "plan.yaml") -> list[Diagnostic]:
    for name, text in files.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    return Loader().check(tmp_path / entry)[1]


def where(text: str, needle: str) -> tuple[int, int]:
    """1-based line and column of the first ``needle`` in ``text``."""
    for number, line in enumerate(text.splitlines(), 1):
        if needle in line:
            return number, line.index(needle) + 1
    raise AssertionError(f"{needle!r} not in the text")


def test_a_misspelt_engine_fact_is_reported_at_its_place_with_a_suggestion(tmp_path: Path) -> None:
    text = plan_yaml("not failed and succeded")
    (found,) = problems(tmp_path, {"plan.yaml": text})
    assert (found.span.line, found.span.column) == where(text, "succeded")
    assert "unknown predicate 'succeded' (did you mean 'succeeded'?)" in found.message


def test_the_engine_facts_need_no_declaration(tmp_path: Path) -> None:
    uses = ["succeeded", "failed", "succeeded(X)", "failed(X)", "elapsed > 2", "alive(self)", "role(self) = Scout"]
    uses += ["in_task(self, T)", "in_state(self, A)"]
    assert problems(tmp_path, {"plan.yaml": plan_yaml(" and ".join(uses))}) == []


def test_an_undeclared_domain_predicate_is_reported(tmp_path: Path) -> None:
    (found,) = problems(tmp_path, {"plan.yaml": plan_yaml("found(a)")})
    assert "unknown predicate 'found'" in found.message
    assert "found/1" in found.hint


def test_an_unknown_function_is_reported_with_the_closest_name(tmp_path: Path) -> None:
    text = plan_yaml("dist(pso(self), pos(a)) < 1", "functions: [pos/1]\n")
    (found,) = problems(tmp_path, {"plan.yaml": text})
    assert "unknown function 'pso' (did you mean 'pos'?)" in found.message
    assert (found.span.line, found.span.column) == where(text, "pso")


def test_a_wrong_arity_is_reported(tmp_path: Path) -> None:
    text = plan_yaml("succeeded and found(a, b)", "predicates: [found/1]\n")
    (found,) = problems(tmp_path, {"plan.yaml": text})
    assert "predicate 'found' takes 1 argument, got 2" in found.message
    assert (found.span.line, found.span.column) == where(text, "found(a, b)")


def test_a_wrong_arity_of_an_engine_fact_and_of_a_registered_predicate(tmp_path: Path) -> None:
    text = plan_yaml("in_state(self) or MaximalDist(a, b)")
    messages = [p.message for p in problems(tmp_path, {"plan.yaml": text})]
    assert any("'in_state' takes 2 arguments, got 1" in m for m in messages)
    assert any("MaximalDist takes 3 arguments, got 2" in m for m in messages)


def test_a_function_is_not_a_truth_value(tmp_path: Path) -> None:
    (found,) = problems(tmp_path, {"plan.yaml": plan_yaml("pos(a)", "functions: [pos/1]\n")})
    assert "is a function, not a predicate" in found.message


def test_symbols_and_bound_variables_are_not_predicates(tmp_path: Path) -> None:
    text = plan_yaml("On(a, g) and forall x in Block: On(x, g) or x", "predicates: [On/2]\n")
    assert problems(tmp_path, {"plan.yaml": text}) == []


def test_a_bare_undeclared_name_where_a_truth_value_is_needed_is_reported(tmp_path: Path) -> None:
    (found,) = problems(tmp_path, {"plan.yaml": plan_yaml("explored", "predicates: [explord/0]\n")})
    assert "unknown predicate 'explored' (did you mean 'explord'?)" in found.message


def test_declarations_are_visible_to_importing_files_only(tmp_path: Path) -> None:
    domain = "predicates:\n  - {name: found, arity: 1, doc: a sample was found}\n"
    files = {"domain.yaml": domain, "plan.yaml": plan_yaml("found(a)", "imports: [domain.yaml]\n")}
    assert problems(tmp_path, files) == []
    # a file does not see what a file importing it declares
    files = {
        "user.yaml": "imports: [plan.yaml]\npredicates: [found/1]\n",
        "plan.yaml": plan_yaml("found(a)"),
    }
    (found,) = problems(tmp_path, files, "user.yaml")
    assert "unknown predicate 'found'" in found.message and found.span.file.endswith("plan.yaml")


def test_declarations_are_visible_through_imports_of_imports(tmp_path: Path) -> None:
    files = {
        "facts.yaml": "predicates: [found/1]\n",
        "middle.yaml": "imports: [facts.yaml]\n",
        "plan.yaml": plan_yaml("found(a)", "imports: [middle.yaml]\n"),
    }
    assert problems(tmp_path, files) == []


def test_xml_declarations_and_an_xml_typo(tmp_path: Path) -> None:
    tree, _ = read_yaml(plan_yaml("found(a) and succeded", "predicates: [found/1]\n"), "p.yaml")
    assert tree is not None
    xml = write_xml(tree.plain())  # type: ignore[arg-type]
    assert '<predicate name="found" arity="1"/>' in xml
    (found,) = problems(tmp_path, {"plan.xml": xml}, "plan.xml")
    assert "unknown predicate 'succeded' (did you mean 'succeeded'?)" in found.message
    assert (found.span.line, found.span.column) == where(xml, "succeded")


def test_an_xml_file_imports_the_declarations_of_a_yaml_file(tmp_path: Path) -> None:
    tree, _ = read_yaml(plan_yaml("holding(self, a)", "imports: [domain.yaml]\n"), "p.yaml")
    assert tree is not None
    files = {"domain.yaml": "predicates: [holding/2]\n", "plan.xml": write_xml(tree.plain())}  # type: ignore[arg-type]
    assert problems(tmp_path, files, "plan.xml") == []


def test_a_name_declared_as_predicate_and_function_is_reported(tmp_path: Path) -> None:
    text = plan_yaml("succeeded", "predicates: [heat/1]\nfunctions: [heat/1]\n")
    (found,) = problems(tmp_path, {"plan.yaml": text})
    assert "'heat' is declared as a predicate" in found.message
    assert found.span.line == 2


def test_a_declaration_that_is_not_name_and_arity_is_reported(tmp_path: Path) -> None:
    text = plan_yaml("succeeded", "predicates: [found, {name: and, arity: 1}, {name: x}]\n")
    messages = [p.message for p in problems(tmp_path, {"plan.yaml": text})]
    assert any("'found' in 'predicates' is not 'name/arity'" in m for m in messages)
    assert any("'and' in 'predicates' is not a name formulas can use" in m for m in messages)
    assert any("has no 'arity'" in m for m in messages)


_ENGINE = {s.name for s in ENGINE_FACTS} | {"self"}
_NAMES = st.text(string.ascii_letters, min_size=1, max_size=8).filter(
    lambda n: n not in KEYWORDS and n not in _ENGINE and n.lower() not in ("y", "n", "yes", "no", "on", "off")
)


@settings(max_examples=30, deadline=None)
@given(name=_NAMES, arity=st.integers(0, 4), extra=st.integers(1, 2))
def test_a_declared_predicate_validates_with_its_arity_only(
    tmp_path_factory: pytest.TempPathFactory, name: str, arity: int, extra: int
) -> None:
    folder = tmp_path_factory.mktemp("decl")
    args = ", ".join(f"o{i}" for i in range(arity))
    use = f"{name}({args})" if arity else name
    head = f"predicates: [{name}/{arity}]\n"
    assert problems(folder, {"plan.yaml": plan_yaml(use, head)}) == []
    wrong = ", ".join(f"o{i}" for i in range(arity + extra))
    (found,) = problems(folder, {"plan.yaml": plan_yaml(f"{name}({wrong})", head)})
    assert f"takes {arity} argument" in found.message


def test_a_skill_registry_declares_the_facts_its_skills_write(tmp_path: Path) -> None:
    from alica.lang.skills import SkillRegistry

    text = plan_yaml("counted(self) and not counted")
    assert any("unknown predicate 'counted'" in p.message for p in problems(tmp_path, {"plan.yaml": text}))
    registry = SkillRegistry()
    registry.declare_predicate("counted", 1, "the agent counted")
    found = Loader(skills=registry).check(tmp_path / "plan.yaml")[1]
    # declared with one argument: the 0-ary use is still wrong
    assert [p.message for p in found] and all("counted" in p.message and "argument" in p.message for p in found)
