"""plan_pickup and plan_place: a 5 cm block on the ground, out of reach, stacked on another block."""

from __future__ import annotations

import numpy as np
import pytest

from alica.skills.manipulation import Box, PickupPlan, plan_pickup, plan_place
from alica.skills.manipulation.geometry import quat_angle
from alica.skills.manipulation.pickup import LIFT_CLEARANCE
from alica.worldsim.arm_scene import ArmScene
from tests.manipulation.helpers import PLATFORM, assert_path_free, dense_states

BLOCK = Box("block", (0.5, 0.0, 0.025), (0.025, 0.025, 0.025))


def _pick(scene: ArmScene, block: Box = BLOCK, seed: int = 0) -> PickupPlan:
    plan = plan_pickup(scene, block, scene.home_q, rng=np.random.default_rng(seed))
    assert plan.ok, plan.reason
    return plan


def test_pickup_of_a_block_half_a_metre_in_front(mobile_scene: ArmScene) -> None:
    mobile_scene.set_obstacles([PLATFORM, BLOCK])
    plan = _pick(mobile_scene)
    assert plan.reason == "ok" and plan.grasp is not None and plan.held is not None
    assert plan.plan_time_s > 0.0
    assert mobile_scene.obstacles == (PLATFORM, BLOCK)  # restored
    approach, descent, carry = plan.paths
    assert np.allclose(approach[0], mobile_scene.home_q) and np.allclose(approach[-1], plan.q_pregrasp)
    assert np.allclose(descent[0], plan.q_pregrasp) and np.allclose(descent[-1], plan.q_grasp)
    assert np.allclose(carry[0], plan.q_grasp) and np.allclose(carry[-1], mobile_scene.home_q)
    # The grasp: tool at the block's centre, pointing down; approach 10 cm above.
    pos, quat = mobile_scene.fk(plan.q_grasp)
    assert pos == pytest.approx(BLOCK.center, abs=0.005)
    assert quat_angle(quat, plan.grasp.pose[1]) < 0.02
    assert mobile_scene.fk(plan.q_pregrasp)[0] == pytest.approx((0.5, 0.0, 0.125), abs=0.005)
    # Straight down: the tool stays on the vertical line through the block.
    for q in dense_states(descent):
        x, y, _ = mobile_scene.fk(q)[0]
        assert abs(x - 0.5) < 0.01 and abs(y) < 0.01
    # Approach and descent avoid the block (an obstacle); the carry path is free holding it.
    assert_path_free(mobile_scene, approach)
    assert_path_free(mobile_scene, descent)
    mobile_scene.set_obstacles([PLATFORM])
    lifted = [q for q in dense_states(carry) if mobile_scene.fk(q)[0][2] - pos[2] >= LIFT_CLEARANCE]
    assert len(lifted) > 0.8 * len(dense_states(carry))
    for q in lifted:
        assert not mobile_scene.in_collision(q, plan.held)
    assert plan.held.center == pytest.approx((0.0, 0.0, 0.0), abs=0.005)


def test_pickup_when_the_block_is_not_yet_an_obstacle(mobile_scene: ArmScene) -> None:
    block = Box("b2", (0.45, -0.2, 0.025), (0.025, 0.025, 0.025), 0.6)
    plan = _pick(mobile_scene, block)
    assert mobile_scene.obstacles == (PLATFORM,)
    mobile_scene.set_obstacles([PLATFORM, block])
    assert_path_free(mobile_scene, plan.paths[0])
    assert_path_free(mobile_scene, plan.paths[1])


def test_a_block_out_of_reach_fails_with_a_reason(mobile_scene: ArmScene) -> None:
    far = Box("far", (1.6, 0.0, 0.025), (0.025, 0.025, 0.025))
    plan = plan_pickup(mobile_scene, far, mobile_scene.home_q, rng=np.random.default_rng(0))
    assert not plan.ok and plan.paths == [] and plan.q_grasp is None
    assert "far" in plan.reason and "unreachable" in plan.reason
    too_wide = Box("wide", (0.5, 0.0, 0.05), (0.1, 0.1, 0.05))
    wide = plan_pickup(mobile_scene, too_wide, mobile_scene.home_q, rng=np.random.default_rng(0))
    assert not wide.ok and "wider than the gripper" in wide.reason
    assert mobile_scene.obstacles == (PLATFORM,)


def test_place_on_top_of_another_block(mobile_scene: ArmScene) -> None:
    support = Box("support", (0.45, 0.2, 0.025), (0.025, 0.025, 0.025))
    mobile_scene.set_obstacles([PLATFORM, support, BLOCK])
    picked = _pick(mobile_scene)
    assert picked.held is not None
    # After the pick-up the block travels with the arm: it is no obstacle any more.
    mobile_scene.set_obstacles([PLATFORM, support])
    q_start = picked.paths[-1][-1]
    place = plan_place(mobile_scene, picked.held, (0.45, 0.2, support.top), q_start, rng=np.random.default_rng(1))
    assert place.ok, place.reason
    assert mobile_scene.obstacles == (PLATFORM, support)
    assert place.placed is not None
    assert place.placed.center == pytest.approx((0.45, 0.2, 0.075), abs=0.005)
    to_above, down, retreat = place.paths
    assert np.allclose(to_above[0], q_start) and np.allclose(to_above[-1], place.q_above)
    assert np.allclose(down[-1], place.q_place) and np.allclose(retreat[-1], mobile_scene.home_q)
    assert_path_free(mobile_scene, to_above, held=picked.held)
    assert_path_free(mobile_scene, down, held=picked.held)
    # Released: the placed block is an obstacle for the retreat, the gripper is open.
    mobile_scene.set_obstacles([PLATFORM, support, place.placed])
    assert_path_free(mobile_scene, retreat)
    # The block's bottom is just above the support when it is let go.
    bottom = mobile_scene.fk(place.q_place)[0][2] - picked.held.center[2] - 0.025  # tool z points down
    assert support.top < bottom < support.top + 0.015


def test_place_with_a_requested_yaw(mobile_scene: ArmScene) -> None:
    picked = _pick(mobile_scene)
    q_start = picked.paths[-1][-1]
    place = plan_place(
        mobile_scene, picked.held, (0.5, -0.15, 0.0), q_start, rng=np.random.default_rng(0), object_yaw=0.5
    )
    assert place.ok, place.reason
    assert np.cos(4 * (place.placed.yaw - 0.5)) == pytest.approx(1.0, abs=1e-3)  # a cube: quarter turns alike


def test_pickup_is_deterministic_for_a_fixed_seed(mobile_scene: ArmScene) -> None:
    """Equal generators give equal plans when every free motion is a direct segment (as here)."""
    a, b = _pick(mobile_scene, seed=3), _pick(mobile_scene, seed=3)
    assert a.grasp == b.grasp
    assert np.array_equal(a.q_grasp, b.q_grasp) and np.array_equal(a.q_pregrasp, b.q_pregrasp)
    assert all(np.array_equal(p, q) for p, q in zip(a.paths, b.paths))


def test_bad_arguments_raise_value_errors(mobile_scene: ArmScene) -> None:
    rng = np.random.default_rng(0)
    with pytest.raises(TypeError, match="Box"):
        plan_pickup(mobile_scene, "block", mobile_scene.home_q, rng=rng)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="7 joint values"):
        plan_pickup(mobile_scene, BLOCK, [0.0] * 3, rng=rng)
    with pytest.raises(ValueError, match="retries"):
        plan_pickup(mobile_scene, BLOCK, mobile_scene.home_q, rng=rng, retries=-1)
    with pytest.raises(ValueError, match="target_top_center"):
        plan_place(mobile_scene, BLOCK, (0.5, 0.0), mobile_scene.home_q, rng=rng)
