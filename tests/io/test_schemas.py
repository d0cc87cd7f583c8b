"""The shipped schemas: XSD for the XML form, JSON Schema (2020-12) for the YAML form."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from hypothesis import given, settings
from lxml import etree

from alica.io.build import build_document
from alica.io.dump import document_data
from alica.io.fields import Problems
from alica.io.tree import from_plain
from alica.io.xml_format import write_xml
from alica.io.yaml_format import read_yaml
from alica.source import SourceSpan
from tests.io.test_xml_format import (
    DOCUMENT_DATA,
    DOCUMENTS,
    HANDWRITTEN_XML,
    HANDWRITTEN_YAML,
    from_data,
    from_yaml,
)

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "alica" / "io" / "schema"
XSD = etree.XMLSchema(etree.parse(str(SCHEMA_DIR / "plan.xsd")))
JSON_SCHEMA = json.loads((SCHEMA_DIR / "plan.schema.json").read_text(encoding="utf-8"))
VALIDATOR = jsonschema.Draft202012Validator(JSON_SCHEMA)


def xsd_errors(text: str) -> list[str]:
    """The XSD's complaints about an XML text."""
    ok = XSD.validate(etree.fromstring(text.encode("utf-8")))
    return [] if ok else [f"{e.line}: {e.message}" for e in XSD.error_log]


def json_errors(data: Any) -> list[str]:
    """The JSON Schema's complaints about plain data."""
    return [f"{list(e.absolute_path)}: {e.message}" for e in VALIDATOR.iter_errors(data)]


def yaml_plain(text: str) -> Any:
    """YAML text as the plain data the builder sees (dates stay text)."""
    tree, problems = read_yaml(text, "s.yaml")
    assert tree is not None and not problems
    return tree.plain()


def builder_problems(data: Any) -> list[str]:
    problems = Problems()
    build_document(from_plain(data, SourceSpan("s", 1, 1)), "s", problems)
    return [p.message for p in problems.items]


# --------------------------------------------------------------------------- XSD


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_written_xml_validates_against_the_xsd(name: str) -> None:
    assert xsd_errors(write_xml(document_data(from_yaml(DOCUMENTS[name])))) == []


def test_handwritten_xml_validates_against_the_xsd() -> None:
    assert xsd_errors(HANDWRITTEN_XML) == []


@pytest.mark.parametrize(
    "fragment",
    [
        '<plan name="P"><colour/></plan>',
        '<plan name="P"><entrypoint task="T" max="lots"/></plan>',
        '<plan name="P"><state name="S" kind="weird"/></plan>',
        '<plan name="P"><entrypoint state="S"/></plan>',
        '<plan name="P"><pre>a</pre><pre>b</pre></plan>',
        '<plan name="P" frequency="fast"/>',
        '<roleset name="R"><role name="A"><priority task="T" value="high"/></role></roleset>',
        '<behaviour name="B"/>',
        '<behaviour name="B" skill="S"><param name="p" type="float" value="1"/></behaviour>',
        '<task name="T" colour="red"/>',
        "<skill/>",
        '<skill name="S"><parameter name="p" type="vector"/></skill>',
        '<skill name="S"><parameter name="p" required="maybe"/></skill>',
        '<skill name="S"><parameter type="int"/></skill>',
        '<skill name="S"><param name="p"/></skill>',
        '<problem name="P"/>',
        "<whatever/>",
    ],
)
def test_the_xsd_rejects_wrong_documents(fragment: str) -> None:
    assert xsd_errors(f'<alica version="1">{fragment}</alica>')


def test_the_xsd_rejects_another_root_and_version() -> None:
    assert xsd_errors("<plans/>")
    assert xsd_errors('<alica version="2"/>')


@settings(max_examples=60)
@given(DOCUMENT_DATA)
def test_any_written_document_validates_against_the_xsd(data: dict[str, Any]) -> None:
    assert xsd_errors(write_xml(document_data(from_data(data)))) == []


# --------------------------------------------------------------------------- JSON Schema


def test_the_json_schema_is_a_valid_2020_12_schema() -> None:
    assert JSON_SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(JSON_SCHEMA)


def test_element_mappings_take_no_additional_keys() -> None:
    objects = [d for d in JSON_SCHEMA["$defs"].values() if d.get("type") == "object"]
    objects += [
        b
        for d in JSON_SCHEMA["$defs"].values()
        for b in d.get("anyOf", [])
        if b.get("type") == "object" and "properties" in b
    ]
    assert len(objects) >= 16
    assert all(o["additionalProperties"] is False for o in objects)
    assert JSON_SCHEMA["additionalProperties"] is False


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_yaml_documents_and_their_dumps_validate(name: str) -> None:
    assert json_errors(yaml_plain(DOCUMENTS[name])) == []
    assert json_errors(document_data(from_yaml(DOCUMENTS[name]))) == []


def test_handwritten_yaml_validates() -> None:
    assert json_errors(yaml_plain(HANDWRITTEN_YAML)) == []


ALTERNATIVES = """\
alica: "1"
imports: roles.yaml
skills: [{name: S, capabilities: arm, params: [{name: p, type: float, required: "no", default: "0.5"}, {name: q}]}]
tasks: Default
behaviours:
  - name: B
    skill: S
    variables: {goal: position, speed: ~}
    params: {a: [1, [2, "x"]], b: null}
    pre: true
    frequency: "10"
plans:
  - name: P
    variables: "?r - robot"
    utility: ~
    entry_points:
      - {task: Default, state: S, min: "1", max: "*", success_required: "yes"}
      - {task: Other, state: S, max: 3}
      - {task: Third, state: S, max: n}
      - {task: Fourth, state: S, max: .inf}
    states:
      - {name: S, kind: Success, children: B}
      - name: T
        children: [B, {ref: P, bind: {x: 1, y: true, z: "pos(a)"}}]
    constraints: [{name: C, formula: "a = b", variables: f1}]
    signature: {parameters: {r: robot}, cost: "2.5"}
    synchronisations: [{name: Y, transitions: "S->T"}]
plantypes: [{name: T, plans: P}]
problems:
  - {name: O, elements: P, wait_plan: P, goal: false, objects: ["a - sample", {name: b}]}
"""


def test_the_json_schema_accepts_every_builder_alternative() -> None:
    data = yaml_plain(ALTERNATIVES)
    assert builder_problems(data) == []
    assert json_errors(data) == []


@pytest.mark.parametrize(
    ("case", "data"),
    [
        ("unknown section", {"plan": []}),
        ("unknown plan key", {"plans": [{"name": "P", "entry_points": [], "states": [], "colour": "red"}]}),
        ("max not a number", {"plans": [{"name": "P", "entry_points": [{"task": "T", "max": "lots"}], "states": []}]}),
        ("variables a number", {"behaviours": [{"name": "B", "skill": "S", "variables": 3}]}),
        ("bad typed name", {"behaviours": [{"name": "B", "skill": "S", "variables": ["a b c"]}]}),
        ("state kind", {"plans": [{"name": "P", "entry_points": [], "states": [{"name": "S", "kind": "weird"}]}]}),
        ("missing states", {"plans": [{"name": "P", "entry_points": []}]}),
        ("param value a mapping", {"behaviours": [{"name": "B", "skill": "S", "params": {"p": {"x": 1}}}]}),
        ("priority not a number", {"rolesets": [{"name": "R", "roles": [{"name": "A", "priorities": {"T": "high"}}]}]}),
        ("task without name", {"tasks": [{"description": "x"}]}),
        (
            "flag",
            {"plans": [{"name": "P", "entry_points": [{"task": "T", "success_required": "maybe"}], "states": []}]},
        ),
        ("version", {"alica": 2}),
        (
            "child without ref",
            {"plans": [{"name": "P", "entry_points": [], "states": [{"name": "S", "children": [{"bind": {}}]}]}]},
        ),
        ("negative min", {"plans": [{"name": "P", "entry_points": [{"task": "T", "min": -1}], "states": []}]}),
        ("skill without name", {"skills": [{"doc": "x"}]}),
        ("unknown skill key", {"skills": [{"name": "S", "capabilites": ["arm"]}]}),
        ("unknown parameter type", {"skills": [{"name": "S", "params": [{"name": "p", "type": "vector"}]}]}),
        ("skill params a mapping", {"skills": [{"name": "S", "params": {"p": "int"}}]}),
        ("parameter without name", {"skills": [{"name": "S", "params": [{"type": "int"}]}]}),
        ("parameter default a mapping", {"skills": [{"name": "S", "params": [{"name": "p", "default": {"a": 1}}]}]}),
    ],
)
def test_the_json_schema_rejects_what_the_builder_rejects(case: str, data: Any) -> None:
    assert json_errors(data), case
    assert builder_problems(data), case


def test_the_json_schema_follows_the_docs_on_wait_plans() -> None:
    assert json_errors({"problems": [{"name": "O", "elements": ["P"], "goal": "g"}]})


@settings(max_examples=60)
@given(DOCUMENT_DATA)
def test_any_document_validates_against_the_json_schema(data: dict[str, Any]) -> None:
    assert json_errors(data) == []
    assert json_errors(document_data(from_data(data))) == []
