"""Robot kinds (IMPERA Section 2 and plans/roles.yaml), driving, bumping and crashing."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from alica.io import load_library
from alica.worldsim.errors import WorldError
from alica.worldsim.faults import crash
from alica.worldsim.robots import ROBOT_KINDS, RobotSpec
from alica.worldsim.world import World

ROOT = Path(__file__).resolve().parents[2]


def test_capabilities_match_the_impera_roles() -> None:
    library = load_library(ROOT / "plans" / "roles.yaml")
    roles = {role.name: role for role in library.rolesets["Impera"].roles}
    for kind, role in (("scout", "Scout"), ("stummel", "Stummel"), ("amparo", "Amparo")):
        assert ROBOT_KINDS[kind].capabilities == roles[role].requires
    # Scout has no arm; Amparo is the slow, heavy one with 3-D perception.
    assert not ROBOT_KINDS["scout"].has_arm
    assert ROBOT_KINDS["stummel"].has_arm and ROBOT_KINDS["amparo"].has_arm
    assert ROBOT_KINDS["scout"].max_speed > ROBOT_KINDS["stummel"].max_speed > ROBOT_KINDS["amparo"].max_speed
    assert ROBOT_KINDS["amparo"].perception == "3d" and ROBOT_KINDS["scout"].perception == "camera"


def test_manipulators_fill_the_blocks_world_roles() -> None:
    library = load_library(ROOT / "plans" / "blocksworld" / "roles.yaml")
    needs = library.rolesets["BlocksTeam"].roles[0].requires
    assert needs <= ROBOT_KINDS["manipulator"].capabilities


def test_spec_is_a_frozen_value() -> None:
    spec = ROBOT_KINDS["scout"]
    assert isinstance(spec, RobotSpec)
    with pytest.raises(AttributeError):
        spec.max_speed = 3.0  # type: ignore[misc]


def test_drives_straight_to_a_point(world: World) -> None:
    r = world.add_robot("scout", "s", (-2.0, 1.0, 0.0))
    r.drive(1.0, 0.0)
    world.step(3.0)
    x, y, yaw = r.pose
    assert x == pytest.approx(1.0, abs=1e-6) and y == pytest.approx(1.0) and yaw == 0.0
    pos, _ = world.client.getBasePositionAndOrientation(r.body_id)
    assert pos[0] == pytest.approx(1.0, abs=1e-6)
    assert not r.bumped


def test_turning_follows_an_arc(world: World) -> None:
    r = world.add_robot("stummel", "s", (0.0, 0.0, 0.0))
    r.drive(0.5, 0.5)  # radius 1 m
    n = world.step(math.pi)  # a quarter circle, to within one physics step
    t = n * world.time_step
    x, y, yaw = r.pose
    assert (x, y) == pytest.approx((math.sin(0.5 * t), 1.0 - math.cos(0.5 * t)), abs=1e-6)
    assert yaw == pytest.approx(0.5 * t)
    # the arm rides along on its mount
    (ax, ay, _az), _ = r.arm.base_pose()
    assert math.hypot(ax - x, ay - y) == pytest.approx(r.arm.mount_offset[0])
    link0 = world.client.getLinkState(r.arm.body_id, 0, computeForwardKinematics=1)[4]
    assert link0[:2] == pytest.approx((ax, ay), abs=1e-6)


def test_commands_are_clipped_to_the_spec(world: World) -> None:
    r = world.add_robot("amparo", "a", (0.0, 0.0, 0.0))
    r.drive(10.0, -10.0)
    assert r.velocity == (r.spec.max_speed, -r.spec.max_yaw_rate)
    world.step(1.0)
    assert math.hypot(*r.pose[:2]) <= r.spec.max_speed + 1e-9
    r.stop()
    assert r.velocity == (0.0, 0.0)


def test_stops_when_bumping_a_rock(world: World) -> None:
    world.add_rock("rock", (3.0, 0.0), 0.5, seed=2)
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    r.drive(1.0, 0.0)
    world.step(5.0)
    assert r.bumped
    assert r.velocity == (0.0, 0.0)
    gap = 3.0 - r.pose[0] - 0.5 - r.spec.radius
    assert 0.0 <= gap < 1.0 * world.time_step + 1e-9  # stopped within one step of the rock
    r.drive(-0.5, 0.0)  # backing off clears the flag and works
    assert not r.bumped
    world.step(1.0)
    assert r.pose[0] == pytest.approx(3.0 - 0.75 - gap - 0.5, abs=1e-6)


def test_bumps_into_other_robots_tables_blocks_and_the_border(world: World) -> None:
    world.add_table("t", (0.0, 3.0), size=(2.0, 0.6))
    world.add_block("b", (-3.0, 0.0))
    world.add_robot("amparo", "other", (3.0, 0.0, 0.0))
    movers = {
        "to_robot": world.add_robot("scout", "r1", (1.5, 0.0, 0.0)),
        "to_table": world.add_robot("scout", "r2", (0.0, 1.5, math.pi / 2)),
        "to_block": world.add_robot("scout", "r3", (-1.5, 0.0, math.pi)),
        "to_border": world.add_robot("scout", "r4", (0.0, -8.0, -math.pi / 2)),
    }
    for r in movers.values():
        r.drive(1.0, 0.0)
    world.step(4.0)
    assert all(r.bumped for r in movers.values())
    assert movers["to_robot"].pose[0] == pytest.approx(3.0 - 0.35 - 0.25, abs=0.01)
    assert movers["to_table"].pose[1] == pytest.approx(3.0 - 0.3 - 0.25, abs=0.01)
    assert movers["to_block"].pose[0] == pytest.approx(-3.0 + 0.025 + 0.25, abs=0.01)
    assert movers["to_border"].pose[1] == pytest.approx(-10.0 + 0.25, abs=0.01)


def test_a_robot_put_into_an_overlap_can_drive_out(world: World) -> None:
    world.add_rock("rock", (2.0, 0.0), 0.5)
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    r.set_pose(1.4, 0.0, math.pi)  # overlapping the rock
    r.drive(0.5, 0.0)  # away from it
    world.step(1.0)
    assert not r.bumped and r.pose[0] < 1.0


def test_crash_stops_the_robot_and_ignores_commands(world: World) -> None:
    r = world.add_robot("stummel", "s", (0.0, 0.0, 0.0))
    r.drive(0.5, 0.0)
    world.step(1.0)
    arm_q = r.arm.q()
    r.arm.follow(r.arm.home_q[None, :] + 0.3, 2.0)
    crash(r)
    assert r.crashed and not r.arm.busy
    here = r.pose
    r.drive(0.5, 0.2)
    r.arm.follow(r.arm.home_q[None, :] - 0.3, 1.0)
    r.arm.open()
    world.step(2.0)
    assert r.pose == here
    assert (r.arm.q() == arm_q).all()
    assert r.velocity == (0.0, 0.0)


def test_crash_by_name_through_the_world(world: World) -> None:
    world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    world.faults.crash("s")
    assert world.robots["s"].crashed
    with pytest.raises(WorldError, match="no robot named 'x'"):
        world.faults.crash("x")


def test_set_pose_checks_the_field(world: World) -> None:
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    r.set_pose((1.0, 2.0, 0.5))
    assert r.pose == (1.0, 2.0, 0.5)
    with pytest.raises(WorldError, match="off the field"):
        r.set_pose(30.0, 0.0, 0.0)
    with pytest.raises(WorldError, match="finite"):
        r.drive(math.nan, 0.0)
