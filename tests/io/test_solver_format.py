"""The solver's part of the plan format (issue 15): typed variables with ranges and candidates,
constraints with a utility, per-agent reads ``v(a)`` over ``agents(E)``, in YAML and XML."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.io import load_document, validate_paths
from alica.io.dump import document_data
from alica.io.reads import agent_domains, reads
from alica.lang import parse
from alica.model import Behaviour, Constraint, Document, Variable
from alica.source import Diagnostic
from tests.conftest import PLANS
from tests.io.helpers import problems_of
from tests.io.test_convert import converted
from tests.io.test_xml_format import from_xml, from_yaml

VARIABLES_YAML = """\
tasks: [T]
plans:
  - name: P
    variables:
      - x - real[-10, 10]
      - k - int[0, 5]
      - p - point[-5, 5]
      - frontier - Frontier
      - v
      - {name: y, type: real, range: [-1.5, 2.25]}
      - {name: f, type: Frontier, candidates: "frontiers()"}
      - {name: z, type: real, min: 0, max: 1e3}
    constraints:
      - {name: Hard, formula: "x > 0", variables: [x]}
      - {name: Both, formula: "x < k", utility: "x + k", variables: [x, k]}
      - name: Gain
        utility: "sum a in agents(S): dist(p(a), p(a))"
    entry_points: [{task: T, state: S, min: 2}]
    states: [{name: S}]
"""

VARIABLES_XML = """\
<alica version="1">
  <task name="T"/>
  <plan name="P">
    <variable name="x" type="real" min="-10" max="10"/>
    <variable name="k" type="int" min="0" max="5"/>
    <variable name="p" type="point" min="-5" max="5"/>
    <variable name="frontier" type="Frontier"/>
    <variable name="v"/>
    <variable name="y" type="real" min="-1.5" max="2.25"/>
    <variable name="f" type="Frontier" candidates="frontiers()"/>
    <variable name="z" type="real" min="0" max="1000"/>
    <constraint name="Hard"><variable>x</variable><formula>x &gt; 0</formula></constraint>
    <constraint name="Both" utility="x + k">
      <variable>x</variable><variable>k</variable>
      <formula><![CDATA[x < k]]></formula>
    </constraint>
    <constraint name="Gain">
      <utility>sum a in agents(S): dist(p(a), p(a))</utility>
    </constraint>
    <entrypoint task="T" state="S" min="2"/>
    <state name="S"/>
  </plan>
</alica>
"""

EXPECTED_VARIABLES = (
    Variable("x", "real", -10.0, 10.0),
    Variable("k", "int", 0.0, 5.0),
    Variable("p", "point", -5.0, 5.0),
    Variable("frontier", "Frontier"),
    Variable("v"),
    Variable("y", "real", -1.5, 2.25),
    Variable("f", "Frontier", candidates="frontiers()"),
    Variable("z", "real", 0.0, 1000.0),
)
EXPECTED_CONSTRAINTS = (
    Constraint("Hard", "x > 0", ("x",)),
    Constraint("Both", "x < k", ("x", "k"), "x + k"),
    Constraint("Gain", "", (), "sum a in agents(S): dist(p(a), p(a))"),
)


# --------------------------------------------------------------------------- reading


def test_yaml_forms_give_the_model() -> None:
    plan = from_yaml(VARIABLES_YAML).plans[0]
    assert plan.variables == EXPECTED_VARIABLES
    assert plan.constraints == EXPECTED_CONSTRAINTS
    assert [v.numeric for v in plan.variables] == [True, True, True, False, False, True, False, True]
    assert [v.object_type for v in plan.variables] == [False, False, False, True, False, False, True, False]


def test_xml_forms_give_the_same_model() -> None:
    assert from_xml(VARIABLES_XML) == from_yaml(VARIABLES_YAML)


def test_name_type_mapping_takes_a_range() -> None:
    doc = from_yaml("behaviours: [{name: B, skill: S, variables: {spot: 'point[-5, 5]', goal: position, any: ~}}]")
    assert doc.behaviours[0].variables == (
        Variable("spot", "point", -5.0, 5.0),
        Variable("goal", "position"),
        Variable("any"),
    )


def test_spans_point_at_each_formula() -> None:
    plan = from_yaml(VARIABLES_YAML).plans[0]
    both = plan.constraints[1]
    assert (both.span.line, both.span.column) == (15, 32)
    assert both.utility_span is not None and (both.utility_span.line, both.utility_span.column) == (15, 50)
    xml_both = from_xml(VARIABLES_XML).plans[0].constraints[1]
    assert xml_both.utility_span is not None and (xml_both.utility_span.line, xml_both.utility_span.column) == (13, 38)


def test_written_yaml_uses_the_short_forms() -> None:
    data = document_data(from_yaml(VARIABLES_YAML))
    plan = data["plans"][0]
    assert plan["variables"][:6] == [
        "x - real[-10, 10]",
        "k - int[0, 5]",
        "p - point[-5, 5]",
        "frontier - Frontier",
        "v",
        "y - real[-1.5, 2.25]",
    ]
    assert plan["variables"][6] == {"name": "f", "type": "Frontier", "candidates": "frontiers()"}
    assert plan["constraints"][2] == {"name": "Gain", "utility": "sum a in agents(S): dist(p(a), p(a))"}


@pytest.mark.parametrize(
    "first,second", [("yaml", "xml"), ("xml", "yaml"), ("yaml", "yaml"), ("xml", "xml")], ids=lambda f: f
)
def test_convert_round_trip_keeps_everything(first: str, second: str) -> None:
    text = VARIABLES_YAML if first == "yaml" else VARIABLES_XML
    there = converted(text, first, second)
    back = converted(there, second, first)
    original = from_yaml(text) if first == "yaml" else from_xml(text)
    again = from_yaml(back) if first == "yaml" else from_xml(back)
    assert again == original
    assert again.plans[0].variables == EXPECTED_VARIABLES
    assert again.plans[0].constraints == EXPECTED_CONSTRAINTS


def test_alica_convert_yaml_xml_yaml(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = tmp_path / "p.yaml"
    source.write_text(VARIABLES_YAML.replace("tasks: [T]", "tasks: [T]\nfunctions: [frontiers/0]"), encoding="utf-8")
    assert main(["convert", str(source), str(tmp_path / "p.xml")]) == 0
    xml_text = (tmp_path / "p.xml").read_text(encoding="utf-8")
    assert '<variable name="x" type="real" min="-10" max="10"/>' in xml_text
    assert 'candidates="frontiers()"' in xml_text and "<utility>x + k</utility>" in xml_text
    assert main(["convert", str(tmp_path / "p.xml"), str(tmp_path / "back.yaml")]) == 0
    capsys.readouterr()
    assert load_document(tmp_path / "back.yaml").plans == load_document(source).plans
    back = yaml.safe_load((tmp_path / "back.yaml").read_text(encoding="utf-8"))
    assert back["plans"][0]["variables"][0] == "x - real[-10, 10]"


# --------------------------------------------------------------------------- structural problems


def _build_messages(text: str) -> list[str]:
    return [p.format() for p in problems_of(text) if "unknown skill" not in p.message]


@pytest.mark.parametrize(
    "entry,where,fragment",
    [
        ('"x - real[a, 1]"', "5:19", "bound 'a' of variable 'x'"),
        ('"x - real[0, 1, 2]"', "5:19", "must be two numbers [low, high]"),
        ("{name: x, type: real, range: [0]}", "5:38", "'range' of variable 'x'"),
        ("{name: x, type: real, range: [0, 1], min: 0}", "5:38", "both 'range' and 'min'/'max'"),
        ("{name: x, type: real, min: low, max: 1}", "5:36", "bound 'low' of variable 'x'"),
        ('"x - real"', "5:9", "has no range"),
        ('"x = real[0, 1]"', "5:9", "is not 'name', 'name - type' or 'name - type[low, high]'"),
    ],
)
def test_bad_variable_declarations_are_located(entry: str, where: str, fragment: str) -> None:
    text = f"""\
    tasks: [T]
    plans:
      - name: P
        variables:
          - {entry}
        entry_points: [{{task: T, state: S}}]
        states: [{{name: S}}]
    """
    found = [m for m in _build_messages(text) if m.startswith(f"doc.yaml:{where}: error: ")]
    assert any(fragment in m for m in found), _build_messages(text)


def test_a_constraint_needs_a_formula_or_a_utility() -> None:
    text = """\
    tasks: [T]
    plans:
      - name: P
        constraints: [{name: Empty, variables: []}]
        entry_points: [{task: T, state: S}]
        states: [{name: S}]
    """
    messages = _build_messages(text)
    assert any(
        m.startswith("doc.yaml:4:19: error: constraint 'Empty' of plan 'P' has neither 'formula' nor 'utility'")
        for m in messages
    ), messages


# --------------------------------------------------------------------------- validation

PLAN = """\
tasks: [T]
functions: [gain/1]
behaviours:
  - {{name: Go, skill: Idle, variables: [{child}]}}
plans:
  - name: P
    variables:
      - {variable}
      - q - point[-5, 5]
      - f - Frontier
    constraints:
      - {{name: C, {key}: "{formula}"}}
    entry_points: [{{name: E, task: T, state: S, min: 1}}]
    states: [{{name: S, children: [{{ref: Go, bind: {{spot: {bound}}}}}]}}]
"""

OK = {"child": "spot", "variable": "x - real[0, 1]", "key": "formula", "formula": "x > 0", "bound": "q"}

#: (what is changed, where the error is, a fragment of its message)
VALIDATION_CASES = [
    ({"variable": "x - real[10, -10]"}, "8:9", "the range [10, -10] of variable 'x' of plan 'P' is empty"),
    ({"variable": "x - real[0, .inf]"}, "8:9", "of variable 'x' of plan 'P' is not finite"),
    ({"variable": "x - real[nan, 1]"}, "8:9", "is not finite"),
    ({"variable": "x - point"}, "8:9", "variable 'x' of plan 'P' has no range"),
    ({"variable": "x - int[0.5, 2]"}, "8:9", "has a fraction"),
    ({"variable": "x - reel[0, 1]"}, "8:9", "its type 'reel' is not real, int or point"),
    ({"variable": "{name: x, type: 're al'}"}, "8:9", "has unknown type 're al'"),
    ({"variable": "{name: x, type: real, range: [0, 1], candidates: 'xs()'}"}, "8:9", "has candidates, but"),
    ({"variable": "{name: x, type: Frontier, candidates: 'frontiers('}"}, "8:9", "candidates 'frontiers(' of"),
    (
        {"formula": "forall a in agents(Ss): f(a) == f(a)"},
        "12:48",
        "agents(Ss) names no entry point, task or state of the plan",
    ),
    ({"formula": "forall a in agents(S): x(a) > 0 and x > 0"}, "12:65", "variable 'x' is read as 'x' here"),
    ({"formula": "forall a in agents(E): spot(a) == f(a)"}, "12:52", "reads per-agent variable 'spot'"),
    ({"formula": "x + 1"}, "12:29", "'x + 1' is an arithmetic expression, not a truth value"),
    ({"formula": "sum a in agents(T): gain(f(a))"}, "12:29", "is a sum, a number, not a truth value"),
    (
        {"key": "utility", "formula": "x > 0"},
        "12:29",
        "utility of constraint 'C' of plan 'P': 'x > 0' is a truth value",
    ),
    ({"key": "utility", "formula": "gains(x)"}, "12:29", "unknown function 'gains'"),
    ({"formula": "frontierness(x)"}, "12:29", "unknown predicate 'frontierness'"),
    ({"child": '"spot - real[0, 1]"'}, "14:58", "'spot' of 'Go' is real, but 'q' of plan 'P' is point"),
]


@pytest.mark.parametrize("change,where,fragment", VALIDATION_CASES, ids=[c[2][:40] for c in VALIDATION_CASES])
def test_each_validation_error_is_located(change: dict[str, str], where: str, fragment: str) -> None:
    text = PLAN.format(**{**OK, **change})
    problems = [p for p in problems_of(text) if "unknown skill" not in p.message]
    at = [p.format() for p in problems if f"{p.span.line}:{p.span.column}" == where]
    assert any(fragment in line for line in at), [p.format() for p in problems]
    assert all(p.hint for p in problems)


def test_the_unchanged_plan_is_valid() -> None:
    assert [p.format() for p in problems_of(PLAN.format(**OK)) if "unknown skill" not in p.message] == []


@pytest.mark.parametrize(
    "formula",
    [
        "forall a, b in agents(E): a == b or MaximalDist(f(a), f(b), 4.0)",
        "forall a in agents(S): MinimalDist(f(a), a, 15.0)",
        "forall a in agents(T): dist(q(a), q(a)) <= 3 and x > 0",
    ],
)
def test_per_agent_reads_over_entry_points_tasks_and_states_are_valid(formula: str) -> None:
    text = PLAN.format(**{**OK, "formula": formula})
    assert [p.format() for p in problems_of(text) if "unknown skill" not in p.message] == []


def test_untyped_bindings_of_any_type_are_valid() -> None:
    text = PLAN.format(**{**OK, "child": "spot", "bound": "f"})
    assert [p.format() for p in problems_of(text) if "unknown skill" not in p.message] == []


def test_a_mixed_read_is_reported_across_constraints() -> None:
    text = PLAN.format(**OK).replace(
        '      - {name: C, formula: "x > 0"}',
        '      - {name: C, formula: "x > 0"}\n      - {name: D, utility: "sum a in agents(S): x(a)"}',
    )
    found = [p.format() for p in problems_of(text) if "read as" in p.message]
    assert len(found) == 1 and found[0].startswith("doc.yaml:13:49: error: ") and "at doc.yaml:12:29" in found[0]


def test_errors_in_xml_are_located_too() -> None:
    text = VARIABLES_XML.replace('min="-10" max="10"', 'min="10" max="-10"').replace(
        "sum a in agents(S)", "sum a in agents(Q)"
    )
    problems = [p.format() for p in _validate_xml(text)]
    assert any(p.startswith("doc.xml:4:5: error: the range [10, -10] of variable 'x'") for p in problems), problems
    assert any(
        p.startswith("doc.xml:18:32: error: utility of constraint 'Gain'") and "agents(Q)" in p for p in problems
    )


def _validate_xml(text: str) -> list[Diagnostic]:
    from alica.io.fields import Problems
    from alica.io.loader import read_text
    from alica.io.validate import Validator
    from alica.lang import default_registry
    from tests.io.helpers import test_skills

    doc, diagnostics = read_text(text, "doc.xml", "xml")
    problems = Problems()
    problems.items.extend(diagnostics)
    Validator([doc], test_skills(), default_registry(), problems).run()
    return sorted(problems.items)


# --------------------------------------------------------------------------- reads


def test_reads_tell_static_from_per_agent_and_skip_bound_names() -> None:
    text = "forall a in agents(E), x in T: f(a) > x and g(x) > y and exists b in agents(S): h(b) > 0"
    found = {(r.name, r.per_agent, r.of_agent) for r in reads(parse(text))}
    assert found == {("f", True, True), ("g", True, False), ("y", False, False), ("h", True, True)}
    assert [(d.name, d.column) for d in agent_domains(parse(text), text)] == [("E", 20), ("S", 77)]


# --------------------------------------------------------------------------- hypothesis

NAMES = st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True)
OBJECT_TYPES = st.from_regex(r"[A-Z][A-Za-z0-9]{0,6}", fullmatch=True)
BOUNDS = st.floats(allow_nan=False, allow_infinity=False, width=64) | st.integers(-(10**6), 10**6).map(float)


@st.composite
def declarations(draw: st.DrawFn) -> Variable:
    name = draw(NAMES)
    kind = draw(st.sampled_from(["real", "int", "point", "any", "object"]))
    if kind == "object":
        candidates = draw(st.none() | st.sampled_from(["frontiers()", "cells(self, 2.5)"]))
        return Variable(name, draw(OBJECT_TYPES), candidates=candidates)
    if kind == "any":
        return Variable(name)
    low, high = sorted((draw(BOUNDS), draw(BOUNDS)))
    if kind == "int":
        low, high = float(math.floor(low)), float(math.floor(high))
    return Variable(name, kind, low, high)


def _long(v: Variable) -> dict[str, object]:
    """The long form ``{name, type, range, candidates}``."""
    out: dict[str, object] = {"name": v.name}
    if v.type != "any":
        out["type"] = v.type
    if v.low is not None:
        out["range"] = [v.low, v.high]
    if v.candidates is not None:
        out["candidates"] = v.candidates
    return out


@settings(max_examples=120)
@given(st.lists(declarations(), min_size=1, max_size=5, unique_by=lambda v: v.name), st.booleans())
def test_variable_declarations_round_trip(variables: list[Variable], long_form: bool) -> None:
    """Random declarations written in YAML (long form, or the dumper's short forms) -> model -> XML -> model."""
    if long_form:
        data: dict[str, object] = {
            "behaviours": [{"name": "B", "skill": "S", "variables": [_long(v) for v in variables]}]
        }
    else:
        data = document_data(Document(behaviours=(Behaviour("B", "S", variables=tuple(variables)),)))
    text = yaml.safe_dump(data, sort_keys=False)
    read = from_yaml(text)
    assert read.behaviours[0].variables == tuple(variables)
    xml_text = converted(text, "yaml", "xml")
    assert from_xml(xml_text) == read
    assert from_yaml(converted(xml_text, "xml", "yaml")) == read


# --------------------------------------------------------------------------- shipped plans


def test_shipped_solver_plans_validate() -> None:
    problems = validate_paths([PLANS / "skills" / "explore.yaml", PLANS / "examples" / "formation.yaml"])
    assert not problems, "\n".join(p.format() for p in problems)


def test_explore_states_eq_7_8_per_agent() -> None:
    plan = next(p for p in load_document(PLANS / "skills" / "explore.yaml").plans if p.name == "Explore")
    assert plan.variables == (Variable("frontier", "Frontier", candidates="having(Frontier, gain)"),)
    by_name = {c.name: c for c in plan.constraints}
    assert set(by_name) == {"SpreadFrontiers", "NearbyFrontiers", "GainOverTravel", "KeepFrontier"}
    spread = parse(by_name["SpreadFrontiers"].text)
    assert {r.name for r in reads(spread) if r.per_agent and r.of_agent} == {"frontier"}
    assert {d.name for d in agent_domains(spread, by_name["SpreadFrontiers"].text)} == {
        "ExploreFrontiers",
        "ExploreAfterMapping",
    }
    utility = by_name["GainOverTravel"].utility
    assert by_name["GainOverTravel"].text == "" and "gain(frontier(a)) - dist(frontier(a), a)" in utility


def test_formation_example_has_a_per_agent_point() -> None:
    doc = load_document(PLANS / "examples" / "formation.yaml")
    plan = doc.plans[0]
    assert Variable("spot", "point", -5.0, 5.0) in plan.variables
    assert plan.entry_points[0].min == 2 and math.isinf(plan.entry_points[0].max)
    assert doc.behaviours[0].skill == "MoveToPosition"
    assert [(p.name, p.value) for p in doc.behaviours[0].params if p.name == "goal"] == [("goal", "$spot")]
    for c in plan.constraints:
        for text in (c.text, c.utility):
            if text:
                assert {d.name for d in agent_domains(parse(text), text)} == {"Hold"}
                assert any(r.name == "spot" and r.per_agent for r in reads(parse(text)))


def test_examples_are_package_data() -> None:
    from alica.io.loader import plans_dir

    assert (plans_dir() / "examples" / "formation.yaml").is_file()
    assert "*/*.yaml" in Path(PLANS.parent / "pyproject.toml").read_text(encoding="utf-8")
