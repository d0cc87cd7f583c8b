"""The ``skills:`` section: skills declared as data, checked, converted and handed to the run."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.engine import SkillBinder
from alica.errors import PlanFormatError, UnknownSkillError
from alica.io import Loader, load_document, load_library, validate_paths
from alica.io.fields import Problems
from alica.io.loader import read_text
from alica.io.validate import Validator
from alica.lang import default_registry
from alica.lang.skills import ParamSpec, SkillRegistry
from alica.model import Behaviour, Document, SkillDeclaration, SkillParameter
from alica.source import Diagnostic
from tests.io.helpers import test_skills
from tests.io.test_convert import converted
from tests.io.test_xml_format import from_xml, from_yaml, typed

CATALOGUE = """\
alica: 1
skills:
  - name: Attack
    doc: "imported from the ALICA Plan Designer: behaviour Attack (Attack.beh#1402488848841)"
    capabilities: [arm]
    params:
      - {name: goal, type: str, required: false, default: "", doc: "where to go"}
      - {name: times, type: int}
      - {name: speed, type: float, default: 0.5}
      - {name: corner, type: position, default: [0, 1]}
      - {name: anything, default: 3}
  - name: Wave
"""

CATALOGUE_XML = """\
<?xml version="1.0" encoding="UTF-8"?>
<alica version="1">
  <skill name="Attack" doc="imported from the ALICA Plan Designer: behaviour Attack (Attack.beh#1402488848841)">
    <capability>arm</capability>
    <parameter name="goal" type="str" required="false" default="" doc="where to go"/>
    <parameter name="times" type="int"/>
    <parameter name="speed" type="float" default="0.5"/>
    <parameter name="corner" type="position"><default><item>0</item><item>1</item></default></parameter>
    <parameter name="anything"><default>3</default></parameter>
  </skill>
  <skill name="Wave"/>
</alica>
"""

#: A plan whose behaviour runs a skill a file declares: format with the imported file and the params.
PLAN = """\
alica: 1
imports: [{imports}]
tasks: [Default]
rolesets:
  - name: Crew
    roles:
      - name: Worker
        priorities: {{Default: 0.5}}
behaviours:
  - name: Strike
    skill: Attack
    params: {params}
plans:
  - name: Job
    entry_points:
      - {{task: Default, state: Working, min: 1, max: 1, success_required: true}}
    states:
      - name: Working
        children: [Strike]
        transitions: [{{to: Done, condition: "succeeded"}}]
      - {{name: Done, kind: success}}
"""


@pytest.fixture(autouse=True)
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Work in the test's folder, so messages name files as ``job.yaml``."""
    monkeypatch.chdir(tmp_path)


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def project(folder: Path, params: str = "{times: 2}", catalogue: str = CATALOGUE) -> Path:
    """A folder with ``skills.yaml`` (the catalogue) and ``job.yaml`` (a plan using it); returns the plan."""
    write(folder, "skills.yaml", catalogue)
    return write(folder, "job.yaml", PLAN.format(imports="skills.yaml", params=params))


def formatted(problems: list[Diagnostic]) -> list[str]:
    return [p.format() for p in problems]


def parameters(declaration: SkillDeclaration) -> list[tuple[str, str, bool, Any, str]]:
    return [(p.name, p.type, p.required, typed(p.default), p.doc) for p in declaration.params]


# --------------------------------------------------------------------------- the two forms


def test_the_yaml_form_builds_declarations() -> None:
    attack, wave = from_yaml(CATALOGUE).skills
    assert attack.name == "Attack" and attack.capabilities == frozenset({"arm"})
    assert attack.doc.startswith("imported from the ALICA Plan Designer")
    assert parameters(attack) == [
        ("goal", "str", False, ("str", ""), "where to go"),
        ("times", "int", True, ("NoneType", None), ""),
        ("speed", "float", False, ("float", 0.5), ""),
        ("corner", "position", False, ("list", [("int", 0), ("int", 1)]), ""),
        ("anything", "any", False, ("int", 3), ""),
    ]
    assert wave == SkillDeclaration("Wave")
    assert attack.span is not None and (attack.span.line, attack.span.column) == (3, 5)
    assert attack.params[1].span is not None and attack.params[1].span.line == 8


def test_the_xml_form_reads_like_the_yaml_form() -> None:
    yaml_doc, xml_doc = from_yaml(CATALOGUE), from_xml(CATALOGUE_XML)
    assert xml_doc == yaml_doc
    assert [parameters(s) for s in xml_doc.skills] == [parameters(s) for s in yaml_doc.skills]


@pytest.mark.parametrize(
    ("attribute", "kind", "value"),
    [
        ('default="0.5"', "float", ("float", 0.5)),
        ('default="3"', "float", ("int", 3)),
        ('default="3"', "int", ("int", 3)),
        ('default="yes"', "bool", ("bool", True)),
        ('default="3"', "str", ("str", "3")),
        ('default="true"', "str", ("str", "true")),
        ('default="pos(a)"', "position", ("str", "pos(a)")),
        ('default="3"', "any", ("str", "3")),
        ("><default>3</default></parameter", "any", ("int", 3)),
        ('><default type="str">3</default></parameter', "any", ("str", "3")),
        ('><default type="list"/></parameter', "list", ("list", [])),
    ],
)
def test_an_xml_default_is_read_by_the_parameter_type(attribute: str, kind: str, value: Any) -> None:
    closing = "" if attribute.endswith("parameter") else "/"
    text = f'<alica><skill name="S"><parameter name="p" type="{kind}" {attribute}{closing}></skill></alica>'
    (param,) = from_xml(text).skills[0].params
    assert typed(param.default) == value and not param.required


def test_written_xml_keeps_defaults_as_attributes_where_they_read_back() -> None:
    xml = converted(CATALOGUE, "yaml", "xml")
    assert '<parameter name="goal" type="str" required="false" doc="where to go" default=""/>' in xml
    assert '<parameter name="speed" type="float" default="0.5"/>' in xml
    assert "<default>3</default>" in xml and "<item>0</item>" in xml


@pytest.mark.parametrize("path", ["yaml", "xml"])
def test_convert_keeps_the_section(tmp_path: Path, path: str, capsys: pytest.CaptureFixture[str]) -> None:
    source = write(
        tmp_path, "skills.yaml" if path == "yaml" else "skills.xml", CATALOGUE if path == "yaml" else CATALOGUE_XML
    )
    other = tmp_path / ("out.xml" if path == "yaml" else "out.yaml")
    back = tmp_path / f"back.{path}"
    assert main(["convert", str(source), str(other)]) == 0
    assert main(["convert", str(other), str(back)]) == 0
    capsys.readouterr()
    original, again = load_document(source), load_document(back)
    assert again == original and [parameters(s) for s in again.skills] == [parameters(s) for s in original.skills]
    assert load_document(other) == original


def test_convert_keeps_every_written_default() -> None:
    text = textwrap.dedent(
        """\
        skills:
          - name: S
            doc: ''
            capabilities: [arm]
            params:
              - {name: a, type: any, required: true, doc: ''}
              - {name: b, type: int, required: false, default: 0}
        """
    )
    back = converted(converted(text, "yaml", "xml"), "xml", "yaml")
    assert yaml.safe_load(back) == yaml.safe_load(text)


# --------------------------------------------------------------------------- behaviours use declared skills


def test_a_plan_using_a_declared_skill_validates_and_loads(tmp_path: Path) -> None:
    job = project(tmp_path)
    assert formatted(validate_paths([tmp_path])) == []
    registry = test_skills()
    library = Loader(skills=registry).load(job)
    assert set(library.skills) == {"Attack", "Wave"}
    spec = registry.get("Attack")  # the loader handed the declarations to its registry
    assert spec.implementation is None and spec.declared_at == library.skills["Attack"].span
    assert spec.param("speed") == ParamSpec("speed", "float", required=False, default=0.5)
    assert spec.capabilities == frozenset({"arm"}) and spec.origin.endswith("skills.yaml")


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ("{}", "job.yaml:10:5: error: behaviour 'Strike' does not give required parameter 'times' of skill 'Attack'"),
        (
            "{times: 2, gaol: x}",
            "job.yaml:12:24: error: skill 'Attack' has no parameter 'gaol' (fix: did you mean 'goal'?)",
        ),
        (
            "{times: many}",
            "job.yaml:12:14: error: parameter 'times' of behaviour 'Strike' must be a whole number, not 'many'",
        ),
        (
            "{times: 2, corner: [1]}",
            "job.yaml:12:24: error: parameter 'corner' of behaviour 'Strike' must be a list [x, y]",
        ),
    ],
)
def test_behaviour_params_are_checked_against_a_declared_skill(tmp_path: Path, params: str, message: str) -> None:
    project(tmp_path, params)
    lines = formatted(validate_paths([tmp_path / "job.yaml"]))
    assert any(line.startswith(message) for line in lines), lines


def test_a_declaration_is_visible_only_in_its_document_set(tmp_path: Path) -> None:
    project(tmp_path)
    other = write(tmp_path, "other.yaml", PLAN.format(imports="", params="{times: 2}"))
    loader = Loader(skills=test_skills())
    loader.load(tmp_path / "job.yaml")  # Attack is now in the loader's registry, from skills.yaml
    _, problems = loader.check(other)
    assert any("binds unknown skill 'Attack'" in p.message for p in problems)
    with pytest.raises(PlanFormatError, match="unknown skill 'Attack'"):
        loader.load(other)


def test_a_later_load_replaces_an_earlier_file_declaration(tmp_path: Path) -> None:
    registry = test_skills()
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    load_library(project(first), skills=registry)
    changed = CATALOGUE.replace("{name: times, type: int}", "{name: times, type: float}")
    load_library(project(second, "{times: 2.5}", changed), skills=registry)
    spec = registry.get("Attack")
    assert spec.param("times") == ParamSpec("times", "float") and spec.declared_at is not None
    assert spec.declared_at.file.endswith("b/skills.yaml")


def test_a_python_declaration_wins_over_the_file(tmp_path: Path) -> None:
    registry = test_skills()

    def implementation(name: str, params: Any, context: Any) -> Any:
        raise AssertionError("not built here")

    registry.declare("Attack", ParamSpec("power", "int"), doc="mine", implementation=implementation)
    project(tmp_path, "{power: 3}")
    assert formatted(Loader(skills=registry).check(tmp_path / "job.yaml")[1]) == []
    lines = formatted(Loader(skills=registry).check(project(tmp_path, "{times: 2}"))[1])
    assert any("skill 'Attack' has no parameter 'times'" in line for line in lines), lines
    library = load_library(project(tmp_path, "{power: 3}"), skills=registry)
    assert "Attack" in library.skills  # the file's declaration is still data of the library
    spec = registry.get("Attack")
    assert spec.doc == "mine" and spec.implementation is implementation and spec.declared_at is None


def test_two_files_declaring_one_skill_is_a_located_duplicate(tmp_path: Path) -> None:
    write(tmp_path, "more.yaml", "skills:\n  - name: Wave\n    doc: again\n")
    write(tmp_path, "skills.yaml", CATALOGUE.replace("alica: 1\n", "alica: 1\nimports: [more.yaml]\n"))
    problems = formatted(validate_paths([tmp_path / "skills.yaml"]))
    assert problems == [
        "more.yaml:2:5: error: duplicate name 'Wave': "
        "another skill has it (first at skills.yaml:13:5) "
        "(fix: rename one of them; names must be unique in the files loaded together)"
    ]


def test_one_file_declaring_a_skill_twice_is_a_duplicate() -> None:
    doc, problems = read_text("skills: [{name: A}, {name: A}]\n", "s.yaml")
    assert problems == []
    loader_problems = formatted(_validate(doc))
    assert loader_problems == [
        "s.yaml:1:21: error: duplicate name 'A': another skill has it (first at s.yaml:1:10) "
        "(fix: rename one of them; names must be unique in the files loaded together)"
    ]


def _validate(*documents: Document) -> list[Diagnostic]:
    """The problems the validator finds in ``documents``, checked against the test skills."""
    problems = Problems()
    Validator(list(documents), test_skills(), default_registry(), problems).run()
    return problems.items


def test_a_declaration_made_in_code_that_paramspec_refuses_is_reported() -> None:
    bad = SkillDeclaration("S", (SkillParameter("p", "vector"),), span=None)
    (problem,) = _validate(Document(skills=(bad,)))
    assert "skill 'S': parameter 'p': unknown type 'vector'" in problem.message


# --------------------------------------------------------------------------- malformed entries


#: A malformed entry of ``skills:``; the error is at the first ``at`` in the entry.
MALFORMED = [
    (
        "{name: A, capabilites: [arm]}",
        "capabilites",
        "unknown key 'capabilites' in skill 'A'",
        "did you mean 'capabilities'?",
    ),
    (
        "{name: A, params: [{name: p, defualt: 1}]}",
        "defualt",
        "unknown key 'defualt' in parameter 'p' of skill 'A'",
        "did you mean 'default'?",
    ),
    (
        "{name: A, params: [{name: p, type: flaot}]}",
        "flaot",
        "parameter 'p' of skill 'A' has unknown type 'flaot'",
        "did you mean 'float'?",
    ),
    (
        "{name: A, params: [{name: p, type: vector}]}",
        "vector",
        "parameter 'p' of skill 'A' has unknown type 'vector'",
        "use one of float, int, bool, str, object, position, pose, list, any",
    ),
    ("{doc: nameless}", "{doc", "a skill has no 'name'", "give a skill a 'name'"),
    (
        "{name: A, params: [{type: int}]}",
        "{type",
        "a parameter of skill 'A' has no 'name'",
        "give a parameter of skill 'A' a 'name'",
    ),
    (
        "{name: A, params: [{name: p, type: int, default: x}]}",
        "x}",
        "default of parameter 'p' of skill 'A' must be a whole number, not 'x'",
        "write a default of type int, or remove it",
    ),
    (
        "{name: A, params: [{name: p, type: bool, default: 1}]}",
        "1}",
        "default of parameter 'p' of skill 'A' must be true or false, not 1",
        "write a default of type bool",
    ),
    (
        "{name: A, params: [{name: p, type: float, default: $x}]}",
        "$x",
        "default of parameter 'p' of skill 'A' must be a number, not '$x'",
        "write a default of type float",
    ),
    (
        "{name: A, params: [{name: p, type: list, default: {a: 1}}]}",
        "{a: 1}",
        "default of parameter 'p' of skill 'A' must be a value or a list, not a mapping",
        "write one value",
    ),
    (
        "{name: A, params: [{name: p, required: true, default: 1}]}",
        "1}",
        "parameter 'p' of skill 'A' is required, so it takes no default",
        "write 'required: false' to give it a default, or remove 'default'",
    ),
    (
        "{name: A, params: [{name: p}, {name: p, type: int}]}",
        "{name: p, type",
        "skill 'A' has two parameters named 'p' (the first is at line 2)",
        "give each parameter its own name",
    ),
    (
        "{name: A, params: [p]}",
        "p]",
        "each parameter of skill 'A' must be a mapping with a 'name', not text",
        "write '- {name: goal",
    ),
    (
        "{name: A, params: {p: int}}",
        "{p: int}",
        "'params' of skill 'A' must be a list, not a mapping",
        "write '- {name: goal, type: str}'",
    ),
    (
        "{name: A, capabilities: {arm: 1}}",
        "{arm",
        "'capabilities' of skill 'A' must be a list, not a mapping",
        "list capabilities by name, e.g. [arm]",
    ),
    ("Attack", "Attack", "each entry of 'skills' must be a mapping with a 'name', not text", "write '- name: MySkill'"),
]


@pytest.mark.parametrize(("entry", "at", "message", "hint"), MALFORMED, ids=[m[2][:40] for m in MALFORMED])
def test_a_malformed_entry_is_a_located_error(tmp_path: Path, entry: str, at: str, message: str, hint: str) -> None:
    path = write(tmp_path, "s.yaml", f"alica: 1\nskills: [{entry}]\n")
    with pytest.raises(PlanFormatError) as caught:
        load_library(path, skills=test_skills())
    found = [d for d in caught.value.diagnostics if d.message == message]
    assert found, formatted(list(caught.value.diagnostics))
    column = f"skills: [{entry}]".index(at) + 1
    assert (found[0].span.file, found[0].span.line, found[0].span.column) == (
        "s.yaml",
        2,
        column,
    )
    assert hint in found[0].hint


def test_a_malformed_xml_entry_is_a_located_error() -> None:
    text = (
        '<alica>\n  <skill name="A" colour="red">\n'
        '    <parameter name="p" type="int" defualt="1"/>\n'
        '    <parameter name="q"><default value="1" kind="x"/></parameter>\n  </skill>\n</alica>\n'
    )
    _, problems = read_text(text, "s.xml", "xml")
    assert sorted(formatted(problems)) == [
        "s.xml:2:19: error: unknown key 'colour' in skill 'A' (fix: allowed keys: name, doc, capabilities, params)",
        "s.xml:3:36: error: unknown key 'defualt' in parameter 'p' of skill 'A' (fix: did you mean 'default'?)",
        "s.xml:4:44: error: unknown attribute 'kind' on <default> (fix: <default> takes 'value' and 'type')",
    ]


@settings(max_examples=200)
@given(
    st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=6),
        lambda inner: (
            st.lists(inner, max_size=3)
            | st.dictionaries(
                st.sampled_from(["name", "type", "default", "required", "doc", "params", "capabilities", "x"]),
                inner,
                max_size=4,
            )
        ),
        max_leaves=12,
    )
)
def test_any_skills_section_gives_problems_not_tracebacks(section: Any) -> None:
    text = yaml.safe_dump({"skills": section})
    doc, problems = read_text(text, "s.yaml")
    for p in problems:
        assert p.span.file == "s.yaml" and p.message
    _validate(doc)  # the declarations the builder kept always make valid ParamSpecs


# --------------------------------------------------------------------------- run time


def test_the_skill_binder_says_how_to_bind_an_implementation(tmp_path: Path) -> None:
    registry = test_skills()
    load_library(project(tmp_path), skills=registry)
    binder = SkillBinder(None, registry)
    with pytest.raises(UnknownSkillError) as caught:
        binder.factory(Behaviour("Strike", "Attack"))
    message = str(caught.value)
    assert message.startswith("behaviour 'Strike' cannot run: skill 'Attack' is declared in ")
    assert "skills.yaml:3:5" in message and "--skills MODULE" in message and "--stand-ins" in message
    standin = SkillBinder(None, registry, fallback=lambda behaviour: lambda *args: None)
    assert standin.factory(Behaviour("Strike", "Attack")) is not None
    with pytest.raises(UnknownSkillError, match="skill 'Nope' has no implementation; bind one with --skills MODULE"):
        SkillBinder(None, registry).factory(Behaviour("B", "Nope"))


def test_a_registry_copy_keeps_its_facts() -> None:
    registry = SkillRegistry()
    registry.declare_predicate("seen", 1)
    assert registry.copy().facts.lookup("seen")
