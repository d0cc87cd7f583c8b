"""The one pipeline: a planning problem in a world -> PDDL -> a planner -> a validated plan, offline and anytime."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import pytest

from alica.errors import PlannerError
from alica.io import load_library
from alica.lang.fact import Fact
from alica.model import Condition, ConditionKind
from alica.prophet import plan_problem
from alica.prophet.pipeline import Found, Rejected
from alica.prophet.planner import Done, Feature, Improved, Plan, Planner, PlanStatus, PlanStep, Progress, SearchEvent
from alica.prophet.planners import PLANNERS
from alica.prophet.world import read_world
from tests.conftest import PLANS

SUSSMAN = "on(c, a) and ontable(a) and ontable(b) and clear(c) and clear(b) and handempty(r)"


@pytest.fixture(scope="module")
def blocks():
    return load_library(PLANS / "blocksworld" / "mission.yaml")


def _sussman(blocks, world: str = SUSSMAN, goal: str = "on(a, b) and on(b, c) and ontable(c)"):
    # planned for the fewest steps (the mission plans for the team's time: the temporal planner)
    problem = replace(
        blocks.problems["StackBlocks"],
        planner="builtin",
        world=Condition(ConditionKind.PRE, world),
        goal=Condition(ConditionKind.POST, goal),
    )
    return problem, read_world(problem, blocks, (), ())


def test_offline_the_plan_comes_back_validated(blocks):
    problem, world = _sussman(blocks)
    assert Fact("on", ("c", "a")) in world.facts
    result = plan_problem(problem, blocks, world).solve(time_limit=10)
    assert result.run.status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL)
    assert result.plan is not None and result.plan.cost == 6 and len(result.plan.steps) == 6
    assert str(result.plan.steps[0]) == "(unstack r c a)"


def test_the_plans_steps_name_the_objects_as_the_world_does(blocks):
    problem, world = _sussman(blocks, SUSSMAN.replace("c", "C").replace("Clear", "clear"), "on(a, b) and on(b, C)")
    result = plan_problem(problem, blocks, world).solve(time_limit=10)
    assert result.plan is not None
    assert "C" in {a for s in result.plan.steps for a in s.args}  # PDDL answers in lower case
    assert "c" in {a for s in result.plan.plan.steps for a in s.args}


def test_anytime_the_search_yields_each_better_plan_validated(blocks):
    problem, world = _sussman(blocks)
    events = list(plan_problem(problem, blocks, world, options={"progress_every": 1}).search(anytime=True))
    found = [e for e in events if isinstance(e, Found)]
    assert found and found[-1].plan.cost == 6
    assert any(isinstance(e, Progress) for e in events)
    assert isinstance(events[-1], Done)


class _Wrong(Planner):
    """Answers with a plan that does not apply."""

    name = "wrong"
    features = frozenset(Feature)

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        yield Improved(Plan((PlanStep("stack", ("r", "a", "b")),), 1.0), 1)
        yield Done(PlanStatus.SOLVED, 1)


def test_an_invalid_plan_is_never_used(blocks, monkeypatch):
    monkeypatch.setitem(PLANNERS, "wrong", "tests.prophet.test_pipeline:_Wrong")
    problem, world = _sussman(blocks)
    planning = plan_problem(problem, blocks, world, planner="wrong")
    events = list(planning.search())
    assert [type(e) for e in events] == [Rejected, Done]
    assert "planner 'wrong' returned an invalid plan: step 1" in events[0].reason
    with pytest.raises(PlannerError, match="returned an invalid plan"):
        planning.solve(time_limit=5)


def test_an_unknown_planner_is_a_planner_error(blocks):
    problem, world = _sussman(blocks)
    with pytest.raises(PlannerError, match="unknown planner 'nonesuch'"):
        plan_problem(problem, blocks, world, planner="nonesuch")
