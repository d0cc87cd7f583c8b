"""The lunar mission's planning problem GetObjects (IMPERA Fig. 17) in the world the team's skills write."""

from __future__ import annotations

from dataclasses import replace

import pytest

from alica.io import load_library
from alica.lang.fact import Fact
from alica.model import Condition, ConditionKind
from alica.prophet import plan_problem
from alica.prophet.planner import PlanStatus
from alica.prophet.world import read_world
from tests.conftest import PLANS

TEAM = ("amparo", "scout", "stummel")
GOAL = "at(green_white_red, g) and at(red_black_red, g)"


@pytest.fixture(scope="module")
def impera():
    return load_library(PLANS / "lunar" / "impera.yaml")


def _problem(impera, goal: str = GOAL):
    return replace(impera.problems["GetObjects"], goal=Condition(ConditionKind.POST, goal))


def _seen(*samples: str) -> list[Fact]:
    """What the detections and the robots' own grippers tell the world model."""
    facts = [Fact("handempty", ("stummel",)), Fact("handempty", ("amparo",))]
    for s in samples:
        facts += [Fact("found", (s,)), Fact("onground", (s,))]
    return facts


def test_the_collection_point_is_known_without_being_seen_and_samples_are_typed_by_their_facts(impera):
    world = read_world(_problem(impera), impera, _seen("green_white_red", "red_black_red"), TEAM, {"Sample": []})
    types = world.object_types()
    assert types["g"] == "location"  # declared by the problem: objects: [g - location]
    # at(?r, ?x) types its first argument as a robot; onground(x) says what the sample is
    assert types["green_white_red"] == types["red_black_red"] == "sample"
    assert not world.outside


def test_a_chosen_sample_nobody_has_seen_is_not_planned_for(impera):
    world = read_world(_problem(impera), impera, _seen("green_white_red"), TEAM)
    assert world.outside == ("red_black_red",)


def test_the_team_plans_the_transport_with_the_robots_that_have_a_free_hand(impera):
    problem = _problem(impera)
    world = read_world(problem, impera, _seen("green_white_red", "red_black_red"), TEAM)
    result = plan_problem(problem, impera, world).solve(time_limit=20)
    assert result.run.status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL)
    assert result.plan is not None
    steps = [str(s) for s in result.plan.steps]
    assert sum(s.startswith("(putdown") for s in steps) == 2
    assert not any("scout" in s for s in steps if s.startswith(("(pickup", "(putdown")))  # no arm, no handempty


def test_objects_of_types_the_domain_does_not_know_are_left_out(impera):
    # the world model also lists the exploration's frontiers: the planning domain has no such type
    typed = {"Frontier": ["f_0_0", "f_1_0"], "Sample": ["green_white_red"], "location": ["g"]}
    world = read_world(_problem(impera), impera, _seen("green_white_red", "red_black_red"), TEAM, typed)
    types = world.object_types()
    assert "f_0_0" not in types and types["green_white_red"] == "Sample" and types["g"] == "location"
    result = plan_problem(_problem(impera), impera, world).solve(time_limit=20)
    assert result.plan is not None


def test_a_delivered_sample_is_no_robot_outside_the_team(impera):
    # at/2 takes a robot (MoveToObject) or a sample (Putdown): at(green_white_red, g) is a sample at g
    facts = [*_seen("green_white_green"), Fact("at", ("green_white_red", "g")), Fact("onground", ("green_white_red",))]
    typed = {"Sample": ["green_white_red", "green_white_green"]}
    problem = _problem(impera, "at(green_white_red, g) and at(green_white_green, g)")
    world = read_world(problem, impera, facts, TEAM, typed)
    assert not world.outside and not world.others and world.left_out == 0
    assert Fact("at", ("green_white_red", "g")) in world.facts
