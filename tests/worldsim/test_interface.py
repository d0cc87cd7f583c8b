"""The world offers the robot interface the skills act through."""

from __future__ import annotations

from alica.worldsim.interface import RobotWorld
from alica.worldsim.scenarios import blocksworld


def test_the_world_is_a_robot_world() -> None:
    with blocksworld([["a", "b"]], agents=1) as world:
        assert isinstance(world, RobotWorld)
        block = world.objects["a"]
        assert block.kind == "block" and block.radius == 0.0 and block.half_extents[0] > 0.0
        assert world.robots["r1"].arm is not None


def test_something_else_is_not() -> None:
    assert not isinstance(object(), RobotWorld)
