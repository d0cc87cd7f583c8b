"""solve_ik: reachable targets, limits, unreachable targets, success rate with restarts, determinism."""

from __future__ import annotations

import numpy as np
import pytest

from alica.skills.manipulation import Box, solve_ik, top_down_quat
from alica.skills.manipulation.geometry import quat_angle
from alica.worldsim.arm_scene import ArmScene


@pytest.mark.parametrize(
    "target",
    [(0.5, 0.0, 0.2), (0.4, 0.25, 0.1), (0.45, -0.3, 0.3), (0.6, 0.1, 0.05), (0.3, 0.0, 0.5)],
)
def test_reaches_targets_in_front_within_limits(scene: ArmScene, target: tuple[float, float, float]) -> None:
    quat = top_down_quat(0.3)
    result = solve_ik(scene, target, quat, rng=np.random.default_rng(0))
    assert result.ok, result.reason
    assert result.reason == "ok" and 1 <= result.attempts <= 11
    assert result.q is not None and scene.within_limits(result.q)
    pos, got = scene.fk(result.q)
    assert np.linalg.norm(np.array(pos) - np.array(target)) <= 0.005
    assert result.error == pytest.approx(float(np.linalg.norm(np.array(pos) - np.array(target))), abs=1e-9)
    assert quat_angle(got, quat) <= 0.02
    assert not scene.in_collision(result.q)


def test_rejects_a_far_target_with_a_clear_reason(scene: ArmScene) -> None:
    result = solve_ik(scene, (2.5, 0.0, 0.3), top_down_quat(0.0), rng=np.random.default_rng(0))
    assert not result.ok and result.q is None
    assert result.attempts == 0
    assert "unreachable" in result.reason and "reach" in result.reason


def test_rejects_a_target_inside_an_obstacle(scene: ArmScene) -> None:
    target = (0.5, 0.0, 0.2)
    scene.set_obstacles([Box("block", target, (0.1, 0.1, 0.1))])
    result = solve_ik(scene, target, top_down_quat(0.0), rng=np.random.default_rng(0), restarts=3)
    assert not result.ok and result.attempts == 4
    assert "in collision" in result.reason
    # Without the collision check the pose itself is reachable.
    free = solve_ik(scene, target, top_down_quat(0.0), rng=np.random.default_rng(0), check_collision=False)
    assert free.ok


def test_success_rate_with_restarts_on_random_reachable_targets(mobile_scene: ArmScene) -> None:
    """>= 95 % of poses reached by random collision-free configurations are solved (fixed seed)."""
    rng = np.random.default_rng(2024)
    targets = []
    while len(targets) < 200:
        q = mobile_scene.random_configuration(rng)
        if not mobile_scene.in_collision(q):
            targets.append(mobile_scene.fk(q))
    lower, upper = mobile_scene.joint_limits
    solved = 0
    for pos, quat in targets:
        result = solve_ik(mobile_scene, pos, quat, rng=rng)
        if result.ok:
            assert result.q is not None
            assert np.all(result.q >= lower) and np.all(result.q <= upper)
            reached, got = mobile_scene.fk(result.q)
            assert np.linalg.norm(np.array(reached) - np.array(pos)) <= 0.005
            assert quat_angle(got, quat) <= 0.02
            solved += 1
        else:
            assert result.reason.startswith("no IK solution in 11 attempts")
    assert solved / len(targets) >= 0.95, f"only {solved} of {len(targets)} targets solved"


def test_restarts_help_and_results_are_deterministic(mobile_scene: ArmScene) -> None:
    rng = np.random.default_rng(5)
    targets = []
    while len(targets) < 40:
        q = mobile_scene.random_configuration(rng)
        if not mobile_scene.in_collision(q):
            targets.append(mobile_scene.fk(q))
    once = sum(solve_ik(mobile_scene, p, o, rng=np.random.default_rng(1), restarts=0).ok for p, o in targets)
    again = sum(solve_ik(mobile_scene, p, o, rng=np.random.default_rng(1)).ok for p, o in targets)
    assert again > once
    for pos, quat in targets[:10]:
        a = solve_ik(mobile_scene, pos, quat, rng=np.random.default_rng(9))
        b = solve_ik(mobile_scene, pos, quat, rng=np.random.default_rng(9))
        assert a.ok == b.ok and a.attempts == b.attempts and a.reason == b.reason
        if a.ok:
            assert np.array_equal(a.q, b.q)


def test_seed_configuration_is_used(scene: ArmScene) -> None:
    q = scene.rest_q + 0.1
    pos, quat = scene.fk(q)
    result = solve_ik(scene, pos, quat, rng=np.random.default_rng(0), q_seed=q, restarts=0)
    assert result.ok and np.max(np.abs(result.q - q)) < 1e-3


def test_bad_arguments_raise_value_errors(scene: ArmScene) -> None:
    rng = np.random.default_rng(0)
    quat = top_down_quat(0.0)
    with pytest.raises(ValueError, match="tolerance"):
        solve_ik(scene, (0.5, 0, 0.2), quat, rng=rng, tolerance=0.0)
    with pytest.raises(ValueError, match="tolerance"):
        solve_ik(scene, (0.5, 0, 0.2), quat, rng=rng, tolerance=-1.0)
    with pytest.raises(ValueError, match="target_pos"):
        solve_ik(scene, (0.5, float("nan"), 0.2), quat, rng=rng)
    with pytest.raises(ValueError, match="target_quat"):
        solve_ik(scene, (0.5, 0, 0.2), (0, 0, 0), rng=rng)
    with pytest.raises(ValueError, match="restarts"):
        solve_ik(scene, (0.5, 0, 0.2), quat, rng=rng, restarts=-1)
    with pytest.raises(ValueError, match="q_seed"):
        solve_ik(scene, (0.5, 0, 0.2), quat, rng=rng, q_seed=[0.0] * 5)
    with pytest.raises(TypeError, match="Generator"):
        solve_ik(scene, (0.5, 0, 0.2), quat, rng=0)  # type: ignore[arg-type]
