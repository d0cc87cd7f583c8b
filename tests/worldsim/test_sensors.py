"""Lidar, perception model and occupancy grids from scans."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from alica.worldsim.errors import WorldError
from alica.worldsim.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from alica.worldsim.objects import SAMPLE_KINDS
from alica.worldsim.sensors import Detection, lidar_angles, lidar_scan, perceive, scan_to_grid, unknown_grid
from alica.worldsim.world import World


def _ray(angle: float, n: int = 360) -> int:
    return int(np.argmin(np.abs(np.angle(np.exp(1j * (lidar_angles(n) - angle))))))


def test_lidar_sees_a_rock_at_the_right_distance(world: World) -> None:
    world.add_rock("rock", (4.0, 0.0), 0.6, seed=1)
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    ranges = lidar_scan(r)
    assert ranges.shape == (360,)
    ahead = ranges[_ray(0.0)]
    # the scan plane cuts the rock a little inside its footprint circle
    assert 4.0 - 0.6 <= ahead <= 4.0 - 0.3
    assert ranges[_ray(math.pi)] == r.spec.lidar_range  # nothing behind
    # turning the robot turns the scan
    r.set_pose(0.0, 0.0, math.pi / 2)
    assert lidar_scan(r)[_ray(-math.pi / 2)] == pytest.approx(ahead, abs=1e-6)


def test_lidar_ignores_the_robot_itself_but_sees_others(world: World) -> None:
    r = world.add_robot("stummel", "s", (0.0, 0.0, 0.0))
    world.add_robot("scout", "other", (0.0, 2.0, 0.0))
    # put the arm down through the scan plane in front of the robot
    q = r.arm.home_q.copy()
    q[1], q[3], q[5] = 1.2, -1.2, 2.4
    r.arm.set_q(q)
    ranges = lidar_scan(r, max_range=8.0)
    assert ranges[_ray(0.0)] == 8.0
    assert ranges[_ray(math.pi / 2)] == pytest.approx(2.0 - 0.25, abs=0.01)


def test_lidar_noise_is_seeded_and_bounded(world: World) -> None:
    world.add_rock("rock", (4.0, 0.0), 0.6)
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    clean = lidar_scan(r)
    world.faults.set_sensor_noise(lidar_sigma=0.02)
    noisy = lidar_scan(r)
    hit = clean < r.spec.lidar_range
    assert hit.any()
    assert np.all(noisy[~hit] == clean[~hit])
    assert 0 < np.abs(noisy[hit] - clean[hit]).max() < 0.1
    assert np.array_equal(lidar_scan(r, noise=0.0), clean)


def test_lidar_argument_errors(world: World) -> None:
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    with pytest.raises(WorldError, match="at least 1 ray"):
        lidar_scan(r, n_rays=0)
    with pytest.raises(WorldError, match="max_range"):
        lidar_scan(r, max_range=0.1)


def test_perception_finds_a_sample_in_range_with_bounded_noise() -> None:
    errors = []
    for seed in range(10):
        with World(seed=seed) as w:
            w.add_sample("a", "green-black-red", (2.0, 0.3))
            r = w.add_robot("amparo", "amparo", (0.0, 0.0, 0.0))
            (det,) = perceive(r)
            assert isinstance(det, Detection) and det.name == "a"
            assert 0.0 < det.confidence <= 1.0
            errors.append(math.dist(det.position[:2], (2.0, 0.3)))
    sigma = World().noise.position_sigma * 0.25 * (1 + 2.0 / 6.0)
    assert max(errors) < 5 * sigma
    assert min(errors) > 0.0


def test_perception_range_field_of_view_and_occlusion(world: World) -> None:
    world.add_sample("near", "red-black-red", (2.0, 0.0))
    world.add_sample("behind", "red-black-red", (-2.0, 0.0))
    world.add_sample("far", "red-black-red", (9.0, 3.0))
    world.add_sample("hidden", "red-black-red", (0.0, 3.0))
    world.add_rock("wall", (0.0, 1.6), 0.8)
    world.add_block("blk", (2.0, 0.8))
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    assert [d.name for d in perceive(r)] == ["blk", "near"]
    assert {d.kind for d in perceive(r)} <= {"block", *SAMPLE_KINDS}
    assert "far" in [d.name for d in perceive(r, max_range=10.0)]
    assert "hidden" not in [d.name for d in perceive(r, fov=2 * math.pi)]
    assert "behind" in [d.name for d in perceive(r, fov=2 * math.pi)]


def test_camera_misclassifies_more_than_3d() -> None:
    def wrong(kind: str, p: float) -> int:
        with World(seed=1) as w:
            w.noise = dataclasses.replace(w.noise, camera_misclassification=p, stereo_misclassification=p / 10)
            w.add_sample("a", "green-white-green", (1.5, 0.0))
            r = w.add_robot(kind, "r", (0.0, 0.0, 0.0))
            return sum(perceive(r)[0].kind != "green-white-green" for _ in range(200))

    assert wrong("stummel", 1.0) == 200
    assert wrong("amparo", 1.0) < 50
    assert wrong("stummel", 0.0) == 0


def test_grid_from_scans_marks_the_rock(world: World) -> None:
    world.add_rock("rock", (4.0, 1.0), 0.7, seed=5)
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    grid = unknown_grid(world.bounds, resolution=0.1)
    assert isinstance(grid, OccupancyGrid) and (grid.cells == UNKNOWN).all()
    hits = scan_to_grid(grid, r, lidar_scan(r, max_range=8.0), max_range=8.0)
    assert hits > 0
    assert grid.value(4.0 - 0.65, 1.0) == OCCUPIED or grid.value(4.0 - 0.55, 1.0) == OCCUPIED
    assert grid.value(2.0, 0.5) == FREE  # between the robot and the rock
    assert grid.value(6.0, 1.0) == UNKNOWN  # in the rock's shadow
    assert grid.value(-5.0, -5.0) == FREE  # open space within range
    assert grid.value(-9.5, -9.5) == UNKNOWN  # out of range
    occupied = np.argwhere(grid.cells == OCCUPIED)
    centres = np.array([grid.cell_to_world(i, j) for j, i in occupied])
    assert np.all(np.hypot(centres[:, 0] - 4.0, centres[:, 1] - 1.0) < 0.7 + 0.1)


def test_set_sensor_noise_zero_gives_exact_positions(world: World) -> None:
    from alica.worldsim.faults import set_sensor_noise

    noise = set_sensor_noise(world, lidar_sigma=0.0, position_sigma=0.0)
    assert noise.position_sigma == 0.0 and world.noise is noise
    sample = world.add_sample("a", "green-black-green", (1.5, 0.0))
    r = world.add_robot("amparo", "r", (0.0, 0.0, 0.0))
    assert perceive(r)[0].position == pytest.approx(tuple(sample.position()))


def test_lidar_casts_only_what_can_be_hit_and_reads_as_a_whole_scan() -> None:
    """Rays that meet no body's box are not cast, the others only as far as the last box: the ranges are
    those of every ray cast over the whole range (up to pybullet's precision)."""
    from alica.worldsim.scenarios import lunar
    from alica.worldsim.sensors import _cast, _own_bodies

    world = lunar(seed=3, rocks=30, samples=3, size=24.0)
    try:
        robot = world.robots["stummel"]
        rng = np.random.default_rng(0)
        for _ in range(6):
            x, y = rng.uniform(-10.0, 10.0, 2)
            robot.set_pose(float(x), float(y), float(rng.uniform(-3.0, 3.0)))
            for reach in (30.0, 6.0):
                ranges = lidar_scan(robot, 720, reach, noise=0.0)
                px, py, yaw = robot.pose
                angles = yaw + lidar_angles(720)
                dirs = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(720)])
                origin = np.array([px, py, robot.spec.lidar_height])
                start = robot.spec.radius + 0.01
                fractions, bodies = _cast(world, origin + start * dirs, origin + reach * dirs, _own_bodies(robot))
                whole = np.where(bodies >= 0, start + fractions * (reach - start), reach)
                assert np.array_equal(ranges < reach, whole < reach)
                assert np.abs(ranges - whole).max() < 0.01
    finally:
        world.close()
