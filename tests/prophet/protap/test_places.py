"""A plan file's planning problem read as ProTaP (places.py), and the stepwise planner behind the interface."""

from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.errors import PlannerError
from alica.io import load_library
from alica.model import Condition, ConditionKind
from alica.prophet.pipeline import plan_problem
from alica.prophet.planner import PlanStatus
from alica.prophet.protap.model import ProtapModel
from alica.prophet.protap.places import read_places
from alica.prophet.world import read_world
from tests.conftest import PLANS

SURVEY = PLANS / "examples" / "protap_survey.yaml"


def _task(world: str, goal: str | None = None, library=None):  # type: ignore[no-untyped-def]
    library = library or load_library(SURVEY)
    problem = replace(library.problems["SurveySites"], world=Condition(ConditionKind.PRE, world))
    if goal is not None:
        problem = replace(problem, goal=Condition(ConditionKind.POST, goal))
    planning = plan_problem(problem, library, read_world(problem, library, (), ()))
    return planning


def test_the_survey_reads_as_one_goto_two_dos_and_a_goal_per_literal():
    planning = _task("at(r1, base) and at(r2, s3) and scanned(s3)")
    places = read_places(planning.domain, planning.pddl, {"base": (0, 0), "s1": (3, 4), "s2": (0, 6), "s3": (6, 6)})
    assert places.goto.name == "gotosite" and places.goto_from
    assert [d.name for d in places.dos] == ["takesample", "scansite"]
    assert places.robots == ("r1", "r2")
    assert places.places == ("base", "s1", "s2", "s3")
    spec = places.spec
    assert (spec.width, spec.height) == (4, 1)
    assert [(g.action, g.cell) for g in spec.goals] == [("a1", (1, 0)), ("a1", (2, 0)), ("a2", (3, 0))]
    assert spec.goto_cost((0, 0), (1, 0)) == 5.0  # metres from base to s1
    assert spec.goto_cost((1, 0), (1, 0)) == 0.0
    assert places.state.cells == (0, 3)
    assert places.state.done == 0b100  # scanned(s3) holds already


def test_without_positions_every_drive_costs_one():
    planning = _task("at(r1, base) and at(r2, base)")
    spec = read_places(planning.domain, planning.pddl).spec
    assert spec.goto_cost((0, 0), (3, 0)) == 1.0


def test_a_robot_at_no_place_starts_at_its_own_position_or_is_refused():
    # r2 is a robot of the team that no fact places anywhere: it starts where its position says
    library = load_library(SURVEY)
    problem = replace(library.problems["SurveySites"], world=Condition(ConditionKind.PRE, "at(r1, base)"))
    world = read_world(problem, library, (), ())
    world = replace(world, objects=(*world.objects, ("r2", "robot")), robots=("r1", "r2"))
    planning = plan_problem(problem, library, world)
    places = read_places(planning.domain, planning.pddl, {"r2": (1.0, 1.0), "base": (0.0, 0.0)})
    assert places.places[-1] == "r2_start" and places.state.cells[1] == len(places.places) - 1
    with pytest.raises(PlannerError, match="robot r2 is at no place"):
        read_places(planning.domain, planning.pddl, {})


def test_a_goal_no_do_element_achieves_is_a_clear_error():
    planning = _task("at(r1, base)", goal="sampled(s1) and at(r1, s2)")
    with pytest.raises(PlannerError, match=r"no do element achieves the goal literal \(at r1 s2\) at a place"):
        read_places(planning.domain, planning.pddl)


def test_elements_without_a_goto_are_refused_with_the_form_expected(tmp_path):
    text = SURVEY.read_text(encoding="utf-8").replace(
        "elements: [GotoSite, TakeSample, ScanSite]", "elements: [TakeSample, ScanSite]"
    )
    path = tmp_path / "survey.yaml"
    path.write_text(
        text.replace("imports: [../tasks.yaml]", f"imports: [{(PLANS / 'tasks.yaml').as_posix()}]"), encoding="utf-8"
    )
    planning = _task("at(r1, base)", library=load_library(path))
    with pytest.raises(PlannerError, match=r"exactly one goto element"):
        read_places(planning.domain, planning.pddl)


def test_the_step_planner_returns_one_step_with_at_most_a_do_and_a_goto_per_robot():
    planning = _task("at(r1, base) and at(r2, s3)")
    result = planning.solve(time_limit=30)
    assert result.run.status is PlanStatus.SOLVED and result.plan is not None
    steps = result.plan.steps
    per_robot: dict[str, list[str]] = {}
    for step in steps:
        per_robot.setdefault(step.args[0], []).append(step.action.lower())
    for actions in per_robot.values():
        assert actions.count("gotosite") <= 1 and len(actions) - actions.count("gotosite") <= 1
        if len(actions) == 2:
            assert actions[1] == "gotosite"  # the do acts where the robot stands, before it drives on
    assert any(step.action.lower() == "scansite" and step.args == ("r2", "s3") for step in steps)


@settings(max_examples=25, deadline=None)
@given(
    starts=st.lists(st.sampled_from(["base", "s1", "s2", "s3"]), min_size=1, max_size=3),
    done=st.sets(st.sampled_from(["sampled(s1)", "sampled(s2)", "scanned(s3)"]), max_size=2),
    seed=st.integers(0, 50),
)
def test_every_step_is_valid_and_within_the_limits(starts, done, seed):
    world = " and ".join([f"at(r{i + 1}, {place})" for i, place in enumerate(starts)] + sorted(done))
    planning = _task(world)
    planning = replace(planning, planner=type(planning.planner)(trials=200, seed=seed))
    result = planning.solve(time_limit=30)  # validated: every action applies in order
    assert result.plan is not None
    places = read_places(planning.domain, planning.pddl)
    model = ProtapModel(places.spec)
    robots = {step.args[0] for step in result.plan.steps}
    assert robots <= set(places.robots)
    assert len(result.plan.steps) <= model.spec.max_nondef_actions
