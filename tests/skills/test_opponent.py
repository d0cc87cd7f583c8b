"""RandomBlockSkill, the opponents' skill: it disturbs the stacks, repeats itself per seed, leaves blocked stacks alone."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.opponent import BlockAction, RandomBlockSkill, applicable_actions, stack_of
from alica.skills.testing import run_skill
from alica.worldsim.scenarios import blocks_facts, blocksworld

STACKS = [["a", "c"], ["b"]]


def _run(world, robot="o1", timeout=60.0, seed=0, params=None):
    """Run the skill for ``timeout`` simulated seconds; the run, the behaviour and every distinct facts set seen."""
    seen: list[frozenset] = []
    behaviours = []

    def watch(w, behaviour):
        if not behaviours:
            behaviours.append(behaviour)
        facts = frozenset(blocks_facts(w))
        if not seen or seen[-1] != facts:
            seen.append(facts)

    run = run_skill("RandomBlockSkill", world, robot, params or {}, timeout=timeout, seed=seed, on_tick=watch)
    return run, behaviours[0], seen


def test_applicable_actions_follow_the_ipc_domain():
    facts = {("on", "c", "a"), ("ontable", "a"), ("ontable", "b"), ("clear", "c"), ("clear", "b"), ("handempty", "o1")}
    assert [a.label for a in applicable_actions(facts, "o1")] == ["Pickup(b)", "Unstack(c, a)"]
    assert applicable_actions(facts, "r1") == []  # r1's hand is not empty in these facts (no handempty(r1))
    holding = {("on", "c", "a"), ("ontable", "a"), ("clear", "c"), ("holding", "o1", "b")}
    assert [a.label for a in applicable_actions(holding, "o1")] == ["Putdown(b)", "Stack(b, c)"]
    assert BlockAction("Unstack", "c", "a").params() == {"object": "c", "from": "a"}
    assert BlockAction("Stack", "b", "c").params() == {"object": "b", "target": "c"}
    assert BlockAction("Pickup", "b").params() == {"object": "b"}


def test_stack_of_follows_on_facts_down_and_up():
    facts = {("on", "c", "b"), ("on", "b", "a"), ("ontable", "a"), ("ontable", "d")}
    assert stack_of("b", facts) == {"a", "b", "c"}
    assert stack_of("a", facts) == {"a", "b", "c"}
    assert stack_of("d", facts) == {"d"}


def test_it_changes_the_blocks_world_and_never_ends():
    with blocksworld(stacks=STACKS, agents=0, opponents=1) as world:
        run, behaviour, seen = _run(world)
        assert run.status == "timeout"  # always RUNNING
        assert len(seen) >= 2, "the blocks facts never changed"
        assert behaviour.chosen and behaviour.outcomes
        assert run.facts == []  # opponents write nothing to the world model
        assert all(t["status"] == "running" for t in run.trace)
        assert all("\n" not in str(t["feedback"]) and t["feedback"] for t in run.trace)


def _first_choices(seed, count=4, limit=150.0):
    """The first ``count`` actions the opponent chooses, running it by hand (10 ticks per simulated second)."""
    with blocksworld(stacks=STACKS, agents=0, opponents=1) as world:
        skill = RandomBlockSkill("opponent", {}, _context(world, "o1", seed))
        skill.setup()
        while len(skill.chosen) < count and world.now() < limit:
            skill.tick_once()
            assert skill.status == Status.RUNNING
            world.step(0.1)
        skill.stop(Status.INVALID)
        return [a.label for a in skill.chosen]


def test_the_same_seed_gives_the_same_choices():
    # the choices, not their timing: OMPL's generator is per process, so paths (and durations) differ
    # between two runs in one process; what was chosen, and in which order, does not
    first = _first_choices(7)
    assert len(first) == 4
    assert _first_choices(7) == first


def _park_at_every_stack(world):
    """Team robots at the work position of each stack (base centre 0.68 m in front of it)."""
    bottoms = [o for o in world.objects.values() if o.kind == "block" and ("ontable", o.name) in blocks_facts(world)]
    for robot, block in zip(
        sorted(n for n in world.robots if n.startswith("r")), sorted(bottoms, key=lambda o: o.name), strict=True
    ):
        x, y = (float(v) for v in block.position()[:2])
        side = -1.0 if robot == "r1" else 1.0
        world.robots[robot].set_pose(x, y + side * 0.68, -side * 0.5 * math.pi)


def test_stacks_with_a_robot_at_them_are_left_alone():
    with blocksworld(stacks=STACKS, agents=2, opponents=1) as world:
        _park_at_every_stack(world)
        before = blocks_facts(world)
        run, behaviour, seen = _run(world)
        assert behaviour.chosen == []
        assert blocks_facts(world) == before and len(seen) == 1
        assert "blocked by other robots" in run.reason


def test_putdown_and_stack_targets_are_checked_too():
    with blocksworld(stacks=STACKS, agents=1, opponents=1) as world:
        arm = world.robots["o1"].arm
        held = world.objects["b"]
        world.client.resetBasePositionAndOrientation(held.body_id, arm.ee_pose()[0].tolist(), (0, 0, 0, 1))
        assert arm.attach(held)
        a = world.objects["a"].position()
        world.robots["r1"].set_pose(float(a[0]), float(a[1]) - 0.68, 0.5 * math.pi)  # at the stack c on a
        skill = RandomBlockSkill("opponent", {}, _context(world, "o1"))
        skill.setup()
        facts = blocks_facts(world)
        assert [x.label for x in applicable_actions(facts, "o1")] == ["Putdown(b)", "Stack(b, c)"]
        assert [x.label for x in skill.free_actions(facts)] == ["Putdown(b)"]
        world.robots["r1"].set_pose(-1.4, 0.6, 0.0)  # near the spot straight ahead of o1 where Putdown would go
        skill = RandomBlockSkill("opponent", {}, _context(world, "o1"))
        skill.setup()
        # the opponent turns to another spot, out of r1's way
        assert [x.label for x in skill.free_actions()] == ["Putdown(b)", "Stack(b, c)"]
        spot = skill._putdown_spot(BlockAction("Putdown", "b"))
        assert math.hypot(spot[0] + 1.4, spot[1] - 0.6) >= 1.0
        # with r1 blocking every spot within reach, Putdown is left alone too
        skill = RandomBlockSkill("opponent", {"blocking_radius": 3.0}, _context(world, "o1"))
        skill.setup()
        assert skill.free_actions() == []


def test_an_opponent_blocked_everywhere_it_stands_drives_elsewhere_for_room():
    # o1 holds b with r1 right beside it: every put-down spot of its reach and the stack c on a are within the
    # blocking radius of r1; waiting there would hold b for good, so it looks for room and acts from there
    with blocksworld(stacks=STACKS, agents=1, opponents=1) as world:
        assert run_skill("Pickup", world, "o1", {"object": "b"}).ok
        x, y, _ = world.robots["o1"].pose
        world.robots["r1"].set_pose(x + 0.55, y, 0.0)
        run, behaviour, _ = _run(world, params={"blocking_radius": 1.6}, timeout=90.0)
        feedback = [t["feedback"] for t in run.trace]
        assert any("looking for room" in f for f in feedback)
        # it put b somewhere at last (it goes on acting afterwards, so at the timeout it may hold a block again)
        placed = [
            label for label, outcome, _ in behaviour.outcomes if outcome == "success" and label[:3] in ("Put", "Sta")
        ]
        assert placed and placed[0] in ("Putdown(b)", "Stack(b, c)"), behaviour.outcomes
        assert math.dist(world.robots["o1"].pose[:2], (x, y)) > 0.5


def _context(world, agent, seed=0):
    import random

    from alica.engine.behaviours import SkillContext

    return SkillContext(agent, world.now, None, None, random.Random(f"{seed}:{agent}"), world)


def test_stopping_it_stops_the_inner_skill_and_the_robot():
    with blocksworld(stacks=STACKS, agents=0, opponents=1) as world:
        skill = RandomBlockSkill("opponent", {}, _context(world, "o1"))
        skill.setup()
        for _ in range(30):  # 3 s: driving to the first stack
            skill.tick_once()
            world.step(0.1)
        inner = skill.inner
        assert skill.status == Status.RUNNING and inner is not None and inner.status == Status.RUNNING
        skill.stop(Status.INVALID)
        assert inner.status == Status.INVALID and skill.inner is None
        assert world.robots["o1"].velocity == (0.0, 0.0)


def test_bad_parameters_and_robots_without_an_arm():
    with blocksworld(stacks=STACKS, agents=0, opponents=1) as world:
        with pytest.raises(SkillError, match="blocking_radius"):
            RandomBlockSkill("opponent", {"blocking_radius": -1.0}, _context(world, "o1")).setup()
        world.add_robot("scout", "s1", (2.0, 2.0, 0.0))
        with pytest.raises(SkillError, match="has no arm"):
            RandomBlockSkill("opponent", {}, _context(world, "s1")).setup()
