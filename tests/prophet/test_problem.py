"""A planning problem of a plan file, planned: PDDL from the signatures, the builtin planner, task creation."""

from __future__ import annotations

import pytest

from alica.errors import PlannerError
from alica.io import load_library
from alica.prophet.planner import PlanStatus
from alica.prophet.problem import domain_text, offline_world, problem_text, to_pddl
from alica.prophet.tasks import create_tasks
from tests.conftest import PLANS

OBJECTS = {"a": "block", "b": "block", "c": "block", "r": "robot"}
SUSSMAN = [
    ("on", ("c", "a")),
    ("ontable", ("a",)),
    ("ontable", ("b",)),
    ("clear", ("c",)),
    ("clear", ("b",)),
    ("handempty", ("r",)),
]


@pytest.fixture(scope="module")
def blocks():
    return load_library(PLANS / "blocksworld" / "mission.yaml")


def test_domain_has_one_action_per_element(blocks):
    text = domain_text(blocks.problems["StackBlocks"], blocks)
    for action in ("pickup", "putdown", "stack", "unstack"):
        assert f"(:action {action}" in text
    assert "(increase (total-cost) 1)" in text


def test_the_sussman_anomaly_is_planned_and_parallelised(blocks):
    from alica.prophet.search.planner import BuiltinPlanner

    problem = blocks.problems["StackBlocks"]
    domain, pddl = to_pddl(problem, blocks, OBJECTS, SUSSMAN)
    result = BuiltinPlanner().solve(domain, pddl, time_limit=10, anytime=True)
    assert result.status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL)
    assert result.cost == 6
    created = create_tasks(
        "StackBlocksPlan", result.plan.steps, blocks, SUSSMAN, "r", next(iter(blocks.rolesets.values())), "Default"
    )
    assert len(created.tasks) >= 2
    assert sum(len(t) for t in created.tasks) == 6


def test_goal_and_world_must_be_literals(blocks):
    from dataclasses import replace

    from alica.model import Condition, ConditionKind

    problem = blocks.problems["StackBlocks"]
    bad = replace(problem, goal=Condition(ConditionKind.POST, "on(a, b) or on(b, a)"))
    with pytest.raises(PlannerError, match="conjunction of literals"):
        problem_text(bad, OBJECTS, SUSSMAN)
    with pytest.raises(PlannerError, match="has no 'world'"):
        offline_world(problem)
