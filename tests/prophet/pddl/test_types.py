"""Types with several parents and ``(either ...)`` types, as in IPC Storage (issue 22)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from alica.prophet.pddl import PddlError, either, parse_domain, parse_problem, write_domain
from alica.prophet.planner import PlanStatus
from alica.prophet.planners import get_planner
from alica.prophet.validate import validate_plan

# Storage's shape: area is a place's sibling and a surface at once; 'in' takes a store area or a crate.
STORE = """(define (domain store)
  (:requirements :typing)
  (:types hoist surface place area - object
          depot - place
          storearea - area
          area crate - surface)
  (:predicates (in ?x - (either storearea crate) ?p - place)
               (on ?c - crate ?s - surface)
               (clear ?s - surface)
               (at ?h - hoist ?a - area)
               (holding ?h - hoist ?c - crate))
  (:action lift
    :parameters (?h - hoist ?c - crate ?s - surface ?a - area)
    :precondition (and (at ?h ?a) (on ?c ?s) (clear ?c))
    :effect (and (holding ?h ?c) (clear ?s) (not (on ?c ?s)) (not (clear ?c))))
  (:action drop
    :parameters (?h - hoist ?c - crate ?s - (either storearea crate) ?a - area)
    :precondition (and (at ?h ?a) (holding ?h ?c) (clear ?s))
    :effect (and (on ?c ?s) (clear ?c) (not (clear ?s)) (not (holding ?h ?c)))))
"""
STORE_PROBLEM = """(define (problem p) (:domain store)
  (:objects h - hoist a1 - area s1 s2 - storearea c1 c2 - crate d - depot)
  (:init (at h a1) (on c1 s1) (clear c1) (on c2 s2) (clear c2) (in s1 d) (in c1 d))
  (:goal (on c1 c2)))
"""


def test_a_type_declared_under_two_parents_has_both() -> None:
    domain = parse_domain(STORE, "store.pddl")
    assert domain.types["area"] == ("surface",)  # 'area - object' is implicit beside 'area - surface'
    assert domain.types["storearea"] == ("area",)
    assert domain.is_subtype("storearea", "surface") and domain.is_subtype("storearea", "area")
    assert not domain.is_subtype("crate", "area") and not domain.is_subtype("depot", "surface")


def test_either_types_read_written_and_planned() -> None:
    domain = parse_domain(STORE, "store.pddl")
    drop = domain.action("drop")
    assert drop is not None and dict(drop.parameters)["?s"] == "(either crate storearea)"
    assert domain.is_subtype("storearea", "(either crate storearea)") and domain.is_subtype(
        "crate", drop.parameters[2][1]
    )
    assert not domain.is_subtype("area", "(either crate storearea)")
    assert parse_domain(write_domain(domain)) == domain
    problem = parse_problem(STORE_PROBLEM, "p.pddl", domain)
    result = get_planner("builtin").solve(domain, problem)
    assert result.status is PlanStatus.SOLVED and result.plan is not None
    assert [str(s) for s in result.plan.steps] == ["(lift h c1 s1 a1)", "(drop h c1 c2 a1)"]
    assert validate_plan((domain, problem), result.plan).valid


def test_the_validator_refuses_an_object_outside_an_either_type() -> None:
    domain = parse_domain(STORE, "store.pddl")
    problem = parse_problem(STORE_PROBLEM, "p.pddl", domain)
    steps = get_planner("builtin").solve(domain, problem).plan.steps  # type: ignore[union-attr]
    bad = [steps[0], type(steps[1])("drop", ("h", "c1", "a1", "a1"))]  # an area is neither a crate nor a store area
    result = validate_plan((domain, problem), bad)
    assert not result.valid and result.failed_step == 2 and "a1" in result.reason, result


@pytest.mark.parametrize(
    ("text", "where", "what"),
    [
        ("(:types a b - object c - (either a b))", "1:47", "'(either ...)' in the type list"),
        ("(:types a - b b - a)", "1:30", "is its own ancestor"),
        ("(:types a - object) (:constants k - (either a object))", "1:58", "an object or constant has one type"),
        ("(:types a) (:predicates (p ?x - (either a zz)))", "1:64", "unknown type 'zz'"),
        ("(:types a) (:predicates (p ?x - (a b)))", "1:54", "expected a type name or '(either type ...)'"),
        ("(:types a - object a - object)", "1:41", "duplicate type 'a'"),
    ],
)
def test_bad_types_are_refused_at_their_place(text: str, where: str, what: str) -> None:
    with pytest.raises(PddlError) as caught:
        parse_domain(f"(define (domain bad) {text})", "bad.pddl")
    message = str(caught.value)
    assert message.startswith(f"bad.pddl:{where}:") and what in message


@given(st.lists(st.sampled_from(["a", "b", "c", "object"]), min_size=1, max_size=4))
def test_either_names_are_canonical(members: list[str]) -> None:
    name = either(members)
    assert name == either(list(reversed(members)))
    if "object" in members:
        assert name == "object"
    elif len(set(members)) == 1:
        assert name == members[0]
    else:
        assert name.startswith("(either ") and sorted(set(members)) == name[8:-1].split()
