"""Assignments, the utility of one assignment, the tie rule and malformed problems."""

from __future__ import annotations

import dataclasses
import math

import pytest

from alica.allocation import AllocationError, AllocationProblem, Assignment, allocate, exhaustive, utility
from alica.model import EntryPoint, Plan, Priority, Role, RoleSet, State, Summand, UtilityFunction


def _plan(
    name: str = "P",
    eps: tuple[tuple[str, int, float], ...] = (("E0", 0, math.inf), ("E1", 0, math.inf)),
    **utility_args: object,
) -> Plan:
    entry_points = tuple(EntryPoint(n, n, "S", lo, hi) for n, lo, hi in eps)
    return Plan(name, entry_points, (State("S"),), utility=UtilityFunction(**utility_args))  # type: ignore[arg-type]


def _roles(**tasks: float) -> RoleSet:
    return RoleSet("R", (Role("R", tuple(Priority(t, v) for t, v in tasks.items())),))


def _problem(agents: tuple[str, ...], plans: tuple[Plan, ...], roleset: RoleSet, **extra: object) -> AllocationProblem:
    return AllocationProblem(agents, dict.fromkeys(agents, "R"), roleset, plans, **extra)  # type: ignore[arg-type]


def _best(problem: AllocationProblem) -> Assignment:
    found = allocate(problem)
    assert found.assignment is not None, found.why
    assert found.assignment == exhaustive(problem).assignment
    return found.assignment


def test_assignment_accessors() -> None:
    a = Assignment.of("P", {"b": "E1", "a": None, "c": "E1"}, 0.5)
    assert a.entries == (("a", None), ("b", "E1"), ("c", "E1"))
    assert a.entry_of("b") == "E1" and a.entry_of("a") is None
    assert a.agents_of("E1") == ("b", "c") and a.agents_of("E0") == ()
    assert a.agents == ("a", "b", "c") and a.idle == ("a",)
    assert list(a.as_dict()) == ["a", "b", "c"]
    with pytest.raises(KeyError, match="'d'"):
        a.entry_of("d")
    with pytest.raises(ValueError, match="twice"):
        Assignment("P", (("a", None), ("a", "E0")), 0.0)
    assert Assignment("P", (("b", None), ("a", "E0")), 0.0).entries == (("a", "E0"), ("b", None))


def test_identical_agents_take_entry_points_in_agent_order() -> None:
    plan = _plan(eps=(("E0", 1, 1), ("E1", 1, 1)))
    assignment = _best(_problem(("b", "a"), (plan,), _roles(E0=0.5, E1=0.5)))
    assert assignment.as_dict() == {"a": "E0", "b": "E1"}


def test_idling_is_the_last_choice() -> None:
    # Priority 0 is worth as much as idling; the entry point comes first in the tie rule.
    assignment = _best(_problem(("a",), (_plan(),), _roles(E0=0.0, E1=0.0)))
    assert assignment.as_dict() == {"a": "E0"}


def test_earlier_plan_wins_a_tie() -> None:
    first, second = _plan("First"), _plan("Second")
    roles = _roles(E0=0.5, E1=0.25)
    assert _best(_problem(("a",), (first, second), roles)).plan == "First"
    assert _best(_problem(("a",), (second, first), roles)).plan == "Second"


def test_utilities_closer_than_the_fixed_point_unit_tie() -> None:
    # E1 is better by 1e-12, far below round(U * 1e9)'s unit: a tie, so E0 wins.
    assignment = _best(_problem(("a",), (_plan(),), _roles(E0=0.5, E1=0.5 + 1e-12)))
    assert assignment.as_dict() == {"a": "E0"}
    assignment = _best(_problem(("a",), (_plan(),), _roles(E0=0.5, E1=0.5 + 1e-9)))
    assert assignment.as_dict() == {"a": "E1"}


def test_the_key_is_exact_whatever_the_summation_order() -> None:
    # 0.1 + 0.2 != 0.2 + 0.1 in floats only through rounding; U is exact here,
    # so agents listed in any order get the same value.
    roleset = RoleSet("R", (Role("A", (Priority("E0", 0.1),)), Role("B", (Priority("E0", 0.2),))))
    plan = _plan(eps=(("E0", 0, math.inf),))
    one = AllocationProblem(("x", "y"), {"x": "A", "y": "B"}, roleset, (plan,))
    two = AllocationProblem(("y", "x"), {"x": "A", "y": "B"}, roleset, (plan,))
    assert allocate(one).assignment == allocate(two).assignment
    assert utility(one, plan, {"x": "E0", "y": "E0"}) == pytest.approx(0.15)


def test_utility_is_minus_one_when_invalid_or_vetoed() -> None:
    plan = _plan(eps=(("E0", 1, 1), ("E1", 0, math.inf)))
    problem = _problem(("a", "b"), (plan,), _roles(E0=0.5, E1=-1.0))
    assert utility(problem, plan, {"a": "E0", "b": None}) == pytest.approx(0.25)
    assert utility(problem, plan, {"a": "E0", "b": "E1"}) == -1.0  # vetoed
    assert utility(problem, plan, {"a": "E0", "b": "E0"}) == -1.0  # E0 takes one agent
    assert utility(problem, plan, {"a": None, "b": None}) == -1.0  # E0 needs one agent
    assert utility(problem, plan, {"a": "E0"}) == -1.0  # b missing
    assert utility(problem, plan, {"a": "E0", "b": None, "c": None}) == -1.0  # unknown agent
    assert utility(problem, plan, {"a": "E0", "b": "E9"}) == -1.0  # unknown entry point
    strict = dataclasses.replace(problem, allow_idle=False)
    assert utility(strict, plan, {"a": "E0", "b": None}) == -1.0  # idling not allowed


def test_successes_lower_the_cardinality() -> None:
    plan = _plan(eps=(("E0", 2, 2), ("E1", 0, math.inf)))
    problem = _problem(("a", "b"), (plan,), _roles(E0=0.5, E1=0.25), successes={"P": {"E0": 1}})
    # E0 is now 1..1: one agent there, the other prefers E1 to idling.
    assert _best(problem).as_dict() == {"a": "E0", "b": "E1"}


def test_summands_and_their_vetoes() -> None:
    summand = Summand("near", 0.5, "distance")
    plan = dataclasses.replace(_plan(), utility=UtilityFunction(priority_weight=0.5, summands=(summand,)))
    values = {("a", "E0"): 1.0, ("a", "E1"): 0.0, ("b", "E0"): -1.0, ("b", "E1"): 0.5}

    def near(p: Plan, s: Summand, agent: str, ep: EntryPoint) -> float:
        return values[(agent, ep.name)]

    problem = _problem(("a", "b"), (plan,), _roles(E0=0.5, E1=0.5), summand=near)
    assignment = _best(problem)
    assert assignment.as_dict() == {"a": "E0", "b": "E1"}
    assert assignment.utility == pytest.approx((0.5 * (0.5 + 0.5) / 2 + 0.5 * (1.0 + 0.5) / 2) / 1.0)
    assert utility(problem, plan, {"a": "E0", "b": "E0"}) == -1.0  # b's summand vetoes E0


def test_malformed_problems_raise() -> None:
    plan = _plan()
    roles = _roles(E0=0.5)
    with pytest.raises(AllocationError, match="more than once: a"):
        allocate(AllocationProblem(("a", "a"), {"a": "R"}, roles, (plan,)))
    with pytest.raises(AllocationError, match="without a role: b"):
        allocate(AllocationProblem(("a", "b"), {"a": "R"}, roles, (plan,)))
    with pytest.raises(AllocationError, match=r"role 'X'.*\(roles: R\)"):
        allocate(AllocationProblem(("a",), {"a": "X"}, roles, (plan,)))
    with pytest.raises(AllocationError, match="negative success count"):
        allocate(_problem(("a",), (plan,), roles, successes={"P": {"E0": -1}}))
    with_summand = dataclasses.replace(plan, utility=UtilityFunction(summands=(Summand("s", 0.5, "x"),)))
    with pytest.raises(AllocationError, match="plan 'P' has utility summands"):
        allocate(_problem(("a",), (with_summand,), roles))
    with pytest.raises(ValueError):
        utility(_problem(("a",), (with_summand,), roles), with_summand, {"a": "E0"})
    bad = _problem(("a",), (with_summand,), roles, summand=lambda *args: math.nan)
    with pytest.raises(AllocationError, match="summand 's' of plan 'P' returned nan"):
        allocate(bad)


def test_no_candidates_and_no_agents() -> None:
    result = allocate(_problem(("a",), (), _roles()))
    assert result.assignment is None and result.why == "no candidate plans"
    empty = allocate(_problem((), (_plan(),), _roles()))
    assert empty.assignment == Assignment("P", (), 0.0)


def test_idling_not_allowed_is_explained() -> None:
    plan = _plan(eps=(("E0", 0, 1),))
    result = allocate(_problem(("a", "b"), (plan,), _roles(E0=0.5), allow_idle=False))
    assert result.assignment is None
    assert "idling is not allowed, so all 2 agents must take an entry point" in result.why
    assert result.why == exhaustive(_problem(("a", "b"), (plan,), _roles(E0=0.5), allow_idle=False)).why
