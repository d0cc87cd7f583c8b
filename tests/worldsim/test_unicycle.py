"""The unicycle: a robot driver without pybullet that satisfies the robot interface (issue 38's example driver)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.skills.testing import run_skill
from alica.worldsim.errors import WorldError
from alica.worldsim.interface import RobotWorld
from alica.worldsim.unicycle import OccupancyMap, UnicycleWorld

#: A 10 m x 6.5 m room of 0.25 m cells, walled, with a block in the middle that a straight line would hit.
ROOM = (
    ["#" * 40]
    + ["#" + "." * 38 + "#"] * 10
    + ["#" + "." * 15 + "#" * 8 + "." * 15 + "#"] * 4
    + ["#" + "." * 38 + "#"] * 10
    + ["#" * 40]
)


def room(seed: int = 0, noise: float = 0.0) -> UnicycleWorld:
    world = UnicycleWorld(OccupancyMap.from_rows(ROOM, 0.25), seed=seed, lidar_noise=noise)
    world.add_robot("scout", "scout", (1.0, 3.25, 0.0))
    return world


def test_it_is_a_robot_world_with_the_maps_bounds_and_obstacles():
    world = room()
    assert isinstance(world, RobotWorld)
    assert world.bounds == (0.0, 0.0, 10.0, 6.5)
    boxes = world.ground_truth_obstacles()
    assert sum(2 * b.half_x / 0.25 for b in boxes) == int(np.sum(world.map.occupied))  # every occupied cell, merged
    assert world.robots["scout"].arm is None and world.objects == {} and world.blocks_facts() == set()


def test_the_lidar_reads_the_distance_to_the_walls():
    robot = room().robots["scout"]
    scan = robot.lidar(4)  # ahead, left, behind, right
    assert np.allclose(robot.lidar_angles(4), [0, math.pi / 2, math.pi, 3 * math.pi / 2])
    assert scan[0] == pytest.approx(3.0, abs=0.1)  # to the block at x = 4
    assert scan[1] == pytest.approx(3.0, abs=0.1) and scan[2] == pytest.approx(0.75, abs=0.1)
    assert robot.lidar(8, max_range=0.5)[0] == 0.5  # no hit reads max_range


def test_the_same_seed_gives_the_same_scans():
    scans = [room(seed=3, noise=0.05).robots["scout"].lidar(90) for _ in range(2)]
    assert np.array_equal(scans[0], scans[1])
    assert not np.array_equal(scans[0], room(seed=4, noise=0.05).robots["scout"].lidar(90))


def test_driving_integrates_arcs_and_a_wall_stops_the_robot_with_a_bump():
    world = room()
    robot = world.robots["scout"]
    robot.drive(1.0, 0.0)
    world.step(1.0)
    assert robot.pose == pytest.approx((2.0, 3.25, 0.0), abs=1e-9) and robot.estimate == pytest.approx(robot.pose)
    robot.drive(0.5, math.pi / 4)  # a quarter circle of radius 2/pi
    world.step(2.0)
    x, y, yaw = robot.pose
    assert (x, y, yaw) == pytest.approx((2.0 + 2 / math.pi, 3.25 + 2 / math.pi, math.pi / 2), abs=1e-6)
    robot.drive(1.0, 0.0)
    world.step(10.0)  # towards the top wall
    assert robot.bumped and robot.pose[1] < 6.25 - robot.spec.radius + 1e-9
    assert world.now() == pytest.approx(13.0)


def test_move_to_position_runs_on_it_around_the_block():
    world = room()
    run = run_skill("MoveToPosition", world, "scout", {"goal": [8.0, 3.25]}, timeout=60)
    assert run.status == "success", run.reason
    x, y, _ = world.robots["scout"].pose
    assert math.hypot(x - 8.0, y - 3.25) < 0.5


def test_bad_maps_and_poses_are_refused_with_a_clear_error():
    with pytest.raises(ValueError, match="'#' and '.'"):
        OccupancyMap.from_rows(["#.", "#x"], 0.25)
    with pytest.raises(ValueError, match="resolution"):
        OccupancyMap.from_rows(["#."], 0.0)
    world = room()
    with pytest.raises(WorldError, match="does not fit"):
        world.add_robot("scout", "r2", (5.0, 3.25, 0.0))  # on the block
    with pytest.raises(WorldError, match="already"):
        world.add_robot("scout", "scout", (8.0, 1.0, 0.0))
    with pytest.raises(WorldError, match="without a camera"):
        world.robots["scout"].camera()


def test_the_explore_plans_skills_map_localize_and_explore_on_it():
    cells = np.zeros((40, 40), dtype=bool)  # 10 m x 10 m, walled, two long blocks
    cells[[0, -1], :] = cells[:, [0, -1]] = True
    cells[10:14, 8:30] = True
    cells[26:30, 12:36] = True
    world = UnicycleWorld(OccupancyMap(cells, 0.25), seed=0, lidar_noise=0.01)
    world.add_robot("scout", "scout", (1.0, 1.0, 0.0))
    scratch: dict[str, object] = {}  # one agent's scratch space: the map BuildMap makes, the others use
    for skill in ("BuildMap", "Localize", "ExploreFrontier"):
        run = run_skill(skill, world, "scout", {}, timeout=200, scratch=scratch)
        assert run.status == "success", (skill, run.reason)
