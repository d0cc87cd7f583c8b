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


def test_the_interface_loads_only_plain_data_of_the_world() -> None:
    import subprocess
    import sys

    code = (
        "import sys, alica.worldsim.interface\n"
        "loaded = {m for m in sys.modules if m.startswith('alica.worldsim.')}\n"
        "assert 'pybullet' not in sys.modules, 'pybullet was imported'\n"
        "extra = loaded - {'alica.worldsim.interface', 'alica.worldsim.camera_image', 'alica.worldsim.kinds',\n"
        "                  'alica.worldsim.robot_specs'}\n"
        "assert not extra, sorted(extra)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def test_the_interface_re_exports_the_data_the_world_uses() -> None:
    from alica.worldsim import interface, objects, robot_camera, robots

    assert interface.CameraImage is robot_camera.CameraImage
    assert interface.RobotSpec is robots.RobotSpec
    assert interface.SAMPLE_KINDS is objects.SAMPLE_KINDS
    assert interface.OBJECT_KINDS is objects.OBJECT_KINDS
