"""The model: immutable values, equality without places, plan semantics."""

from __future__ import annotations

import dataclasses
import math

import pytest

from alica.model import (
    UNBOUNDED,
    Condition,
    ConditionKind,
    EntryPoint,
    Plan,
    Priority,
    Role,
    RoleSet,
    State,
    StateKind,
    Transition,
    UtilityFunction,
)
from alica.source import SourceSpan


def _plan() -> Plan:
    return Plan(
        "Mission",
        entry_points=(
            EntryPoint("Explore", "Explore", "Search", 1, UNBOUNDED),
            EntryPoint("Transport", "Transport", "Wait", 1, 2, success_required=True),
        ),
        states=(
            State("Search"),
            State("Wait"),
            State("Carry"),
            State("Done", StateKind.SUCCESS),
            State("Lost", StateKind.FAILURE),
        ),
        transitions=(
            Transition("Wait->Carry", "Wait", "Carry", Condition(ConditionKind.TRANSITION, "found(a)")),
            Transition("Carry->Done", "Carry", "Done"),
            Transition("Carry->Lost", "Carry", "Lost"),
        ),
    )


def test_elements_are_frozen() -> None:
    plan = _plan()
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.name = "Other"  # type: ignore[misc]


def test_equality_ignores_source_places() -> None:
    a = State("S", span=SourceSpan("a.yaml", 3, 5))
    b = State("S", span=SourceSpan("b.xml", 9, 1))
    assert a == b and hash(a) == hash(b)


def test_cardinalities_sum_over_entry_points() -> None:
    plan = _plan()
    assert plan.min_cardinality == 2
    assert math.isinf(plan.max_cardinality)


def test_plan_success_needs_each_required_entry_point() -> None:
    plan = _plan()
    assert not plan.succeeded({})
    assert not plan.succeeded({"Explore": 3})
    assert plan.succeeded({"Transport": 1})


def test_success_required_with_min_zero_still_needs_one_agent() -> None:
    plan = Plan("P", (EntryPoint("T", "T", "S", 0, 1, success_required=True),), (State("S"),))
    assert not plan.succeeded({"T": 0})
    assert plan.succeeded({"T": 1})


def test_reachable_states_follow_transitions() -> None:
    plan = _plan()
    assert plan.reachable_states("Transport") == {"Wait", "Carry", "Done", "Lost"}
    assert plan.reachable_states("Explore") == {"Search"}
    assert [t.target for t in plan.out_transitions("Carry")] == ["Done", "Lost"]


def test_state_kinds_and_lookups() -> None:
    plan = _plan()
    assert plan.state("Done").terminal and not plan.state("Wait").terminal
    with pytest.raises(KeyError, match="no state 'Nowhere'"):
        plan.state("Nowhere")
    with pytest.raises(KeyError):
        plan.entry_point("Missing")


def test_role_set_priorities_and_default() -> None:
    scout = Role("Scout", (Priority("Explore", 0.9), Priority("Pickup", -1.0)))
    rs = RoleSet("Impera", (scout,), default_priority=0.2)
    assert rs.priority("Scout", "Explore") == 0.9
    assert rs.priority("Scout", "Pickup") == -1.0
    assert rs.priority("Scout", "MoveTo") == 0.2
    with pytest.raises(KeyError):
        rs.role("Amparo")


def test_utility_weight_sum() -> None:
    assert UtilityFunction().weight_sum == 1.0
    assert UtilityFunction(priority_weight=0.5, similarity_weight=0.2).weight_sum == pytest.approx(0.7)
