"""plan_arm: paths around obstacles, invalid endpoints, holding an object, reproducibility."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from alica.skills.manipulation import Box, interpolate_path, path_is_free, plan_arm, solve_ik, top_down_quat
from alica.worldsim.arm_scene import ArmScene
from tests.manipulation.helpers import assert_path_free, dense_states

ROOT = Path(__file__).resolve().parents[2]
WALL = Box("wall", (0.5, 0.0, 0.25), (0.08, 0.03, 0.25))


def _either_side_of_the_wall(scene: ArmScene) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    a = solve_ik(scene, (0.5, 0.25, 0.15), top_down_quat(0.0), rng=rng)
    b = solve_ik(scene, (0.5, -0.25, 0.15), top_down_quat(0.0), rng=rng)
    assert a.ok and b.ok
    return a.q, b.q


def test_path_around_a_box_is_collision_free_when_rechecked(scene: ArmScene) -> None:
    scene.set_obstacles([WALL])
    start, goal = _either_side_of_the_wall(scene)
    assert not path_is_free(scene, np.stack([start, goal]))  # the direct move hits the wall
    result = plan_arm(scene, start, goal, time_limit=5.0)
    assert result.status == "exact" and result.ok, result.reason
    assert result.path.shape[1] == 7 and len(result.path) >= 3
    assert np.allclose(result.path[0], start) and np.allclose(result.path[-1], goal)
    assert result.plan_time_s > 0.0
    assert_path_free(scene, result.path, step=0.02)
    unsimplified = plan_arm(scene, start, goal, time_limit=5.0, simplify=False)
    assert unsimplified.ok
    assert_path_free(scene, unsimplified.path, step=0.02)


def test_a_free_direct_segment_is_returned_as_is(scene: ArmScene) -> None:
    result = plan_arm(scene, scene.home_q, scene.rest_q)
    assert result.ok and len(result.path) == 2 and "direct" in result.reason
    assert_path_free(scene, result.path)


def test_invalid_start_and_goal(scene: ArmScene) -> None:
    scene.set_obstacles([WALL])
    start, goal = _either_side_of_the_wall(scene)
    inside = np.array([0.0, 1.7, 0.0, -0.3, 0.0, 2.5, 0.785])  # tool below the ground
    assert scene.in_collision(inside)
    bad_start = plan_arm(scene, inside, goal)
    assert bad_start.status == "invalid_start" and "collision" in bad_start.reason
    assert bad_start.path.shape == (0, 7) and not bad_start.ok
    bad_goal = plan_arm(scene, start, inside)
    assert bad_goal.status == "invalid_goal" and "collision" in bad_goal.reason
    beyond = start.copy()
    beyond[3] = 0.5  # joint 4's upper limit is 0
    limits = plan_arm(scene, beyond, goal)
    assert limits.status == "invalid_start" and "joint limits" in limits.reason


def test_tiny_budget_times_out(scene: ArmScene) -> None:
    scene.set_obstacles([WALL])
    start, goal = _either_side_of_the_wall(scene)
    result = plan_arm(scene, start, goal, time_limit=1e-4)
    assert result.status == "timeout" and result.path.shape == (0, 7)


def test_the_held_box_is_checked_along_the_path(scene: ArmScene) -> None:
    """A post the bare hand clears but a 20 cm object hanging from it would hit: the path avoids it."""
    long = Box("long", (0.0, 0.0, 0.1), (0.02, 0.02, 0.1))
    rng = np.random.default_rng(0)
    a = solve_ik(scene, (0.5, 0.3, 0.4), top_down_quat(0.0), rng=rng, held=long)
    b = solve_ik(scene, (0.5, -0.3, 0.4), top_down_quat(0.0), rng=rng, held=long)
    assert a.ok and b.ok
    direct = np.stack([a.q, b.q])
    # Put the post under the middle of the direct motion, its top 6 cm under the tool.
    tools = [scene.fk(q)[0] for q in dense_states(direct)]
    mid = min(tools, key=lambda p: abs(p[1]))
    height = mid[2] - 0.06
    scene.set_obstacles([Box("post", (mid[0], mid[1], height / 2), (0.04, 0.04, height / 2))])
    assert path_is_free(scene, direct)
    assert not path_is_free(scene, direct, long)
    result = plan_arm(scene, a.q, b.q, held=long, time_limit=5.0)
    assert result.ok, result.reason
    assert "RRTConnect" in result.reason
    assert_path_free(scene, result.path, held=long)


def test_interpolation_and_bad_arguments(scene: ArmScene) -> None:
    path = np.array([[0.0] * 7, [0.1, 0, 0, 0, 0, 0, 0.05]])
    states = interpolate_path(path, 0.02)
    assert len(states) == 6 and np.allclose(states[-1], path[-1])
    assert np.max(np.abs(np.diff(states, axis=0))) <= 0.02 + 1e-12
    with pytest.raises(ValueError, match="7 joint values"):
        plan_arm(scene, [0.0] * 6, scene.rest_q)
    with pytest.raises(ValueError, match="NaN"):
        plan_arm(scene, scene.home_q, [float("nan")] * 7)
    with pytest.raises(ValueError, match="time_limit"):
        plan_arm(scene, scene.home_q, scene.rest_q, time_limit=0.0)


_SCRIPT = """
import json, sys
import numpy as np
from alica.skills.manipulation import Box, plan_arm, solve_ik, top_down_quat
from alica.worldsim.arm_scene import ArmScene
scene = ArmScene(obstacles=[Box("wall", (0.5, 0.0, 0.25), (0.08, 0.03, 0.25))])
rng = np.random.default_rng(0)
a = solve_ik(scene, (0.5, 0.25, 0.15), top_down_quat(0.0), rng=rng)
b = solve_ik(scene, (0.5, -0.25, 0.15), top_down_quat(0.0), rng=rng)
paths = [plan_arm(scene, a.q, b.q, seed=int(sys.argv[1]), time_limit=30.0).path.round(12).tolist() for _ in range(2)]
print(json.dumps(paths))
"""


def _run(seed: int) -> list:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT, str(seed)], capture_output=True, text=True, check=True, cwd=ROOT, env=env
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_ompl_paths_are_reproducible_from_a_fresh_process_with_a_seed() -> None:
    """Same seed, same call sequence, fresh process: identical paths. Within one process calls differ."""
    first, second = _run(7), _run(7)
    assert first == second
    assert len(first[0]) >= 3
