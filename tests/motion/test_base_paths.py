"""plan_path on random rock fields: exact paths checked on the grid and with FCL, failures with reasons."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from alica.skills.motion import FclChecker, GridChecker, densify, plan_path
from alica.worldsim.grid import Obstacle2D, OccupancyGrid
from tests.motion.fields import BOUNDS, CORNER_A, CORNER_B, field

ROOT = Path(__file__).resolve().parents[2]
RADIUS = 0.3


def assert_path_valid(
    path: np.ndarray, grid: OccupancyGrid, obstacles: list, radius: float = RADIUS, robots: tuple = ()
) -> None:
    """Every state sampled along the path (every 2.5 cm) is valid in the grid (inflated by the radius) and in FCL."""
    pts = densify(path, 0.025)
    plain = GridChecker(grid, radius, margin=0.0, other_robots=robots)
    assert plain.valid_points(pts).all()
    exact = FclChecker(obstacles, radius)
    exact.set_other_robots(robots)
    assert all(exact.valid_xy(float(x), float(y)) for x, y in pts)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_corner_to_corner_exact_and_valid(seed: int) -> None:
    obstacles, grid = field(seed, 60)
    exact = FclChecker(obstacles, RADIUS)
    start = (*CORNER_A, 0.0)
    result = plan_path(start, CORNER_B, grid, RADIUS, obstacles_exact=exact, time_limit=5.0)
    assert result.status == "exact", result.reason
    assert result.ok
    path = result.path
    assert path.shape[1] == 3 and len(path) >= 2
    assert np.allclose(path[0], start)
    assert math.dist(path[-1, :2], CORNER_B) <= 0.1 + 1e-9
    straight = math.dist(CORNER_A, CORNER_B)
    assert result.length >= straight - 0.1 - 1e-9  # the path ends within the goal tolerance (0.1 m) of the corner
    assert result.length == pytest.approx(np.hypot(*np.diff(path[:, :2], axis=0).T).sum())
    assert_path_valid(path, grid, obstacles)


def test_optimised_path_not_longer_and_valid() -> None:
    obstacles, grid = field(5, 60)
    checker = GridChecker(grid, RADIUS)
    first = plan_path((*CORNER_A, 0.0), CORNER_B, checker, RADIUS, time_limit=5.0)
    better = plan_path((*CORNER_A, 0.0), CORNER_B, checker, RADIUS, time_limit=5.0, optimize_time=0.2)
    assert first.status == better.status == "exact"
    assert better.length >= math.dist(CORNER_A, CORNER_B) - 1e-9
    assert_path_valid(better.path, grid, obstacles)


def test_goal_with_heading() -> None:
    _, grid = field(6, 60)
    result = plan_path((*CORNER_A, 0.0), (*CORNER_B, 1.0), grid, RADIUS, any_yaw=False, time_limit=5.0)
    assert result.status == "exact", result.reason
    assert result.path[-1, 2] == pytest.approx(1.0)
    assert math.dist(result.path[-1, :2], CORNER_B) <= 0.1
    with pytest.raises(ValueError, match="any_yaw=False"):
        plan_path((*CORNER_A, 0.0), CORNER_B, grid, RADIUS, any_yaw=False)


def test_goal_inside_a_rock_is_invalid_goal() -> None:
    obstacles, grid = field(1, 60)
    rock = max(obstacles, key=lambda o: o.radius)
    result = plan_path((*CORNER_A, 0.0), (rock.x, rock.y), grid, RADIUS)
    assert result.status == "invalid_goal"
    assert "inside an obstacle" in result.reason
    assert len(result.path) == 0 and not result.ok
    outside = plan_path((*CORNER_A, 0.0), (25.0, 0.0), grid, RADIUS)
    assert outside.status == "invalid_goal" and "outside the grid" in outside.reason


def test_start_in_a_rock_is_invalid_start() -> None:
    obstacles, grid = field(1, 60)
    rock = obstacles[0]
    result = plan_path((rock.x, rock.y, 0.0), CORNER_B, grid, RADIUS)
    assert result.status == "invalid_start" and "start" in result.reason


def test_enclosed_goal_is_unreachable_quickly() -> None:
    ring = [
        Obstacle2D("circle", 5.0 + 3.0 * math.cos(a), 5.0 + 3.0 * math.sin(a), radius=0.5)
        for a in np.linspace(0.0, 2.0 * math.pi, 24, endpoint=False)
    ]
    obstacles, _ = field(2, 40)
    obstacles = [o for o in obstacles if math.hypot(o.x - 5.0, o.y - 5.0) > 5.0] + ring
    grid = OccupancyGrid.from_obstacles(obstacles, BOUNDS, 0.05)
    # With a 30 s limit, anything but the flood-fill answer would end as "timeout" after 30 s.
    result = plan_path((*CORNER_A, 0.0), (5.0, 5.0), grid, RADIUS, time_limit=30.0)
    assert result.status == "unreachable"
    assert "enclosed" in result.reason  # the flood fill's answer, not the 30 s timeout's


def test_other_robot_in_the_way_is_avoided() -> None:
    grid = OccupancyGrid.from_obstacles([], (-6.0, -6.0, 6.0, 6.0), 0.05)
    free = plan_path((-5.0, 0.0, 0.0), (5.0, 0.0), grid, RADIUS)
    assert free.status == "exact"
    other = (0.0, 0.0, 0.5)
    assert np.hypot(*densify(free.path, 0.05).T).min() < RADIUS + other[2], "the free path passes the robot's spot"
    exact = FclChecker([], RADIUS)
    result = plan_path((-5.0, 0.0, 0.0), (5.0, 0.0), grid, RADIUS, other_robots=[other], obstacles_exact=exact)
    assert result.status == "exact", result.reason
    pts = densify(result.path, 0.01)
    assert np.hypot(*pts.T).min() >= RADIUS + other[2]
    assert_path_valid(result.path, grid, [], robots=(other,))
    blocked_goal = plan_path((-5.0, 0.0, 0.0), (0.2, 0.0), grid, RADIUS, other_robots=[other])
    assert blocked_goal.status == "invalid_goal" and "another robot" in blocked_goal.reason


def test_rock_missing_from_the_grid_is_caught_by_the_exact_check() -> None:
    grid = OccupancyGrid.from_obstacles([], (-6.0, -6.0, 6.0, 6.0), 0.05)
    rock = trimesh.creation.icosphere(subdivisions=1, radius=0.6)
    rock.apply_translation([0.0, 0.0, 0.3])
    exact = FclChecker([rock], RADIUS)
    straight = np.array([[-5.0, 0.0], [5.0, 0.0]])
    assert exact.first_collision(straight) is not None and GridChecker(grid, RADIUS).first_invalid(straight) is None
    result = plan_path((-5.0, 0.0, 0.0), (5.0, 0.0), grid, RADIUS, obstacles_exact=exact, time_limit=5.0)
    # The grid-only path would cross the rock: it is blocked where FCL finds contact, then replanned.
    assert result.status == "exact", result.reason
    assert exact.first_collision(result.path, 0.01) is None
    hidden = trimesh.creation.box(extents=(0.4, 12.0, 1.0))
    wall = FclChecker([hidden], RADIUS)
    walled = plan_path((-5.0, 0.0, 0.0), (5.0, 0.0), grid, RADIUS, obstacles_exact=wall, time_limit=0.5)
    assert walled.status == "timeout" and "exact (FCL) check" in walled.reason
    assert len(walled.path) == 0


SCRIPT = """
import json, sys
from alica.skills.motion import plan_path
from tests.motion.fields import CORNER_A, CORNER_B, field
_, grid = field(8, 60)
out = []
for _ in range(2):
    r = plan_path((*CORNER_A, 0.0), CORNER_B, grid, 0.3, seed=int(sys.argv[1]), time_limit=5.0)
    out.append([r.status, r.path.round(12).tolist()])
print(json.dumps(out))
"""


def run_seeded(seed: int) -> list:
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(seed)], cwd=ROOT, capture_output=True, text=True, timeout=120, check=True
    )
    return json.loads(done.stdout)


def test_same_seed_same_paths_across_processes() -> None:
    first, second = run_seeded(11), run_seeded(11)
    assert first[0][0] == "exact"
    assert first == second


def test_bad_arguments_raise() -> None:
    _, grid = field(1, 10)
    with pytest.raises(ValueError, match="outside the grid"):
        plan_path((30.0, 0.0, 0.0), CORNER_B, grid, RADIUS)
    with pytest.raises(ValueError, match="robot_radius"):
        plan_path((*CORNER_A, 0.0), CORNER_B, grid, -0.1)
    with pytest.raises(ValueError, match="time_limit"):
        plan_path((*CORNER_A, 0.0), CORNER_B, grid, RADIUS, time_limit=0.0)
    with pytest.raises(ValueError, match="start"):
        plan_path((1.0, 2.0), CORNER_B, grid, RADIUS)
    with pytest.raises(ValueError, match="radius"):
        plan_path((*CORNER_A, 0.0), CORNER_B, GridChecker(grid, 0.5), RADIUS)
