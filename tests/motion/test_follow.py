"""PathFollower on a simulated unicycle, stuck and blocked detection, escape_goal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.skills.motion import FclChecker, GridChecker, PathFollower, escape_goal, plan_path
from alica.worldsim.grid import Obstacle2D, OccupancyGrid
from tests.motion.fields import CORNER_A, CORNER_B, field

RADIUS = 0.3


def drive(
    follower: PathFollower, pose: tuple[float, float, float], dt: float = 0.05, steps: int = 20000
) -> tuple[tuple[float, float, float], list[tuple[float, float]]]:
    """Integrate the unicycle x' = v cos(yaw), y' = v sin(yaw), yaw' = w until done."""
    x, y, yaw = pose
    trace = [(x, y)]
    for _ in range(steps):
        v, w, done = follower.command((x, y, yaw), dt)
        if done:
            break
        assert abs(v) <= follower.max_speed + 1e-9 and abs(w) <= follower.max_yaw_rate + 1e-9
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
        trace.append((x, y))
    return (x, y, yaw), trace


def test_follower_drives_a_unicycle_to_the_goal() -> None:
    obstacles, grid = field(3, 60)
    result = plan_path((*CORNER_A, 2.0), CORNER_B, grid, RADIUS, time_limit=5.0)
    assert result.status == "exact"
    follower = PathFollower(result.path, lookahead=0.6, max_speed=0.8, max_yaw_rate=1.5, tolerance=0.1)
    end, trace = drive(follower, (*CORNER_A, 2.0))
    assert follower.done
    assert math.dist(end[:2], result.path[-1, :2]) <= 0.1
    assert follower.progress == pytest.approx(follower.total_length, abs=0.2)
    # The unicycle stays near the path and clear of the rocks (pure pursuit cuts corners a little).
    exact = FclChecker(obstacles, RADIUS - 0.05)
    assert all(exact.valid_xy(x, y) for x, y in trace[::5])


def test_stuck_fires_when_the_pose_does_not_change() -> None:
    path = np.array([[0.0, 0.0], [5.0, 0.0]])
    follower = PathFollower(path, stuck_time=2.0)
    pose = (1.0, 0.0, 0.0)
    fired = [t for t in np.arange(0.0, 4.0, 0.1) if follower.stuck(pose, float(t))]
    assert fired and fired[0] == pytest.approx(2.1, abs=0.11)
    # Moving along the path is progress: never stuck.
    moving = PathFollower(path, stuck_time=2.0)
    assert not any(moving.stuck((0.2 * t, 0.0, 0.0), t) for t in np.arange(0.0, 20.0, 0.5))
    # Turning towards the path on the spot counts as progress too.
    turning = PathFollower(path, stuck_time=1.0)
    assert not any(turning.stuck((0.0, 0.0, 3.0 - 0.3 * t), t) for t in np.arange(0.0, 9.0, 0.5))


def test_blocked_detects_a_new_obstacle_on_the_path() -> None:
    grid = OccupancyGrid.from_obstacles([], (-6.0, -6.0, 6.0, 6.0), 0.05)
    result = plan_path((-5.0, 0.0, 0.0), (5.0, 0.0), grid, RADIUS)
    assert result.status == "exact"
    follower = PathFollower(result.path)
    pose = (-5.0, 0.0, 0.0)
    assert not follower.blocked(GridChecker(grid, RADIUS), pose)
    assert not follower.blocked(grid, pose, robot_radius=RADIUS)
    newer = grid.copy()
    newer.add_obstacles(
        [Obstacle2D("circle", 1.0, float(np.interp(1.0, result.path[:, 0], result.path[:, 1])), radius=0.2)]
    )
    assert follower.blocked(GridChecker(newer, RADIUS), pose)
    assert follower.blocked(newer, pose, robot_radius=RADIUS)
    assert not follower.blocked(newer, pose, robot_radius=RADIUS, horizon=3.0), "the obstacle is 6 m ahead"
    # Another robot on the path.
    on_path = (3.0, float(np.interp(3.0, result.path[:, 0], result.path[:, 1])), 0.3)
    assert follower.blocked(GridChecker(grid, RADIUS), pose, other_robots=[on_path])
    assert follower.blocked(FclChecker([], RADIUS), pose, other_robots=[on_path])
    # Once past the obstacle, the rest of the path is free again.
    assert not follower.blocked(newer, (2.0, on_path[1], 0.0), robot_radius=RADIUS)
    with pytest.raises(ValueError, match="robot_radius"):
        follower.blocked(newer, pose)


def test_escape_goal_out_of_a_corner() -> None:
    walls = [
        Obstacle2D("box", -2.5, 0.0, half_x=0.5, half_y=3.0),
        Obstacle2D("box", 0.0, -2.5, half_x=3.0, half_y=0.5),
    ]
    grid = OccupancyGrid.from_obstacles(walls, (-4.0, -4.0, 4.0, 4.0), 0.05)
    pose = (-1.85, -1.85, 0.0)  # wedged into the inner corner (walls end at -2.0)
    clearance = RADIUS + 0.2
    assert not GridChecker(grid, clearance, margin=0.0).valid_xy(*pose[:2])
    goal = escape_goal(grid, pose, clearance, max_distance=2.0)
    assert goal is not None
    assert GridChecker(grid, clearance, margin=0.0).valid_xy(*goal)
    assert math.dist(goal, pose[:2]) <= 2.0
    assert goal[0] > pose[0] and goal[1] > pose[1], "away from both walls"
    assert math.dist(goal, pose[:2]) < 0.7, "the nearest free spot (0.43 m out along each axis), not a far one"
    # Planning from there works.
    assert plan_path((*goal, 0.0), (3.0, 3.0), grid, RADIUS).status == "exact"
    assert escape_goal(grid, pose, clearance, max_distance=0.1) is None
    # Off the grid counts as occupied.
    edge = escape_goal(grid, (3.95, 3.95), 0.5, max_distance=2.0)
    assert edge is not None and edge[0] <= 3.5 + 1e-9 and edge[1] <= 3.5 + 1e-9


def test_escape_goal_leads_away_from_what_the_robot_touches() -> None:
    # a base refuses any move deeper into what it touches: a robot touching a block (seed 15 of the 5-agent demo)
    # could not take a straight line past the block to the nearest free spot, and gave up after 5 escapes
    block = Obstacle2D("box", -0.4, 0.0, half_x=0.025, half_y=0.025)
    rocks = [Obstacle2D("circle", x, y, radius=0.1) for x, y in [(-0.85, -0.2), (0.14, -0.75), (-0.69, 0.09)]]
    grid = OccupancyGrid.from_obstacles([block, *rocks], (-3.0, -3.0, 3.0, 3.0), 0.05)
    pose = (-0.3, -0.26, math.pi)  # 0.28 m from the block's centre: a base of radius 0.25 touches it

    def towards_block(spot):
        return (spot[0] - pose[0]) * (-0.4 - pose[0]) + (spot[1] - pose[1]) * (0.0 - pose[1])

    nearest = escape_goal(grid, pose, 0.55, max_distance=3.0)
    out = escape_goal(grid, pose, 0.55, max_distance=3.0, body_radius=0.25)
    assert nearest is not None and towards_block(nearest) > -0.01  # sideways past the block
    assert out is not None and towards_block(out) < -0.05  # away from it
    assert math.dist(out, pose[:2]) > math.dist(nearest, pose[:2])
    assert GridChecker(grid, 0.55, margin=0.0).valid_xy(*out)
    # with nothing leading away, the nearest free spot still (a wall right behind the robot)
    wall = Obstacle2D("box", -0.3, -0.6, half_x=3.0, half_y=0.05)
    boxed = OccupancyGrid.from_obstacles([block, wall], (-3.0, -3.0, 3.0, 3.0), 0.05)
    fallback = escape_goal(boxed, pose, 0.55, max_distance=3.0, body_radius=0.25)
    assert fallback is not None and fallback == escape_goal(boxed, pose, 0.55, max_distance=3.0)


def test_follower_bad_arguments() -> None:
    with pytest.raises(ValueError, match="path"):
        PathFollower(np.zeros((0, 2)))
    with pytest.raises(ValueError, match="lookahead"):
        PathFollower(np.zeros((2, 2)), lookahead=0.0)
    single = PathFollower(np.array([[1.0, 1.0]]))
    assert single.command((1.0, 1.05, 0.0), 0.1) == (0.0, 0.0, True)
