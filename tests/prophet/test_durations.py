"""Skill durations for a temporal planner: declared on the signatures, measured by the team (alica.prophet.durations),
written as durative PDDL (alica.prophet.problem) and planned for the makespan (alica.prophet.pipeline)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import pytest

from alica.errors import PlannerError
from alica.io import load_library
from alica.lang.fact import Fact
from alica.prophet.durations import PRIOR, StepTimes
from alica.prophet.pipeline import plan_problem
from alica.prophet.planner import PlanStep
from alica.prophet.problem import domain_text
from alica.prophet.tasks import create_tasks
from alica.prophet.world import read_world
from tests.conftest import PLANS
from tests.prophet.test_keep_off import PLAN as SUSSMAN
from tests.prophet.test_keep_off import ROBOTS, WORLD

PLAN = SUSSMAN[:4]  # a robot digs c out and puts it down, another stacks b on c


@pytest.fixture(scope="module")
def library():
    return load_library(PLANS / "blocksworld" / "mission.yaml")


def _at(created: Any, state: str | None) -> Any:
    return SimpleNamespace(plan=created.plan, state=state)


def test_a_step_is_timed_from_its_running_state_to_the_next_place_and_failures_are_left_out(library) -> None:
    created = create_tasks("P", PLAN, library, WORLD, ROBOTS, next(iter(library.rolesets.values())), "Default")
    times = StepTimes()
    for now, state in ((0.0, "T0_Wait0"), (1.0, "T0_S0_Unstack"), (5.0, "T0_S0_Unstack"), (7.5, "T0_Wait1")):
        times.observe(_at(created, state), created, now)
    assert times.count == {"Unstack": 1} and times.total == {"Unstack": 6.5}
    for now, state in ((8.0, "T0_S1_Putdown"), (20.0, "T0_Done")):
        times.observe(_at(created, state), created, now)
    assert times.total["Putdown"] == 12.0
    for now, state in ((30.0, "T1_S0_Pickup"), (40.0, "T1_Failed")):  # a failed step says nothing of its duration
        times.observe(_at(created, state), created, now)
    times.observe(_at(created, "T1_S0_Pickup"), created, 41.0)
    times.observe(None, None, 45.0)  # the plan was replaced meanwhile
    assert "Pickup" not in times.count


def test_the_declared_duration_counts_as_prior_measurements(library) -> None:
    times = StepTimes()
    declared = library.plans["Unstack"].signature.duration
    assert declared == 7.0 and library.plans["Putdown"].signature.duration == 8.0
    assert times.estimates(library, ["Unstack"]) == {"Unstack": 7.0}
    times.total, times.count = {"Unstack": 22.0}, {"Unstack": 2}  # two steps of 11 s
    assert times.estimates(library, ["Unstack"])["Unstack"] == pytest.approx((7.0 * PRIOR + 22.0) / (PRIOR + 2))


def test_the_temporal_domain_locks_what_a_step_uses_from_its_start(library) -> None:
    text = domain_text(library.problems["StackBlocks"], library, temporal=True, durations={"Stack": 9.5})
    assert ":durative-actions" in text and "total-cost" not in text
    stack = text.split("(:durative-action stack")[1].split("(:durative-action")[0]
    assert "(= ?duration 9.5)" in stack  # the measured duration over the declared 8
    assert "(at start (not (clear ?y)))" in stack and "(at start (not (holding ?r ?x)))" in stack
    assert "(at end (on ?x ?y))" in stack and "(at end (handempty ?r))" in stack


def test_an_element_without_a_duration_is_named(library) -> None:
    bare = replace(library.plans["Pickup"], signature=replace(library.plans["Pickup"].signature, duration=None))
    documents = tuple(
        replace(d, plans=tuple(bare if p.name == "Pickup" else p for p in d.plans)) for d in library.documents
    )
    stripped = type(library)(documents)
    with pytest.raises(PlannerError, match=r"element 'Pickup' declares none: give its signature a 'duration'"):
        domain_text(stripped.problems["StackBlocks"], stripped, temporal=True)


def test_a_problem_planned_for_the_makespan_spreads_the_steps_and_is_checked_as_scheduled(library) -> None:
    problem = library.problems["StackBlocks"]
    problem = replace(problem, goal=replace(problem.goal, text="on(b, c) and on(d, e)"))
    robots = ["r1", "r2"]
    facts = [Fact(p, a) for p, a in WORLD if p != "handempty"] + [
        Fact("ontable", ("d",)),
        Fact("clear", ("d",)),
        Fact("ontable", ("e",)),
        Fact("clear", ("e",)),
        *(Fact("handempty", (r,)) for r in robots),
    ]
    world = read_world(problem, library, facts, robots, {"block": ["a", "b", "c", "d", "e"], "robot": robots})
    planning = plan_problem(problem, library, world, planner="temporal")
    result = planning.solve(time_limit=20)
    assert result.plan is not None
    assert {step.args[0] for step in result.plan.steps} == {"r1", "r2"}  # both robots work at once
    assert result.plan.cost == pytest.approx(7.0 + 8.0 + 0.001)  # Pickup then Stack on each robot, side by side
    # a sequence the schedule cannot run (Stack before its Pickup) is refused, with the reason
    wrong = planning.check([PlanStep("stack", ("r1", "b", "c")), PlanStep("pickup", ("r1", "b"))])
    assert not wrong.valid and wrong.reason
