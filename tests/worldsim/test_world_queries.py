"""The robot interface's queries of the world: what a spot would overlap, and the blocks' facts (perfect perception)."""

from __future__ import annotations

from alica.worldsim.interface import RobotWorld
from alica.worldsim.scenarios import blocks_facts, blocksworld


def test_the_world_answers_blocks_facts_and_blocker_through_the_robot_interface() -> None:
    with blocksworld([["c", "b", "a"]], agents=1) as w:
        w.step(1.0)
        world: RobotWorld = w  # what a skill sees
        assert world.blocks_facts() == blocks_facts(w)
        assert ("on", "a", "b") in world.blocks_facts() and ("handempty", "r1") in world.blocks_facts()
        x, y, _ = (float(v) for v in w.objects["a"].position())
        assert world.blocker(x, y, 0.05) in {"block 'a'", "block 'b'", "block 'c'"}
        rx, ry, _ = w.robots["r1"].pose
        assert world.blocker(rx, ry, 0.05) == "robot 'r1'"
        xmin, ymin, _, _ = world.bounds
        assert world.blocker(xmin + 0.1, ymin + 0.1, 0.05) is None
