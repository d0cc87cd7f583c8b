"""WaitAside and the stand-off reservations: waiting robots make way, guard finished stacks, wait near their next step."""

from __future__ import annotations

import math
import random

from py_trees.common import Status

from alica.engine.behaviours import SkillContext
from alica.skills import reservations
from alica.skills.opponent import RandomBlockSkill
from alica.skills.waiting import GUARD_RADIUS, NEAR_SPAN, WaitAside
from alica.worldmodel import WorldModel
from alica.worldsim.scenarios import blocks_facts, blocksworld


def _context(world, agent, wm=None, seed=0):
    return SkillContext(agent, world.now, wm, None, random.Random(f"{seed}:{agent}"), world)


def _skill(cls, world, agent, params, wm=None, seed=0):
    skill = cls(f"{agent}-{cls.__name__}", dict(params), _context(world, agent, wm, seed))
    skill.setup()
    return skill


def _run(world, skills, seconds):
    """Tick every skill 10 times per simulated second for ``seconds``; the blocks facts after each tick."""
    seen = []
    for _ in range(round(seconds * 10)):
        for skill in skills:
            skill.tick_once()
            assert skill.status == Status.RUNNING, skill.feedback_message  # neither skill ends by itself
        world.step(0.1)
        seen.append(frozenset(blocks_facts(world)))
    return seen


def _xy(world, name):
    pose = world.robots[name].pose
    return float(pose[0]), float(pose[1])


def _block_xy(world, name):
    p = world.objects[name].position()
    return float(p[0]), float(p[1])


def test_reservations_are_shared_through_the_world_model_and_released():
    with blocksworld(stacks=[["a"]], agents=2) as world:
        wm = WorldModel("team", clock=world)  # one replica both skills read, as replicas that have synchronised
        one = _skill(WaitAside, world, "r1", {}, wm)
        two = _skill(WaitAside, world, "r2", {}, wm)
        reservations.reserve(one, (0.5, -0.25))
        radius = world.robots["r1"].spec.radius
        assert reservations.reserved(two) == [(0.5, -0.25, radius)]
        assert reservations.reserved(one) == []  # a robot's own reservation is not in its way
        reservations.release(one)
        assert reservations.reserved(two) == []


def test_reservations_without_a_world_model_lapse():
    with blocksworld(stacks=[["a"]], agents=2) as world:
        one = _skill(WaitAside, world, "r1", {})
        two = _skill(WaitAside, world, "r2", {})
        reservations.reserve(one, (0.5, -0.25))
        assert [p[:2] for p in reservations.reserved(two)] == [(0.5, -0.25)]
        world.step(reservations.RESERVATION_TTL + 0.5)  # a crashed robot refreshes nothing
        assert reservations.reserved(two) == []


def test_a_waiting_robot_makes_way_for_a_reserved_stand_off_point():
    with blocksworld(stacks=[["a"], ["b"]], agents=2) as world:
        wm = WorldModel("team", clock=world)
        waiter = _skill(WaitAside, world, "r2", {"clearance": 0.4, "max_distance": 5.0, "keep_away": 1.15}, wm)
        _run(world, [waiter], 3.0)
        before = _xy(world, "r2")
        assert waiter.feedback_message == "waiting aside"
        worker = _skill(WaitAside, world, "r1", {}, wm)
        reservations.reserve(worker, before)  # r1 is about to stand where r2 waits
        _run(world, [waiter], 10.0)
        after = _xy(world, "r2")
        mine = world.robots["r2"].spec.radius + world.robots["r1"].spec.radius
        assert math.dist(before, after) >= mine, (before, after)
        assert waiter.feedback_message == "waiting aside"


def test_a_robot_waits_near_the_work_site_of_its_next_step():
    with blocksworld(stacks=[["a", "b"], ["c"], ["d"]], agents=1) as world:
        site = _block_xy(world, "d")
        waiter = _skill(WaitAside, world, "r1", {"clearance": 0.4, "max_distance": 5.0, "near": "d"})
        _run(world, [waiter], 15.0)
        assert waiter.feedback_message == "waiting aside"
        assert NEAR_SPAN[0] <= math.dist(_xy(world, "r1"), site) <= NEAR_SPAN[1]


def test_a_name_that_is_no_object_is_ignored():
    with blocksworld(stacks=[["a"]], agents=1) as world:
        waiter = _skill(WaitAside, world, "r1", {"near": "near", "guard": "guard", "keep_away": 1.15})
        _run(world, [waiter], 5.0)
        assert waiter.feedback_message == "waiting aside"  # stands by, away from the block


def test_an_opponent_cannot_undo_a_guarded_stack():
    finished = [["a", "b", "c"]]
    with blocksworld(stacks=[*finished, ["d"], ["e"]], agents=1, opponents=1) as world:
        tower = {("on", "b", "a"), ("on", "c", "b"), ("ontable", "a")}
        guard = _skill(WaitAside, world, "r1", {"clearance": 0.4, "max_distance": 5.0, "guard": "c"})
        _run(world, [guard], 10.0)  # the robot that finished a stack stands beside it; this one drives there first
        assert math.dist(_xy(world, "r1"), _block_xy(world, "c")) <= GUARD_RADIUS
        opponent = _skill(RandomBlockSkill, world, "o1", {}, seed=3)
        seen = _run(world, [guard, opponent], 150.0)
        assert all(tower <= facts for facts in seen), "the opponent undid the guarded stack"
        assert len(set(seen)) >= 2, "the opponent never acted: the test shows nothing"
        assert all({a.block, a.other}.isdisjoint({"a", "b", "c"}) for a in opponent.chosen)
        opponent.stop(Status.INVALID)
        guard.stop(Status.INVALID)


def test_without_a_guard_the_opponent_takes_the_stack_apart():
    # the same world and seed as above, nobody guarding: the stack does not survive (the test above can fail)
    with blocksworld(stacks=[["a", "b", "c"], ["d"], ["e"]], agents=1, opponents=1) as world:
        tower = {("on", "b", "a"), ("on", "c", "b"), ("ontable", "a")}
        away = _skill(WaitAside, world, "r1", {"clearance": 0.4, "max_distance": 5.0, "keep_away": 1.15})
        _run(world, [away], 10.0)
        opponent = _skill(RandomBlockSkill, world, "o1", {}, seed=3)
        seen = _run(world, [away, opponent], 150.0)
        assert not all(tower <= facts for facts in seen)
        opponent.stop(Status.INVALID)
        away.stop(Status.INVALID)


def test_with_no_opponent_near_a_guard_stands_by_instead():
    # threat_radius: nothing to guard the stack from, so the robot does not stand beside it (where the
    # team's builders need the room); it stays where it stands by
    with blocksworld(stacks=[["a", "b", "c"], ["d"], ["e"]], agents=1) as world:
        start = _xy(world, "r1")
        params = {"clearance": 0.4, "max_distance": 5.0, "guard": "c", "keep_away": 1.15, "threat_radius": 2.5}
        waiter = _skill(WaitAside, world, "r1", params, WorldModel("team", clock=world))
        _run(world, [waiter], 10.0)
        assert math.dist(_xy(world, "r1"), _block_xy(world, "c")) > GUARD_RADIUS
        assert math.dist(_xy(world, "r1"), start) < 0.05
        waiter.stop(Status.INVALID)


def test_an_opponent_near_brings_the_guard_and_the_stack_survives():
    # the opponent starts 1.5 m from the stack: within threat_radius, so the robot guards it as before
    finished = [["a", "b", "c"]]
    with blocksworld(stacks=[*finished, ["d"], ["e"]], agents=1, opponents=1) as world:
        tower = {("on", "b", "a"), ("on", "c", "b"), ("ontable", "a")}
        params = {"clearance": 0.4, "max_distance": 5.0, "guard": "c", "keep_away": 1.15, "threat_radius": 2.5}
        team = WorldModel("team", clock=world)  # the team's own: the opponent is not in it
        guard = _skill(WaitAside, world, "r1", params, team)
        _run(world, [guard], 10.0)
        assert math.dist(_xy(world, "r1"), _block_xy(world, "c")) <= GUARD_RADIUS
        opponent = _skill(RandomBlockSkill, world, "o1", {}, seed=3)
        seen = _run(world, [guard, opponent], 150.0)
        assert all(tower <= facts for facts in seen), "the opponent undid the guarded stack"
        assert len(set(seen)) >= 2, "the opponent never acted: the test shows nothing"
        opponent.stop(Status.INVALID)
        guard.stop(Status.INVALID)
