"""Reading YAML into the located tree and building documents from it."""

from __future__ import annotations

import math

from alica.io.loader import read_text
from alica.io.yaml_format import read_yaml
from alica.model import StateKind
from tests.io.helpers import document


def test_places_are_kept() -> None:
    tree, problems = read_yaml("plans:\n  - name: P\n", "f.yaml")
    assert not problems and tree is not None
    item = tree.value["plans"].value[0]
    assert (item.span.line, item.span.column) == (2, 5)
    assert item.key_span("name").column == 5


def test_duplicate_keys_are_errors_not_silently_dropped() -> None:
    _, problems = read_yaml("a: 1\nb: 2\na: 3\n", "f.yaml")
    assert [p.format() for p in problems] == [
        "f.yaml:3:1: error: duplicate key 'a' (first written at line 1) (fix: remove one of them; YAML would silently keep only the last)"
    ]


def test_syntax_error_has_a_place() -> None:
    tree, problems = read_yaml("plans: [\n  a: b\n", "f.yaml")
    assert tree is None
    assert problems[0].span.file == "f.yaml" and problems[0].span.line >= 2
    assert "YAML syntax" in problems[0].message


def test_alias_bombs_are_capped() -> None:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    for i in range(1, 9):
        prev = f"*a{i - 1}"
        lines.append(f"a{i}: &a{i} [{', '.join([prev] * 10)}]")
    tree, problems = read_yaml("\n".join(lines) + "\n", "bomb.yaml")
    assert tree is None
    assert "expands to more than" in problems[0].message


def test_multiple_documents_rejected() -> None:
    _, problems = read_yaml("tasks: [A]\n---\ntasks: [B]\n", "f.yaml")
    assert "more than one YAML document" in problems[0].message


def test_full_plan_builds() -> None:
    doc = document("""\
    tasks: [Default]
    plans:
      - name: P
        variables: [goal - position, speed]
        entry_points:
          - {task: Default, state: A, min: 1, max: "*", success_required: yes}
        states:
          - name: A
            children: [{ref: Q, bind: {x: "pos(a)"}}]
            transitions: [{to: B, condition: "succeeded", name: Go}]
          - {name: B, kind: success, post: "at(self, g)"}
        utility: {priority_weight: 0.6, similarity_weight: 0.4, threshold: 0.05}
    """)
    plan = doc.plans[0]
    ep = plan.entry_points[0]
    assert (ep.min, math.isinf(ep.max), ep.success_required) == (1, True, True)
    assert [v.type for v in plan.variables] == ["position", "any"]
    assert plan.transitions[0].name == "Go" and plan.transitions[0].condition.text == "succeeded"
    assert plan.state("B").kind is StateKind.SUCCESS
    assert plan.states[0].children[0].bindings[0].value == "pos(a)"
    assert plan.utility.threshold == 0.05


def test_unknown_key_is_reported_with_suggestion() -> None:
    _, problems = read_text("plans:\n  - name: P\n    entry_point: []\n    states: []\n", "f.yaml")
    texts = [p.format() for p in problems]
    assert any(
        t.startswith("f.yaml:3:5: error: unknown key 'entry_point' in plan 'P' (fix: did you mean 'entry_points'?)")
        for t in texts
    ), texts


def test_wrong_type_is_reported() -> None:
    _, problems = read_text("plans:\n  - name: P\n    entry_points: []\n    states: {A: 1}\n", "f.yaml")
    assert any("'states' of plan 'P' must be a list, not a mapping" in p.message for p in problems)


def test_bad_number_is_reported() -> None:
    _, problems = read_text(
        "plans:\n  - name: P\n    entry_points: [{task: T, state: A, min: many}]\n    states: [{name: A}]\n", "f.yaml"
    )
    assert any("'min' of an entry point of plan 'P' must be a whole number, not text" in p.message for p in problems)
