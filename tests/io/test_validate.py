"""Validation of a document set: one test per rule, asserting message and place."""

from __future__ import annotations

from tests.io.helpers import messages

HEAD = """\
tasks: [Default, Explore]
behaviours:
  - name: Drive
    skill: DriveTo
    params: {goal: [1, 2]}
"""


def _one(text: str, fragment: str, line: int) -> None:
    found = messages(HEAD + text)
    assert any(fragment in m and f"doc.yaml:{line}:" in m for m in found), found


def test_valid_document_has_no_problems() -> None:
    assert (
        messages(
            HEAD
            + """\
plans:
  - name: P
    entry_points: [{task: Default, state: A, min: 1, max: 2}]
    states:
      - name: A
        children: [Drive]
        transitions: [{to: B, condition: "succeeded"}]
      - {name: B, kind: success}
"""
        )
        == []
    )


def test_unknown_state_reference() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Default, state: Nowhere}]
    states: [{name: A}]
""",
        "starts in unknown state 'Nowhere'",
        8,
    )


def test_unknown_task_in_entry_point() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Explor, state: A}]
    states: [{name: A}]
""",
        "names task 'Explor', which is not defined (fix: did you mean 'Explore'?)",
        8,
    )


def test_duplicate_plan_names() -> None:
    _one(
        """\
plans:
  - {name: P, entry_points: [{task: Default, state: A}], states: [{name: A}]}
  - {name: P, entry_points: [{task: Default, state: A}], states: [{name: A}]}
""",
        "duplicate name 'P'",
        8,
    )


def test_behaviour_and_plan_share_a_namespace() -> None:
    _one(
        """\
plans:
  - {name: Drive, entry_points: [{task: Default, state: A}], states: [{name: A}]}
""",
        "duplicate name 'Drive'",
        7,
    )


def test_min_greater_than_max() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Default, state: A, min: 3, max: 2}]
    states: [{name: A}]
""",
        "has min 3 > max 2",
        8,
    )


def test_entry_point_without_state() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Default}]
    states: [{name: A}]
""",
        "has no initial state",
        8,
    )


def test_unreachable_state() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Default, state: A}]
    states:
      - {name: A}
      - {name: Island}
""",
        "state 'Island' of plan 'P' cannot be reached",
        11,
    )


def test_transition_out_of_terminal_state() -> None:
    _one(
        """\
plans:
  - name: P
    entry_points: [{task: Default, state: A}]
    states:
      - {name: A, kind: success, transitions: [{to: A}]}
""",
        "leaves success state 'A'",
        10,
    )


def test_cycle_through_plan_type() -> None:
    found = messages(
        HEAD
        + """\
plans:
  - name: P
    entry_points: [{task: Default, state: A}]
    states: [{name: A, children: [T]}]
plantypes:
  - {name: T, plans: [P]}
"""
    )
    assert any(("the plan tree has a cycle: " in m and "P -> T -> P" in m) or "T -> P -> T" in m for m in found), found


def test_priority_out_of_range() -> None:
    _one(
        """\
rolesets:
  - name: R
    roles:
      - name: Scout
        priorities: {Explore: 1.2}
""",
        "is 1.2, outside [-1, 1]",
        10,
    )


def test_utility_weights_must_sum_to_one() -> None:
    _one(
        """\
plans:
  - name: P
    utility:
      priority_weight: 0.5
      summands: [{name: Near, weight: 0.2, expression: "1 - 0.5"}]
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
""",
        "sum to 0.7, not 1",
        9,
    )


def test_unknown_skill_with_suggestion() -> None:
    _one(
        """\
  - {name: Grab, skill: Grasps, params: {object: a}}
""",
        "binds unknown skill 'Grasps' (fix: did you mean 'Grasp'?)",
        6,
    )


def test_skill_parameters_are_checked() -> None:
    found = messages(
        HEAD
        + """\
  - {name: Grab, skill: Grasp, params: {retries: 2.5, speed: 1}}
"""
    )
    assert any("doc.yaml:6:" in m and "required parameter 'object'" in m for m in found), found
    assert any("parameter 'retries' of behaviour 'Grab' must be a whole number" in m for m in found), found
    assert any("skill 'Grasp' has no parameter 'speed'" in m for m in found), found


def test_parameter_variable_must_be_declared() -> None:
    _one(
        """\
  - {name: Go, skill: DriveTo, params: {goal: $target}}
""",
        "refers to '$target', which is not a variable",
        6,
    )


def test_malformed_formula_points_to_its_column() -> None:
    found = messages(
        HEAD
        + """\
plans:
  - name: P
    pre: "On(a, g) and (b"
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
"""
    )
    # the formula starts at column 11 of line 8; '(' at formula column 14 is unclosed
    assert any(m.startswith("doc.yaml:8:") and "pre condition of plan 'P'" in m for m in found), found


def test_wrong_arity_of_registered_predicate() -> None:
    _one(
        """\
plans:
  - name: P
    run: "MaximalDist(a, b)"
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
""",
        "MaximalDist",
        8,
    )


def test_problem_without_wait_plan() -> None:
    _one(
        """\
plans:
  - name: Step
    signature: {parameters: ["?x"], precondition: "free(?x)", effect: "not free(?x)"}
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
problems:
  - {name: O, elements: [Step], goal: "done"}
""",
        "has no WaitPlan",
        12,
    )


def test_problem_element_needs_signature() -> None:
    _one(
        """\
plans:
  - name: Step
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
problems:
  - {name: O, elements: [Step], goal: "done", wait_plan: Step}
""",
        "has no planning signature",
        7,
    )


def test_effect_must_be_literals() -> None:
    _one(
        """\
plans:
  - name: Step
    signature: {parameters: ["?x"], effect: "free(?x) or busy(?x)"}
    entry_points: [{task: Default, state: A}]
    states: [{name: A}]
""",
        "effect of plan 'Step'",
        8,
    )


def test_synchronisation_must_match_transitions() -> None:
    found = messages(
        HEAD
        + """\
plans:
  - name: P
    entry_points: [{task: Default, state: A}, {task: Explore, state: C}]
    states:
      - {name: A, transitions: [{to: B, sync: S}]}
      - {name: B}
      - {name: C, transitions: [{to: D}]}
      - {name: D}
    synchronisations:
      - {name: S, transitions: [A->B, C->D]}
"""
    )
    assert any("does not say 'sync: S'" in m for m in found), found


def test_binding_names_a_variable_of_the_child() -> None:
    _one(
        """\
  - {name: Go, skill: DriveTo, variables: [goal], params: {goal: $goal}}
plans:
  - name: P
    entry_points: [{task: Default, state: A}]
    states:
      - name: A
        children: [{ref: Go, bind: {target: "pos(a)"}}]
""",
        "'Go' has no variable 'target'",
        12,
    )


def test_all_problems_are_reported_at_once() -> None:
    found = messages(
        HEAD
        + """\
plans:
  - name: P
    entry_points: [{task: Nope, state: A, min: 2, max: 1}]
    states: [{name: A, children: [Missing]}, {name: Z}]
"""
    )
    assert len(found) >= 3
