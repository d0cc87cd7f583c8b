"""Odometry with seeded drift: the robots' pose estimates."""

from __future__ import annotations

import math

import pytest

from alica.worldsim.errors import WorldError

pytest.importorskip("pybullet")

from alica.worldsim.scenarios import lunar


def _drive(world, name: str = "scout") -> None:
    robot = world.robots[name]
    robot.drive(0.8, 0.3)
    world.step(5.0)
    robot.drive(0.8, -0.4)
    world.step(5.0)
    robot.stop()


def test_without_drift_the_estimate_is_the_true_pose() -> None:
    with lunar(seed=3, rocks=0, samples=0) as world:
        _drive(world)
        robot = world.robots["scout"]
        assert robot.estimate == robot.pose
        assert robot.odometry.distance == pytest.approx(8.0, abs=0.05)


def test_drift_is_seeded_grows_with_the_distance_and_leaves_the_world_rng_alone() -> None:
    errors = []
    draws = []
    for seed in (5, 5, 6):
        with lunar(seed=seed, rocks=0, samples=0) as world:
            world.faults.set_sensor_noise(odometry_drift=0.02)
            _drive(world)
            robot = world.robots["scout"]
            x, y, yaw = robot.pose
            ex, ey, eyaw = robot.estimate
            errors.append((math.hypot(x - ex, y - ey), abs(math.remainder(yaw - eyaw, 2 * math.pi))))
            draws.append(float(world.rng.random()))
    assert errors[0] == errors[1]  # the same seed drifts alike
    assert errors[0] != errors[2]
    assert all(0.0 < e < 0.1 * 8.0 for e, _ in errors)  # some drift, bounded by a few % of 8 m
    with lunar(seed=5, rocks=0, samples=0) as world:
        _drive(world)
        assert float(world.rng.random()) == draws[0]  # drift does not draw from the world's rng


def test_set_estimate_corrects_and_set_pose_resets() -> None:
    with lunar(seed=1, rocks=0, samples=0) as world:
        world.faults.set_sensor_noise(odometry_drift=0.02)
        robot = world.robots["scout"]
        robot.set_estimate((1.0, 2.0, 0.5))
        assert robot.estimate == (1.0, 2.0, 0.5)
        robot.drive(1.0, 0.0)
        world.step(1.0)
        ex, ey, _ = robot.estimate
        assert math.hypot(ex - 1.0, ey - 2.0) == pytest.approx(1.0, abs=0.1)  # odometry continues from it
        robot.set_pose(3.0, 3.0, 0.0)
        assert robot.estimate == pytest.approx(robot.pose)
        with pytest.raises(WorldError, match="set_estimate"):
            robot.set_estimate((1.0, "x", 0.0))  # type: ignore[arg-type]
        with pytest.raises(WorldError, match="finite"):
            robot.set_estimate((math.nan, 0.0, 0.0))


def test_save_and_restore_bring_the_estimate_back() -> None:
    with lunar(seed=2, rocks=0, samples=0) as world:
        world.faults.set_sensor_noise(odometry_drift=0.05)
        robot = world.robots["scout"]
        _drive(world)
        state = world.snapshots.save()
        saved = robot.estimate
        _drive(world)
        assert robot.estimate != saved
        world.snapshots.restore(state)
        assert robot.estimate == saved


def test_bad_drift_is_refused() -> None:
    with lunar(seed=0, rocks=0, samples=0) as world:
        for bad in (-0.1, 1.5, math.nan):
            with pytest.raises(WorldError, match="odometry_drift"):
                world.faults.set_sensor_noise(odometry_drift=bad)
        assert world.faults.set_sensor_noise(odometry_drift=0.02).odometry_drift == 0.02
