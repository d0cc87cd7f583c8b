"""The XML form of plan files: reading into the located tree, writing, places, safety."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree

from alica.io.build import build_document
from alica.io.dump import document_data
from alica.io.fields import Problems
from alica.io.tree import Node, from_plain
from alica.io.xml_format import _SPECS, read_xml, resolve_scalar, write_xml
from alica.io.yaml_format import read_yaml, write_yaml
from alica.model import Document
from alica.source import Diagnostic, SourceSpan

# --------------------------------------------------------------------------- test documents

#: Every element and key of docs/plan_format.md, with the alternatives the builder accepts.
FULL = """\
alica: 1
imports: [roles.yaml, skills/move_to_position.xml]
predicates:
  - stuck/0
  - {name: found, arity: 1, doc: "a sample was found & <seen>"}
functions: [pos/1, {name: battery, arity: 1}]
skills:
  - name: Attack
    doc: "imported from the ALICA Plan Designer: behaviour Attack (Attack.beh#1402488848841) & <more>"
    capabilities: [arm, camera]
    params:
      - {name: goal, type: str, required: false, default: "", doc: "where to go"}
      - {name: times, type: int}
      - {name: speed, type: float, default: 0.5}
      - {name: careful, type: bool, required: false}
      - {name: label, type: str, default: "0.3"}
      - {name: corner, type: position, default: [0, 1.5]}
      - {name: anything, default: 3}
  - name: Wave
tasks:
  - Default
  - {name: Explore, description: "map the area & look for <samples>"}
  - {name: Transport, description: "line one\\nline two\\n"}
rolesets:
  - name: Impera
    description: the IMPERA team
    default_priority: -0.25
    roles:
      - name: Scout
        description: fast, "light" robot
        requires: [lidar2d, camera]
        priorities: {Default: 0.5, Explore: 0.9, Transport: -1}
      - name: Carrier
        priorities: {Transport: 1}
behaviours:
  - name: DriveToGoal
    description: drive somewhere
    skill: DriveTo
    variables: [goal - position, "?r - robot", plain, {name: speed, type: float}]
    params:
      goal: $goal
      tolerance: 0.3
      text_number: "0.3"
      flag: true
      text_flag: "true"
      nothing: null
      empty: ""
      tilde: "~"
      count: 3
      big: 12345678901234567890
      negative: -1.5e-7
      infinite: .inf
      octal_text: "010"
      date: 2001-12-14
      spaced: " padded "
      corners: [1, 2]
      nested: [[1, "a"], [], "true", null, 2.5, ""]
      none_list: []
      angle: "a < b & c > d"
    pre: "not stuck"
    run: "battery(self) > 0.1"
    post: "dist(pos(self), goal) <= 0.3"
    frequency: 10
  - name: Wait
    skill: Idle
plans:
  - name: Mission
    description: |
      explore, then bring sample a
      to the collection point g
    variables: [a - sample, g, "x - real[-10, 10]", {name: f, type: Frontier, candidates: "frontiers()"}]
    pre: "true"
    run: "not aborted"
    frequency: 2.5
    utility:
      priority_weight: 0.6
      similarity_weight: 0.1
      threshold: 0.05
      summands:
        - {name: Near, weight: 0.3, expression: "1 - min(1, dist(pos(self), pos(a)) / 40)"}
    constraints:
      - name: Spread
        formula: "forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2"
        variables: [f1, f2]
      - {name: Gain, utility: "x < 3 and 2 * x > 1"}
    entry_points:
      - {task: Explore, state: Exploring, min: 1, max: "*"}
      - {task: Transport, state: WaitForSample, min: 1, max: 2, success_required: true}
      - {name: Helper, task: Transport, state: WaitForSample}
    states:
      - name: Exploring
        description: look around
        children: [Explore]
      - name: WaitForSample
        transitions:
          - to: Fetch
            condition: "found(a)"
      - name: Fetch
        children:
          - {ref: DriveToGoal, bind: {goal: "pos(a)", speed: 2, careful: true}}
          - Wait
        transitions:
          - {to: Delivered, condition: "On(a, g) -> done", name: Deliver, sync: Together}
          - {to: Failed, condition: "x < 3 && y > 2"}
          - {to: Exploring}
      - name: Delivered
        kind: success
        post: "On(a, g)"
      - name: Failed
        kind: failure
    synchronisations:
      - name: Together
        transitions: [Deliver, "Fetch->Failed"]
        talk_timeout: 0.05
        sync_timeout: 12
        fail_on_timeout: true
  - name: MoveToObject
    entry_points: [{task: Default, state: Go}]
    states: [{name: Go}]
    signature:
      parameters: ["?r - robot", "?x - sample"]
      precondition: "onground(?x) and handempty(?r)"
      effect: "not onground(?x) and holding(?r, ?x)"
      cost: 2
      duration: 4.5
  - name: Empty
    entry_points: [{task: Default, state: S}]
    states: [{name: S}]
    signature: {}
plantypes:
  - name: Transportation
    description: carry it
    plans: [MoveToObject, Empty]
problems:
  - name: GetObjects
    description: pick things up
    elements: [MoveToObject]
    wait_plan: Wait
    alternative_plan: Empty
    update_time: 0.5
    timeout: 30
    planner: builtin
    objects: ["a - sample", "g - location", r1]
    world: "onground(a) and handempty(r1)"
    goal: "at(a, g)"
"""

#: The first example of docs/plan_format.md.
MISSION = """\
alica: 1
imports: [roles.yaml, skills/move_to_position.yaml]
tasks: [Explore, Transport]
plans:
  - name: Mission
    description: explore, then bring sample a to the collection point g
    entry_points:
      - {task: Explore, state: Exploring, min: 1, max: "*"}
      - {task: Transport, state: WaitForSample, min: 1, max: 2, success_required: true}
    states:
      - name: Exploring
        children: [Explore]
      - name: WaitForSample
        transitions:
          - to: Fetch
            condition: "found(a)"
      - name: Fetch
        children:
          - {ref: MoveToPosition, bind: {goal: "pos(a)"}}
        transitions:
          - {to: Delivered, condition: "On(a, g)"}
      - name: Delivered
        kind: success
"""

#: Builder alternatives: a single task as text, variables as a name: type mapping, numeric text.
ALTERNATIVES = """\
tasks: Default
behaviours:
  - name: B
    skill: S
    variables: {goal: position, speed: ~}
    frequency: "5"
plans:
  - name: P
    entry_points: [{task: Default, state: S, min: "1", max: n, success_required: "yes"}]
    states: [{name: S, kind: Success, children: B}]
"""

DOCUMENTS = {"full": FULL, "mission": MISSION, "alternatives": ALTERNATIVES, "empty": "{}\n"}

#: Hand-written XML in the style of the module docstring, and the same in YAML.
HANDWRITTEN_XML = """\
<?xml version="1.0" encoding="UTF-8"?>
<!-- a mission written by hand -->
<alica version="1" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
       xsi:noNamespaceSchemaLocation="plan.xsd">
  <import href="roles.yaml"/>
  <predicate name="stuck" arity="0" doc="the robot cannot move"/>
  <function name="pos" arity="1"/>
  <skill name="Attack" doc="imported">
    <capability>arm</capability>
    <parameter name="goal" type="str" required="false" default="" doc="where to go"/>
    <parameter name="speed" type="float" default="0.5"/>
    <parameter name="corner" type="position"><default><item>0</item><item>1</item></default></parameter>
    <parameter name="times" type="int"/>
  </skill>
  <task name="Explore" description="map the area"/>
  <task name="Transport"/>
  <roleset name="Impera" default_priority="0">
    <role name="Scout">
      <requires>lidar2d</requires>
      <requires>camera</requires>
      <priority task="Explore" value="0.9"/>
    </role>
  </roleset>
  <behaviour name="DriveToGoal" skill="DriveTo" frequency="10">
    <variable name="goal" type="position"/>
    <param name="goal" value="$goal"/>
    <param name="tolerance" value="0.3"/>
    <param name="label" value="0.3" type="str"/>
    <param name="corners"><item>1</item><item>2</item></param>
    <pre>not stuck</pre>
    <post>dist(pos(self), goal) &lt;= 0.3</post>
  </behaviour>
  <plan name="Mission" frequency="0">
    <description>explore, then bring sample a to g</description>
    <utility priority_weight="0.7" similarity_weight="0.1" threshold="0.1">
      <summand name="Near" weight="0.2">1 - dist(pos(self), pos(a))/40</summand>
    </utility>
    <entrypoint task="Explore" state="Exploring" min="1" max="*"/>
    <entrypoint task="Transport" state="WaitForSample" min="1" max="2" success_required="true"/>
    <state name="Exploring"><child ref="Explore"/></state>
    <state name="WaitForSample">
      <transition to="Fetch"><condition>found(a)</condition></transition>
    </state>
    <state name="Fetch">
      <child ref="DriveToGoal"><bind variable="goal">pos(a)</bind></child>
      <transition to="Delivered" name="Deliver" sync="S">
        <condition><![CDATA[On(a, g) and dist(a, g) < 1]]></condition>
      </transition>
    </state>
    <state name="Delivered" kind="success"/>
    <synchronisation name="S" talk_timeout="0.03" sync_timeout="10" fail_on_timeout="false">
      <transition>Deliver</transition>
    </synchronisation>
  </plan>
  <plantype name="T"><plan>A</plan><plan>B</plan></plantype>
  <problem name="GetObjects" wait_plan="Wait" alternative_plan="Alt" update_time="1" timeout="30" planner="builtin">
    <element>MoveToObject</element>
    <object name="a" type="sample"/>
    <world>onground(a)</world>
    <goal>On(a, g)</goal>
  </problem>
</alica>
"""

HANDWRITTEN_YAML = """\
imports: [roles.yaml]
predicates: [{name: stuck, arity: 0, doc: the robot cannot move}]
functions: [pos/1]
skills:
  - name: Attack
    doc: imported
    capabilities: [arm]
    params:
      - {name: goal, type: str, required: false, default: "", doc: where to go}
      - {name: speed, type: float, default: 0.5}
      - {name: corner, type: position, default: [0, 1]}
      - {name: times, type: int}
tasks: [{name: Explore, description: map the area}, Transport]
rolesets:
  - name: Impera
    roles: [{name: Scout, requires: [camera, lidar2d], priorities: {Explore: 0.9}}]
behaviours:
  - name: DriveToGoal
    skill: DriveTo
    frequency: 10
    variables: [goal - position]
    params: {goal: $goal, tolerance: 0.3, label: "0.3", corners: [1, 2]}
    pre: not stuck
    post: dist(pos(self), goal) <= 0.3
plans:
  - name: Mission
    description: explore, then bring sample a to g
    utility:
      priority_weight: 0.7
      similarity_weight: 0.1
      summands: [{name: Near, weight: 0.2, expression: "1 - dist(pos(self), pos(a))/40"}]
    entry_points:
      - {task: Explore, state: Exploring, min: 1}
      - {task: Transport, state: WaitForSample, min: 1, max: 2, success_required: true}
    states:
      - {name: Exploring, children: [Explore]}
      - {name: WaitForSample, transitions: [{to: Fetch, condition: found(a)}]}
      - name: Fetch
        children: [{ref: DriveToGoal, bind: {goal: pos(a)}}]
        transitions: [{to: Delivered, name: Deliver, sync: S, condition: "On(a, g) and dist(a, g) < 1"}]
      - {name: Delivered, kind: success}
    synchronisations: [{name: S, transitions: [Deliver]}]
plantypes: [{name: T, plans: [A, B]}]
problems:
  - name: GetObjects
    elements: [MoveToObject]
    wait_plan: Wait
    alternative_plan: Alt
    timeout: 30
    objects: [a - sample]
    world: onground(a)
    goal: On(a, g)
"""

# --------------------------------------------------------------------------- helpers


def from_yaml(text: str, path: str = "doc.yaml") -> Document:
    """Build a document from YAML text; no problem allowed."""
    tree, diagnostics = read_yaml(textwrap.dedent(text), path)
    assert not diagnostics and tree is not None, [d.format() for d in diagnostics]
    problems = Problems()
    doc = build_document(tree, path, problems)
    assert not problems, [p.format() for p in problems.items]
    return doc


def from_xml(text: str | bytes, path: str = "doc.xml") -> Document:
    """Build a document from XML text; no problem allowed."""
    tree, diagnostics = read_xml(text, path)
    assert not diagnostics and tree is not None, [d.format() for d in diagnostics]
    problems = Problems()
    doc = build_document(tree, path, problems)
    assert not problems, [p.format() for p in problems.items]
    return doc


def from_data(data: dict[str, Any], path: str = "data") -> Document:
    """Build a document from plain data; no problem allowed."""
    problems = Problems()
    doc = build_document(from_plain(data, SourceSpan(path, 1, 1)), path, problems)
    assert not problems, [p.format() for p in problems.items]
    return doc


def xml_problems(text: str, path: str = "doc.xml") -> list[Diagnostic]:
    """Everything the reader and the builder report for an XML text."""
    tree, diagnostics = read_xml(text, path)
    problems = Problems()
    problems.items.extend(diagnostics)
    if tree is not None:
        build_document(tree, path, problems)
    return problems.items


def one_problem(text: str, words: str) -> Diagnostic:
    """The single problem whose message contains ``words``."""
    found = [p for p in xml_problems(text) if words in p.message]
    assert len(found) == 1, [p.format() for p in xml_problems(text)]
    return found[0]


def nodes(node: Node) -> list[Node]:
    """Every node of a tree."""
    out = [node]
    if isinstance(node.value, dict):
        for child in node.value.values():
            out += nodes(child)
    elif isinstance(node.value, list):
        for child in node.value:
            out += nodes(child)
    return out


def typed(value: Any) -> Any:
    """A value with its type spelled out (``1 == 1.0 == True`` in plain equality)."""
    if isinstance(value, (list, tuple)):
        return ("list", [typed(v) for v in value])
    return (type(value).__name__, value)


def params_of(doc: Document) -> list[Any]:
    return [(b.name, [(p.name, typed(p.value)) for p in b.params]) for b in doc.behaviours]


def file_char(text: str, span: SourceSpan) -> str:
    """The character of ``text`` at a span (1-based line and column)."""
    return text.split("\n")[span.line - 1][span.column - 1]


def where(text: str, needle: str) -> tuple[int, int]:
    """1-based line and column of the first ``needle`` in ``text``."""
    index = text.index(needle)
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


def round_trip(doc: Document) -> Document:
    return from_xml(write_xml(document_data(doc)))


# --------------------------------------------------------------------------- coverage of the fixtures


def _keys(node: Node, out: set[str], skip: bool = False) -> set[str]:
    if isinstance(node.value, dict):
        for key, child in node.value.items():
            if not skip:
                out.add(key)
            _keys(child, out, skip=key in ("params", "priorities", "bind"))
    elif isinstance(node.value, list):
        for child in node.value:
            _keys(child, out)
    return out


def test_the_full_fixture_uses_every_key_of_the_vocabulary() -> None:
    tree, _ = read_yaml(FULL, "full.yaml")
    assert tree is not None
    used = _keys(tree, set())
    vocabulary = set()
    for spec in _SPECS.values():
        vocabulary |= {spec.key_of(a) for a in spec.attributes} | {c.key for c in spec.children}
        vocabulary |= {spec.content} if spec.content else set()
    assert vocabulary - used == set()


def test_the_written_full_fixture_uses_every_tag() -> None:
    root = etree.fromstring(write_xml(document_data(from_yaml(FULL))).encode())
    written = {el.tag for el in root.iter()}
    tags = {"alica", "item"} | {c.tag for spec in _SPECS.values() for c in spec.children}
    assert tags - written == set()


# --------------------------------------------------------------------------- round trips


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_xml_round_trip_gives_an_equal_document(name: str) -> None:
    doc = from_yaml(DOCUMENTS[name])
    again = round_trip(doc)
    assert again == doc
    assert params_of(again) == params_of(doc)


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_yaml_to_xml_to_yaml(name: str) -> None:
    doc = from_yaml(DOCUMENTS[name])
    via_xml = from_xml(write_xml(document_data(doc)))
    back = from_yaml(write_yaml(document_data(via_xml)))
    assert back == doc
    assert params_of(back) == params_of(doc)
    assert document_data(back) == document_data(doc)


@pytest.mark.parametrize("name", sorted(DOCUMENTS))
def test_writing_is_stable(name: str) -> None:
    text = write_xml(document_data(from_yaml(DOCUMENTS[name])))
    assert write_xml(document_data(from_xml(text))) == text


def test_handwritten_xml_reads_like_the_same_yaml() -> None:
    assert from_xml(HANDWRITTEN_XML) == from_yaml(HANDWRITTEN_YAML)
    assert params_of(from_xml(HANDWRITTEN_XML)) == params_of(from_yaml(HANDWRITTEN_YAML))


def test_the_reader_gives_the_yaml_tree_shape() -> None:
    tree, _ = read_xml(HANDWRITTEN_XML, "h.xml")
    assert tree is not None
    plain = tree.plain()
    assert plain["imports"] == ["roles.yaml"]
    assert plain["rolesets"][0]["roles"][0]["requires"] == ["lidar2d", "camera"]
    assert plain["rolesets"][0]["roles"][0]["priorities"] == {"Explore": "0.9"}
    assert plain["behaviours"][0]["params"] == {"goal": "$goal", "tolerance": 0.3, "label": "0.3", "corners": [1, 2]}
    assert plain["behaviours"][0]["variables"] == [{"name": "goal", "type": "position"}]
    assert plain["plans"][0]["states"][2]["children"] == [{"ref": "DriveToGoal", "bind": {"goal": "pos(a)"}}]
    assert plain["plans"][0]["utility"]["summands"] == [
        {"name": "Near", "weight": "0.2", "expression": "1 - dist(pos(self), pos(a))/40"}
    ]
    assert plain["alica"] == "1"


def test_written_xml_has_header_and_two_space_indent() -> None:
    text = write_xml(document_data(from_yaml(MISSION)))
    lines = text.splitlines()
    assert lines[0] == '<?xml version="1.0" encoding="UTF-8"?>'
    assert lines[1] == '<alica version="1">'
    assert lines[2] == '  <import href="roles.yaml"/>'
    assert '    <entrypoint task="Explore" state="Exploring" min="1"/>' in lines
    assert lines[-1] == "</alica>" and text.endswith("\n")


def test_formulas_with_angle_brackets_are_written_as_cdata() -> None:
    text = write_xml(document_data(from_yaml(FULL)))
    assert "<post><![CDATA[dist(pos(self), goal) <= 0.3]]></post>" in text
    assert "<pre>not stuck</pre>" in text


def test_multiline_descriptions_are_elements_and_kept_exactly() -> None:
    doc = from_yaml(FULL)
    text = write_xml(document_data(doc))
    assert "<description>explore, then bring sample a\nto the collection point g\n</description>" in text
    assert from_xml(text).plans[0].description == "explore, then bring sample a\nto the collection point g\n"


def test_text_that_xml_would_normalise_survives() -> None:
    data = {
        "tasks": [
            {"name": "T", "description": "tab\there, cr\r\nand lone\r and ]]> and <&>"},
            {"name": "U", "description": "  spaced  "},
        ],
        "behaviours": [{"name": "B", "skill": "S", "pre": "a\r\nb <= c", "params": {"p": "x\ry", "q": ["\r", " "]}}],
    }
    doc = from_data(data)
    again = round_trip(doc)
    assert again == doc and params_of(again) == params_of(doc)


@pytest.mark.parametrize(
    "path", sorted((Path(__file__).resolve().parents[2] / "plans").rglob("*.yaml")), ids=lambda p: p.name
)
def test_shipped_plans_round_trip(path: Path) -> None:
    tree, diagnostics = read_yaml(path.read_text(encoding="utf-8"), str(path))
    problems = Problems()
    assert tree is not None and not diagnostics, [d.format() for d in diagnostics]
    doc = build_document(tree, str(path), problems)
    assert not problems, [d.format() for d in problems.items]
    assert round_trip(doc) == doc


# --------------------------------------------------------------------------- parameter values


def test_param_values_are_typed_like_yaml() -> None:
    xml = """\
<alica>
  <behaviour name="B" skill="S">
    <param name="number" value="0.3"/>
    <param name="text" value="0.3" type="str"/>
    <param name="flag" value="true"/>
    <param name="flag_text" value="true" type="str"/>
    <param name="yes" value="yes"/>
    <param name="int" value="7"/>
    <param name="null"/>
    <param name="null_text" value="null"/>
    <param name="empty" value="" type="str"/>
    <param name="plain" value="hello"/>
    <param name="from_text">0.5</param>
    <param name="list"><item>1</item><item type="str">1</item><item value="x"/><item/></param>
    <param name="empty_list" type="list"/>
  </behaviour>
</alica>
"""
    xml_doc = from_xml(xml)
    yaml_doc = from_yaml(
        """\
        behaviours:
          - name: B
            skill: S
            params:
              number: 0.3
              text: "0.3"
              flag: true
              flag_text: "true"
              yes: yes
              int: 7
              null:
              null_text: null
              empty: ""
              plain: hello
              from_text: 0.5
              list: [1, "1", x, null]
              empty_list: []
        """
    )
    assert xml_doc == yaml_doc
    assert params_of(xml_doc) == params_of(yaml_doc)
    values = xml_doc.behaviours[0].param_map
    assert values["number"] == 0.3 and isinstance(values["number"], float)
    assert values["text"] == "0.3"
    assert values["flag"] is True and values["flag_text"] == "true"


@pytest.mark.parametrize(
    ("value", "written"),
    [
        ("0.3", 'value="0.3" type="str"'),
        (0.3, 'value="0.3"/>'),
        ("true", 'value="true" type="str"'),
        (True, 'value="true"/>'),
        ("", 'value="" type="str"'),
        ("~", 'value="~" type="str"'),
        ("hello", 'value="hello"/>'),
        (1e20, 'value="1.0e+20"/>'),
        (-math.inf, 'value="-.inf"/>'),
        (None, '<param name="p"/>'),
        ([], 'type="list"/>'),
    ],
)
def test_the_writer_marks_text_that_would_resolve(value: Any, written: str) -> None:
    doc = from_data({"behaviours": [{"name": "B", "skill": "S", "params": {"p": value}}]})
    text = write_xml(document_data(doc))
    assert written in text
    assert params_of(from_xml(text)) == params_of(doc)


@pytest.mark.parametrize(
    "scalar",
    [
        "0.3",
        "1e3",
        "1.0e+3",
        "true",
        "True",
        "yes",
        "off",
        "~",
        "null",
        "010",
        "0x1F",
        "1_000",
        "1:30",
        ".inf",
        "-.inf",
        "2001-12-14",
        "hello",
        "$goal",
        "0o17",
        "+1",
        "-0",
    ],
)
def test_resolve_scalar_agrees_with_the_yaml_reader(scalar: str) -> None:
    tree, problems = read_yaml(f"v: {scalar}\n", "s.yaml")
    assert tree is not None and not problems
    expected = tree.value["v"].value  # type: ignore[index]
    assert typed(resolve_scalar(scalar)) == typed(expected)


@given(st.floats(allow_nan=False))
def test_written_floats_resolve_to_themselves(number: float) -> None:
    doc = from_data({"behaviours": [{"name": "B", "skill": "S", "params": {"p": number}}]})
    assert params_of(from_xml(write_xml(document_data(doc)))) == params_of(doc)


def test_unknown_value_type_is_reported() -> None:
    text = '<alica><behaviour name="B" skill="S"><param name="p" value="1" type="float"/></behaviour></alica>'
    problem = one_problem(text, "unknown value type")
    assert problem.span.column == text.index("float") + 1


# --------------------------------------------------------------------------- places


def test_every_node_has_a_place() -> None:
    for text in (HANDWRITTEN_XML, write_xml(document_data(from_yaml(FULL)))):
        tree, problems = read_xml(text, "p.xml")
        assert tree is not None and not problems
        for node in nodes(tree):
            assert node.span.file == "p.xml"
            assert node.span.line >= 1 and node.span.column >= 1
            for span in node.key_spans.values():
                assert span.line >= 1 and span.column >= 1


def test_elements_and_attributes_are_located_exactly() -> None:
    text = '<alica>\n  <task name="A"/>\n  <plan\n      name="P"\n   frequency="2">\n    <entrypoint task="A" state="S"/>\n  </plan>\n</alica>\n'
    tree, problems = read_xml(text, "f.xml")
    assert tree is not None and not problems
    task = tree.value["tasks"].value[0]  # type: ignore[index]
    assert (task.span.line, task.span.column) == (2, 3)
    assert (task.key_span("name").line, task.key_span("name").column) == (2, 9)
    plan = tree.value["plans"].value[0]  # type: ignore[index]
    assert (plan.span.line, plan.span.column) == (3, 3)
    assert (plan.key_span("name").line, plan.key_span("name").column) == (4, 7)
    assert (plan.value["name"].span.line, plan.value["name"].span.column) == (4, 13)
    assert (plan.key_span("frequency").line, plan.key_span("frequency").column) == (5, 4)
    ep = plan.value["entry_points"].value[0]
    assert (ep.span.line, ep.span.column) == (6, 5)


@pytest.mark.parametrize("line_end", ["\n", "\r\n", "\r"], ids=["lf", "crlf", "cr"])
def test_every_kind_of_line_end_gives_the_same_places(line_end: str) -> None:
    lines = [
        "<alica>",
        '  <task name="A"',
        '     colour="x"/>',
        '  <plan name="P">',
        "    <pre>a</pre>",
        "    <pre>b</pre>",
        "  </plan>",
        "</alica>",
        "",
    ]
    problems = xml_problems(line_end.join(lines))
    assert sorted(
        (p.span.line, p.span.column) for p in problems if "colour" in p.message or "duplicate" in p.message
    ) == [(3, 6), (6, 5)]
    tree, syntax = read_xml(line_end.join(lines[:5] + ["  <pre>x < 3</pre>"] + lines[6:]), "s.xml")
    assert tree is None and syntax[0].span.line == 6


def test_places_fall_back_to_the_source_line(monkeypatch: pytest.MonkeyPatch) -> None:
    import alica.io.xml_format as xml_format

    monkeypatch.setattr(xml_format, "_scan_tags", lambda text: [])
    text = '<alica>\n  <task name="A"/>\n  <plan\n      name="P"\n   frequency="2">\n    <entrypoint task="A" state="S"/>\n  </plan>\n</alica>\n'
    tree, problems = read_xml(text, "f.xml")
    assert tree is not None and not problems
    plan = tree.value["plans"].value[0]  # type: ignore[index]
    assert (plan.span.line, plan.span.column) == (3, 3)
    assert (plan.key_span("name").line, plan.key_span("name").column) == (4, 7)
    assert (plan.key_span("frequency").line, plan.key_span("frequency").column) == (5, 4)
    for node in nodes(tree):
        assert node.span.line >= 1 and node.span.column >= 1


def test_places_survive_comments_cdata_and_non_ascii() -> None:
    text = (
        "<!-- <task name='fake'/> -->\n<alica><!-- x --><task name=\"Größe\" description='日本 &lt;&amp;>'/>"
        '<![CDATA[<task>]]>\n  <task name="B"/></alica>'
    )
    tree, diagnostics = read_xml(text, "c.xml")
    assert tree is not None
    tasks = tree.value["tasks"].value  # type: ignore[index]
    assert (tasks[0].span.line, tasks[0].span.column) == (2, 18)
    assert (tasks[1].span.line, tasks[1].span.column) == (3, 3)
    assert any("not allowed directly inside <alica>" in d.message for d in diagnostics)


def test_unknown_attribute_is_reported_by_the_builder_with_its_line() -> None:
    text = '<alica>\n  <task name="A"\n        colour="red"/>\n</alica>\n'
    problem = one_problem(text, "unknown key 'colour'")
    assert problem.message == "unknown key 'colour' in task 'A'"
    assert (problem.span.line, problem.span.column) == (3, 9)


def test_unknown_element_is_reported_by_the_builder_with_its_line() -> None:
    text = """\
<alica>
  <plan name="P">
    <entrypoint task="T" state="S"/>
    <state name="S"/>
    <colour shade="dark">red</colour>
    <stat name="X"/>
  </plan>
</alica>
"""
    colour = one_problem(text, "unknown key 'colour'")
    assert (colour.span.line, colour.span.column) == (5, 5)
    stat = one_problem(text, "unknown key 'stat'")
    assert (stat.span.line, stat.span.column) == (6, 5)
    assert "state" in stat.hint  # the builder's 'did you mean'
    text_lost = one_problem(text, "text 'red'")
    assert text_lost.span.line == 5


def test_misspelt_attribute_gets_a_suggestion() -> None:
    problem = one_problem(
        '<alica><plan name="P" frequncy="1"><entrypoint task="T" state="S"/><state name="S"/></plan></alica>',
        "frequncy",
    )
    assert "frequency" in problem.hint


def test_unknown_attributes_on_text_and_entry_elements_are_reported() -> None:
    text = """\
<alica>
  <roleset name="R">
    <role name="A">
      <requires level="2">camera</requires>
      <priority task="T" value="0.5" weight="1"/>
    </role>
  </roleset>
  <behaviour name="B" skill="S">
    <param name="p" value="1" unit="m"/>
    <pre lang="en">x</pre>
  </behaviour>
</alica>
"""
    assert one_problem(text, "'level'").span.line == 4
    assert one_problem(text, "'weight'").span.line == 5
    assert one_problem(text, "'unit'").span.line == 9
    assert one_problem(text, "'lang'").span.line == 10


def test_duplicate_element_is_reported() -> None:
    text = '<alica>\n  <behaviour name="B" skill="S">\n    <pre>a</pre>\n    <pre>b</pre>\n  </behaviour>\n</alica>\n'
    problem = one_problem(text, "duplicate")
    assert problem.message == "duplicate 'pre' in <behaviour> (first given at line 3)"
    assert (problem.span.line, problem.span.column) == (4, 5)
    assert from_xml_lenient(text).behaviours[0].pre.text == "a"  # type: ignore[union-attr]


def from_xml_lenient(text: str) -> Document:
    tree, _ = read_xml(text, "l.xml")
    assert tree is not None
    return build_document(tree, "l.xml", Problems())


def test_attribute_and_element_for_the_same_key_is_a_duplicate() -> None:
    text = '<alica>\n  <task name="T" description="a">\n    <description>b</description>\n  </task>\n</alica>\n'
    assert one_problem(text, "duplicate 'description'").span.line == 3


def test_duplicate_entries_are_reported() -> None:
    text = """\
<alica>
  <roleset name="R"><role name="A">
    <priority task="T" value="0.5"/>
    <priority task="T" value="0.7"/>
  </role></roleset>
  <behaviour name="B" skill="S"><param name="p" value="1"/><param name="p" value="2"/></behaviour>
</alica>
"""
    assert one_problem(text, "duplicate <priority> for 'T'").span.line == 4
    assert one_problem(text, "duplicate <param> for 'p'").span.line == 6


def test_entry_without_its_key_attribute_is_reported() -> None:
    assert one_problem(
        '<alica><roleset name="R"><role name="A"><priority value="1"/></role></roleset></alica>', "no 'task' attribute"
    )


def test_keys_may_be_attributes_or_elements() -> None:
    xml = (
        '<alica><plan name="P"><entrypoint task="T" state="S"/><state><name>S</name>'
        '<transition to="S" condition="go"/></state></plan></alica>'
    )
    yaml_text = "plans: [{name: P, entry_points: [{task: T, state: S}], states: [{name: S, transitions: [{to: S, condition: go}]}]}]\n"
    assert from_xml(xml) == from_yaml(yaml_text)


def test_text_elements_hold_only_text() -> None:
    problem = one_problem(
        '<alica><behaviour name="B" skill="S"><pre>x <b/> y</pre></behaviour></alica>', "holds only text"
    )
    assert "&lt;" in problem.hint


# --------------------------------------------------------------------------- formula places


FORMULAS = """\
<alica>
  <behaviour name="B" skill="S">
    <pre>not   stuck</pre>
    <run>
        battery(self) > 0.1
          and ok(x)
    </run>
    <post><![CDATA[dist(a, b) <= 0.3]]></post>
  </behaviour>
  <plan name="P">
    <utility><summand name="N" weight="0.5"> 1 - f(x)</summand></utility>
    <constraint name="C"><formula>a = b</formula></constraint>
    <entrypoint task="T" state="S"/>
    <state name="S">
      <child ref="B"><bind variable="v">pos(a)</bind></child>
      <transition to="S" condition="  reached(self)"/>
    </state>
  </plan>
</alica>
"""


def test_formula_spans_point_at_the_formula_text() -> None:
    doc = from_xml(FORMULAS)
    behaviour = doc.behaviours[0]
    places = {
        "pre": behaviour.pre.span,  # type: ignore[union-attr]
        "run": behaviour.run.span,  # type: ignore[union-attr]
        "post": behaviour.post.span,  # type: ignore[union-attr]
        "summand": doc.plans[0].utility.summands[0].span,
        "constraint": doc.plans[0].constraints[0].span,
        "bind": doc.plans[0].states[0].children[0].bindings[0].span,
        "condition": doc.plans[0].transitions[0].condition.span,  # type: ignore[union-attr]
    }
    starts = {
        "pre": "not   stuck",
        "run": "battery",
        "post": "dist(a",
        "summand": " 1 - f",
        "constraint": "a = b",
        "bind": "pos(a)",
        "condition": "reached",
    }
    expected = {k: where(FORMULAS, v) for k, v in starts.items()}
    assert expected["run"] == (5, 9) and expected["post"] == (8, 20)
    assert {k: (s.line, s.column) for k, s in places.items()} == expected  # type: ignore[union-attr]
    assert file_char(FORMULAS, places["run"]) == "b" and file_char(FORMULAS, places["post"]) == "d"


@pytest.mark.parametrize("text", [FORMULAS, HANDWRITTEN_XML.replace("&lt;", "<!---->").replace("<!---->=", "=")])
def test_every_column_of_a_text_maps_to_its_file_column(text: str) -> None:
    tree, _ = read_xml(text, "f.xml")
    assert tree is not None
    checked = 0
    for node in nodes(tree):
        if isinstance(node.value, str) and node.text_offset is not None:
            for column in range(1, len(node.value) + 1):
                if node.value[column - 1] != "\n":
                    assert file_char(text, node.text_span(column)) == node.value[column - 1]
                    checked += 1
    assert checked > 100


# --------------------------------------------------------------------------- syntax and structure errors


def test_syntax_error_has_the_place_lxml_reports_and_a_hint() -> None:
    text = '<alica>\n  <behaviour name="B" skill="S">\n    <pre>x < 3</pre>\n  </behaviour>\n</alica>\n'
    tree, problems = read_xml(text, "s.xml")
    assert tree is None and len(problems) == 1
    problem = problems[0]
    assert problem.message.startswith("XML syntax: ")
    assert problem.span.line == 3 and problem.span.column in (12, 13)
    assert "&lt;" in problem.hint and "CDATA" in problem.hint
    assert problem.format().startswith("s.xml:3:")


@pytest.mark.parametrize(
    ("text", "line", "hint"),
    [
        ('<alica>\n  <task name="A">\n</alica>\n', 3, "close every element"),
        ("<alica>\n  <pre>a & b</pre>\n</alica>", 2, "&amp;"),
        ('<alica>\n  <task name="A" name="B"/>\n</alica>', 2, "once"),
        ("<alica/>\n<alica/>\n", 2, "exactly one <alica>"),
        ("", 1, "start the file"),
        ("   \n", 2, "start the file"),
        ("<alica>\n  <task name=A/>\n</alica>", 2, 'name="value"'),
    ],
)
def test_syntax_errors(text: str, line: int, hint: str) -> None:
    tree, problems = read_xml(text, "s.xml")
    assert tree is None and len(problems) == 1
    assert problems[0].span.line == line
    assert hint in problems[0].hint


def test_the_root_must_be_alica() -> None:
    tree, problems = read_xml('<?xml version="1.0"?>\n<plans><plan name="P"/></plans>', "r.xml")
    assert tree is None
    assert problems[0].message == "the root element must be <alica>, not <plans>"
    assert (problems[0].span.line, problems[0].span.column) == (2, 1)
    tree, problems = read_xml('<alica xmlns="urn:other"/>', "r.xml")
    assert tree is None and "root element" in problems[0].message


def test_version_attribute_is_checked_by_the_builder() -> None:
    problem = one_problem('<alica version="2"/>', "format version")
    assert (problem.span.line, problem.span.column) == (1, 17)


def test_bytes_are_decoded_by_bom_or_declaration() -> None:
    latin = '<?xml version="1.0" encoding="ISO-8859-1"?>\n<alica><task name="Größe"/></alica>'.encode("latin-1")
    assert from_xml(latin).tasks[0].name == "Größe"
    utf16 = '<?xml version="1.0" encoding="UTF-16"?><alica><task name="Größe"/></alica>'.encode("utf-16")
    assert from_xml(utf16).tasks[0].name == "Größe"
    assert from_xml('\ufeff<alica><task name="X"/></alica>').tasks[0].name == "X"
    tree, problems = read_xml(b"<alica><task name='\xff'/></alica>", "b.xml")
    assert tree is None and "not valid utf-8" in problems[0].message


def test_a_declared_encoding_in_text_is_harmless() -> None:
    assert from_xml('<?xml version="1.0" encoding="UTF-16"?>\n<alica><task name="é"/></alica>').tasks[0].name == "é"


# --------------------------------------------------------------------------- safety

BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
 <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
 <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
 <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
 <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
 <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<alica><task name="&lol9;" description="&lol9;"/><plan name="&lol9;"><description>&lol9;</description></plan></alica>
"""

XXE = """<?xml version="1.0"?>
<!DOCTYPE alica [<!ENTITY x SYSTEM "file:///etc/passwd">]>
<alica><task name="&x;"/><task name="T"><description>&x;</description></task></alica>
"""


@pytest.mark.parametrize("text", [BILLION_LAUGHS, XXE], ids=["billion-laughs", "xxe"])
def test_entity_attacks_give_a_diagnostic(text: str) -> None:
    tree, problems = read_xml(text, "evil.xml")  # refused before any entity is expanded
    assert tree is None and len(problems) == 1
    assert problems[0].message == "DTDs and entity declarations are not allowed in plan files"
    assert problems[0].span.line == 2
    shown = problems[0].format()
    assert "lollol" not in shown and "root:" not in shown


@pytest.mark.parametrize(
    "text",
    [
        "<!DOCTYPE alica>\n<alica/>",
        '\ufeff<?xml version="1.0"?><!-- c --><!DOCTYPE alica SYSTEM "http://example.com/plan.dtd"><alica/>',
        b'<?xml version="1.0" encoding="UTF-16"?><!DOCTYPE a [<!ENTITY x "y">]><alica>&x;</alica>'.decode().encode(
            "utf-16"
        ),
    ],
)
def test_any_doctype_is_refused(text: str | bytes) -> None:
    tree, problems = read_xml(text, "d.xml")
    assert tree is None and "DTDs" in problems[0].message


def test_undefined_entities_are_never_expanded() -> None:
    tree, problems = read_xml('<alica><task name="&passwd;"/></alica>', "e.xml")
    assert tree is None and "passwd" in problems[0].message
    assert "&amp;" in problems[0].hint


def test_character_references_are_fine() -> None:
    assert from_xml('<alica><task name="a&#60;b&amp;&#x3E;"/></alica>').tasks[0].name == "a<b&>"


# --------------------------------------------------------------------------- the writer's limits


def test_writer_refuses_unknown_keys_and_impossible_text() -> None:
    with pytest.raises(ValueError, match="bogus"):
        write_xml({"bogus": 1})
    with pytest.raises(ValueError, match="colour"):
        write_xml({"plans": [{"name": "P", "colour": "red", "entry_points": [], "states": []}]})
    with pytest.raises(ValueError, match="XML"):
        write_xml({"tasks": [{"name": "bell\x07"}]})


def test_writer_accepts_every_builder_alternative() -> None:
    tree, _ = read_yaml(ALTERNATIVES, "a.yaml")
    assert tree is not None
    doc = from_yaml(ALTERNATIVES)
    assert from_xml(write_xml(tree.plain())) == doc  # type: ignore[arg-type]


# --------------------------------------------------------------------------- never raises

XML_CHARS = st.characters(codec="utf-8", exclude_categories=("Cs", "Cc", "Cn")) | st.sampled_from("\t\n\r")
TAGS = sorted({"alica", "item", "name"} | set(_SPECS) | {c.tag for s in _SPECS.values() for c in s.children})
ATTRIBUTES = sorted(
    {a for s in _SPECS.values() for a in s.attributes} | {"value", "type", "href", "variable", "task", "bogus"}
)
VALUES = st.sampled_from(["", "0.3", "true", "*", "-1", "x", "a - b", "str", "list", " 1 ", "normal", "nan"]) | st.text(
    XML_CHARS, max_size=6
)


def _element(draw_children: st.SearchStrategy[list[Any]]) -> st.SearchStrategy[Any]:
    def make(tag: str, attributes: dict[str, str], text: str | None, children: list[Any], cdata: bool) -> Any:
        el = etree.Element(tag)
        for key, value in attributes.items():
            el.set(key, value)
        if text is not None:
            el.text = etree.CDATA(text) if cdata and "]]>" not in text and "\r" not in text else text
        el.extend(children)
        for child in children:
            child.tail = "\n  "
        return el

    return st.builds(
        make,
        st.sampled_from(TAGS),
        st.dictionaries(st.sampled_from(ATTRIBUTES), VALUES, max_size=3),
        st.none() | st.text(XML_CHARS, max_size=8),
        draw_children,
        st.booleans(),
    )


ELEMENTS = st.recursive(_element(st.just([])), lambda inner: _element(st.lists(inner, max_size=4)), max_leaves=25)


def check_result(result: Any, path: str) -> None:
    """``read_xml``'s contract: (tree or None, diagnostics), located, and buildable."""
    tree, problems = result
    assert isinstance(problems, list) and all(isinstance(p, Diagnostic) for p in problems)
    assert all(p.span.line >= 1 and p.span.column >= 1 for p in problems)
    if tree is None:
        assert problems
        return
    for node in nodes(tree):
        assert node.span.file == path and node.span.line >= 1 and node.span.column >= 1
    build_document(tree, path, Problems())


@given(st.text())
def test_any_text_never_raises(text: str) -> None:
    check_result(read_xml(text, "t.xml"), "t.xml")


@given(st.binary())
def test_any_bytes_never_raise(data: bytes) -> None:
    check_result(read_xml(data, "b.xml"), "b.xml")


ENCODINGS = st.sampled_from(
    ["utf-8", "UTF-16", "latin-1", "ascii", "idna", "punycode", "utf-7", "rot13", "hex", "cp1252", "nope"]
)


@given(ENCODINGS, st.binary(max_size=40) | st.text(max_size=40).map(lambda t: f"<alica>{t}</alica>".encode()))
def test_any_declared_encoding_never_raises(encoding: str, data: bytes) -> None:
    check_result(read_xml(f'<?xml version="1.0" encoding="{encoding}"?>'.encode() + data, "b.xml"), "b.xml")


@given(ELEMENTS, st.booleans())
def test_any_element_tree_never_raises(root: Any, pretty: bool) -> None:
    body = etree.tostring(root, encoding="unicode", pretty_print=pretty)
    check_result(read_xml(body, "e.xml"), "e.xml")
    check_result(read_xml(f"<alica>\n{body}\n</alica>", "e.xml"), "e.xml")


PIECES = st.sampled_from(
    [
        "<alica>",
        "</alica>",
        "<plan name='P'>",
        "</plan>",
        "<pre>",
        "</pre>",
        "<![CDATA[",
        "]]>",
        "<!--",
        "-->",
        "&lt;",
        "&",
        "<",
        ">",
        '"',
        "=",
        "<?pi x?>",
        "<!DOCTYPE a>",
        "\n",
        " ",
        "x",
        "é",
        "<task name='a' ",
        "/>",
        "<param name='p'>",
        "<item>",
        "</item>",
        "&#0;",
        "&#x10FFFF;",
        "\r\n",
    ]
)


@given(st.lists(PIECES, max_size=30).map("".join))
def test_any_xml_like_text_never_raises(text: str) -> None:
    check_result(read_xml(text, "x.xml"), "x.xml")


def test_deep_nesting_is_a_diagnostic() -> None:
    deep = "<alica>" + "<x>" * 5000 + "</x>" * 5000 + "</alica>"
    tree, problems = read_xml(deep, "deep.xml")
    assert tree is None and problems


# --------------------------------------------------------------------------- any document round-trips

NAME = (
    st.text(st.characters(codec="utf-8", categories=("L", "N")) | st.sampled_from("_-<>&'\". "), min_size=1, max_size=8)
    .map(str.strip)
    .filter(bool)
)
IDENT = st.from_regex(r"\??[A-Za-z_][A-Za-z0-9_-]{0,5}", fullmatch=True)
TYPE = st.from_regex(r"[A-Za-z_][A-Za-z0-9_-]{0,5}", fullmatch=True)
TEXT = st.text(XML_CHARS, max_size=20)
UNIT = st.floats(0, 1)
#: Finite: the builder refuses infinity in every numeric field with a clear error ("too large"), as it should.
NON_NEGATIVE = st.floats(min_value=0, allow_nan=False, allow_infinity=False)
POSITIVE = st.floats(min_value=0.001, max_value=1e6, allow_nan=False, allow_infinity=False)
TYPED = IDENT | st.tuples(IDENT, TYPE).map(" - ".join) | st.fixed_dictionaries({"name": IDENT}, optional={"type": TYPE})
SCALARS = (
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats(allow_nan=False)
    | TEXT
    | st.sampled_from(
        ["0.3", "true", "", "~", "null", "1_000", "0x1F", "2001-12-14", "<<", "=", " 1", "$goal", "yes", ".inf", "1e3"]
    )
)
PARAM = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=3), max_leaves=6)


def _optional(required: dict[str, Any], **optional: Any) -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries(required, optional=optional)


ROLE = _optional(
    {"name": NAME},
    description=TEXT,
    requires=st.lists(NAME, max_size=3),
    priorities=st.dictionaries(NAME, st.floats(-1, 1), max_size=3),
)
CHILD = NAME | _optional({"ref": NAME}, bind=st.dictionaries(NAME, TEXT, max_size=2))
TRANSITION = _optional({"to": NAME}, name=NAME, condition=TEXT, sync=NAME)
STATE = _optional(
    {"name": NAME},
    kind=st.sampled_from(["normal", "success", "failure"]),
    description=TEXT,
    children=st.lists(CHILD, max_size=3),
    post=TEXT,
    transitions=st.lists(TRANSITION, max_size=2),
)
ENTRY = _optional(
    {"task": NAME},
    name=NAME,
    state=NAME,
    min=st.integers(0, 5),
    max=st.integers(0, 9) | st.just("*"),
    success_required=st.booleans(),
)
PLAN = _optional(
    {
        "name": NAME,
        "entry_points": st.lists(ENTRY, min_size=1, max_size=2),
        "states": st.lists(STATE, min_size=1, max_size=3, unique_by=lambda s: s["name"]),
    },
    description=TEXT,
    variables=st.lists(TYPED, max_size=2),
    pre=TEXT,
    run=TEXT,
    frequency=NON_NEGATIVE,
    utility=_optional(
        {},
        priority_weight=UNIT,
        similarity_weight=UNIT,
        threshold=st.floats(0, 10),
        summands=st.lists(_optional({"name": NAME, "weight": UNIT, "expression": TEXT}), max_size=2),
    ),
    constraints=st.lists(_optional({"name": NAME, "formula": TEXT}, variables=st.lists(IDENT, max_size=2)), max_size=2),
    signature=_optional({}, parameters=st.lists(TYPED, max_size=2), precondition=TEXT, effect=TEXT, cost=NON_NEGATIVE),
    synchronisations=st.lists(
        _optional(
            {"name": NAME, "transitions": st.lists(NAME, min_size=1, max_size=2)},
            talk_timeout=NON_NEGATIVE,
            sync_timeout=NON_NEGATIVE,
            fail_on_timeout=st.booleans(),
        ),
        max_size=2,
    ),
)
#: A default of each parameter type (``None``: no default).
SKILL_DEFAULTS: dict[str, st.SearchStrategy[Any]] = {
    "float": st.floats(allow_nan=False) | st.integers(-5, 5),
    "int": st.integers(),
    "bool": st.booleans(),
    "str": TEXT,
    "object": NAME,
    "position": st.lists(st.floats(-10, 10), min_size=2, max_size=3),
    "pose": st.lists(st.floats(-10, 10), min_size=3, max_size=3),
    "list": st.lists(SCALARS, max_size=3),
    "any": PARAM,
}


@st.composite
def _skill_parameter(draw: st.DrawFn) -> dict[str, Any]:
    kind = draw(st.sampled_from(sorted(SKILL_DEFAULTS)))
    default = draw(st.none() | SKILL_DEFAULTS[kind])
    out: dict[str, Any] = {"name": draw(NAME)}
    if kind != "any" or draw(st.booleans()):
        out["type"] = kind
    if default is not None:
        out["default"] = default
        if draw(st.booleans()):
            out["required"] = False
    elif draw(st.booleans()):
        out["required"] = draw(st.booleans())
    if draw(st.booleans()):
        out["doc"] = draw(TEXT)
    return out


SKILL = _optional(
    {"name": NAME},
    doc=TEXT,
    capabilities=st.lists(NAME, max_size=2),
    params=st.lists(_skill_parameter(), max_size=3, unique_by=lambda p: p["name"]),
)
DOCUMENT_DATA = _optional(
    {},
    imports=st.lists(NAME, max_size=2),
    skills=st.lists(SKILL, max_size=2),
    tasks=st.lists(NAME | _optional({"name": NAME}, description=TEXT), max_size=3),
    rolesets=st.lists(
        _optional(
            {"name": NAME, "roles": st.lists(ROLE, min_size=1, max_size=2)},
            description=TEXT,
            default_priority=st.floats(-1, 1),
        ),
        max_size=2,
    ),
    behaviours=st.lists(
        _optional(
            {"name": NAME, "skill": NAME},
            description=TEXT,
            variables=st.lists(TYPED, max_size=3),
            params=st.dictionaries(NAME, PARAM, max_size=4),
            pre=TEXT,
            run=TEXT,
            post=TEXT,
            frequency=NON_NEGATIVE,
        ),
        max_size=2,
    ),
    plans=st.lists(PLAN, max_size=2),
    plantypes=st.lists(
        _optional({"name": NAME, "plans": st.lists(NAME, min_size=1, max_size=3)}, description=TEXT), max_size=2
    ),
    problems=st.lists(
        _optional(
            {"name": NAME, "elements": st.lists(NAME, min_size=1, max_size=2), "goal": TEXT, "wait_plan": NAME},
            description=TEXT,
            alternative_plan=NAME,
            update_time=st.floats(1e-3, 1e3),
            timeout=st.floats(1e-3, 1e3),
            planner=NAME,
            objects=st.lists(TYPED, max_size=2),
            world=TEXT,
        ),
        max_size=2,
    ),
)


@settings(max_examples=150)
@given(DOCUMENT_DATA)
def test_any_document_round_trips_through_xml(data: dict[str, Any]) -> None:
    doc = from_data(data)
    text = write_xml(document_data(doc))
    again = from_xml(text)
    assert again == doc
    assert params_of(again) == params_of(doc)
    assert from_xml(write_xml(data)) == doc
