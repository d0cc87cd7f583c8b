"""The world's arm planning scene (alica.worldsim.arm_scene.ArmScene): the Panda's joints, limits and FK; collision checks.

Also: an arm gives its scene (Arm.planning_scene), the arms of a world share one planning model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.skills.manipulation.geometry import quat_angle
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.arm_scene import ArmScene, default_urdf
from alica.worldsim.geometry import Box
from alica.worldsim.world import World


def test_panda_joints_limits_and_tool_link(scene: ArmScene) -> None:
    assert len(scene.arm_model.arm_joints) == 7
    lower, upper = scene.joint_limits
    assert lower.shape == upper.shape == (7,)
    assert np.all(lower < upper)
    # Values of the pybullet_data Panda URDF.
    assert lower[0] == pytest.approx(-2.9671) and upper[0] == pytest.approx(2.9671)
    assert lower[3] == pytest.approx(-3.1416) and upper[3] == pytest.approx(0.0)
    assert lower[5] == pytest.approx(-0.0873) and upper[5] == pytest.approx(3.8223)
    name = scene.client.getJointInfo(scene.robot_id, scene.arm_model.ee_link)[12].decode()
    assert name == "panda_grasptarget"
    assert scene.within_limits(scene.rest_q) and scene.within_limits(scene.home_q)
    # joint_limits hands out copies
    lower[0] = 99.0
    assert scene.joint_limits[0][0] != 99.0


def test_fk_of_the_ready_pose_and_of_a_moved_base(scene: ArmScene) -> None:
    pos, quat = scene.fk(scene.rest_q)
    assert pos == pytest.approx((0.307, 0.0, 0.485), abs=2e-3)
    assert quat_angle(quat, (1.0, 0.0, 0.0, 0.0)) < 1e-2  # tool pointing straight down
    # Zero configuration: the arm stands upright; the tool is 0.088 m in front of the axis.
    up, _ = scene.fk(np.zeros(7))
    assert up[0] == pytest.approx(0.088, abs=1e-3) and up[1] == pytest.approx(0.0, abs=1e-6)
    quarter = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    scene.set_base_pose(((1.0, 2.0, 0.3), quarter))
    assert scene.base_pose()[0] == pytest.approx((1.0, 2.0, 0.3), abs=1e-6)
    moved, _ = scene.fk(scene.rest_q)
    assert moved == pytest.approx((1.0, 2.307, 0.785), abs=2e-3)
    assert scene.shoulder_position() == pytest.approx((1.0, 2.0, 0.633), abs=1e-3)


def test_transport_and_rest_poses_are_free_even_holding_a_block(mobile_scene: ArmScene) -> None:
    cube = Box("cube", (0.0, 0.0, 0.0), (0.025, 0.025, 0.025))
    for q in (mobile_scene.rest_q, mobile_scene.home_q):
        assert not mobile_scene.in_collision(q)
        assert not mobile_scene.in_collision(q, cube)


def test_a_box_through_the_arm_collides_and_a_far_box_does_not(scene: ArmScene) -> None:
    tool, _ = scene.fk(scene.rest_q)
    scene.set_obstacles([Box("far", (3.0, 3.0, 0.5), (0.1, 0.1, 0.5))])
    assert not scene.in_collision(scene.rest_q)
    scene.set_obstacles([Box("far", (3.0, 3.0, 0.5), (0.1, 0.1, 0.5)), Box("hit", tool, (0.05, 0.05, 0.05))])
    assert scene.in_collision(scene.rest_q)
    scene.set_obstacles([])
    assert not scene.in_collision(scene.rest_q)
    assert scene.obstacles == ()


def test_margin_inflates_obstacles(scene: ArmScene) -> None:
    # A slab under the fingertips of the ready pose, 1 mm below them: inside the 3 mm margin.
    c = scene.client
    scene.set_joints(scene.rest_q)
    probe = c.createMultiBody(
        0.0, c.createCollisionShape(c.GEOM_BOX, halfExtents=(1, 1, 0.01)), basePosition=(0, 0, -1)
    )
    lowest = min(
        c.getClosestPoints(scene.robot_id, probe, 5.0, link)[0][5][2] for link in scene.arm_model.gripper_links
    )
    c.removeBody(probe)
    assert scene.margin == pytest.approx(0.003)

    def slab(gap: float) -> Box:
        return Box("slab", (0.3, 0.0, lowest - gap - 0.01), (0.2, 0.2, 0.01))

    scene.set_obstacles([slab(0.001)])
    assert scene.in_collision(scene.rest_q)
    scene.set_obstacles([slab(0.01)])
    assert not scene.in_collision(scene.rest_q)


def test_ground_and_self_collisions(scene: ArmScene) -> None:
    reaching_down = np.array([0.0, 1.7, 0.0, -0.3, 0.0, 2.5, 0.785])  # tool below z = 0
    assert scene.fk(reaching_down)[0][2] < 0.0
    assert scene.in_collision(reaching_down)
    folded = np.array([0.0, 0.0, 0.0, -2.5, 0.0, -0.08, 0.0])  # hand folded onto the forearm
    assert scene.in_collision(folded)
    high = ArmScene(base_pose=((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0)))
    try:
        assert high.in_collision(folded)  # not the ground: the arm itself
    finally:
        high.close()


def test_held_object_is_checked_and_fingers_may_touch_it(scene: ArmScene) -> None:
    q = scene.rest_q
    tool, _ = scene.fk(q)
    # Wider than the open fingers' gap would be: the fingers close on it, no collision.
    cube = Box("cube", (0.0, 0.0, 0.0), (0.025, 0.025, 0.025))
    assert not scene.in_collision(q, cube)
    # A held 20 cm tall box hanging below the tool hits a post the bare arm clears.
    long = Box("long", (0.0, 0.0, 0.1), (0.02, 0.02, 0.1))
    post_top = tool[2] - 0.05
    scene.set_obstacles([Box("post", (tool[0], tool[1], post_top / 2), (0.03, 0.03, post_top / 2))])
    assert not scene.in_collision(q)
    assert scene.in_collision(q, long)
    assert not scene.in_collision(q)  # the held body is parked again


def test_bad_arguments_raise_value_errors(scene: ArmScene) -> None:
    with pytest.raises(ValueError, match="7 joint values"):
        scene.in_collision([0.0] * 6)
    with pytest.raises(ValueError, match="NaN"):
        scene.fk([0.0, 0.0, float("nan"), 0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="duplicate"):
        scene.set_obstacles([Box("a", (1, 1, 1), (0.1, 0.1, 0.1)), Box("a", (2, 2, 2), (0.1, 0.1, 0.1))])
    with pytest.raises(ValueError, match="> 0"):
        Box("flat", (0, 0, 0), (0.1, 0.0, 0.1))
    with pytest.raises(ValueError, match="three"):
        Box("bad", (0, 0), (0.1, 0.1, 0.1))
    with pytest.raises(TypeError, match="held"):
        scene.in_collision(scene.rest_q, held="cube")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="URDF"):
        ArmScene(urdf_path="no/such/arm.urdf")


def test_scenes_are_independent_and_close_is_idempotent() -> None:
    a, b = ArmScene(), ArmScene(obstacles=[Box("hit", (0.3, 0.0, 0.5), (0.1, 0.1, 0.1))])
    try:
        assert a.client is not b.client
        assert not a.in_collision(a.rest_q) and b.in_collision(b.rest_q)
    finally:
        a.close()
        b.close()
        b.close()
    assert default_urdf().endswith("panda.urdf")


def test_scenes_sharing_a_model_answer_as_scenes_of_their_own() -> None:
    from alica.skills.manipulation import solve_ik
    from alica.worldsim.arm_scene import ArmPlanningModel

    poses = [((0.0, 0.0, 0.3), (0.0, 0.0, 0.0, 1.0)), ((2.0, 1.0, 0.3), (0.0, 0.0, 0.7071068, 0.7071068))]
    walls = [
        [Box("wall", (0.45, 0.0, 0.4), (0.02, 0.3, 0.4)), Box("a", (0.5, 0.2, 0.025), (0.025, 0.025, 0.025))],
        [Box("a", (2.0, 1.5, 0.025), (0.025, 0.025, 0.025))],
    ]
    held = Box("h", (0.0, 0.0, 0.03), (0.025, 0.025, 0.025))
    model = ArmPlanningModel()
    shared = [ArmScene(base_pose=p, obstacles=w, model=model) for p, w in zip(poses, walls, strict=True)]
    alone = [ArmScene(base_pose=p, obstacles=w) for p, w in zip(poses, walls, strict=True)]
    try:
        rng = np.random.default_rng(3)
        qs = [shared[0].random_configuration(rng) for _ in range(40)]
        for k, q in enumerate(qs):  # the two shared scenes take turns, query by query
            i = k % 2
            h = held if k % 3 == 0 else None
            assert shared[i].collides(q, h) == alone[i].collides(q, h)
            assert shared[i].fk(q) == alone[i].fk(q)
            assert shared[i].base_pose() == alone[i].base_pose()
        shared[0].set_joints(qs[0])
        shared[1].set_joints(qs[1])
        assert shared[0].current_tool_pose() == alone[0].fk(qs[0])  # its joints were kept for it
        for i in (0, 1):
            target = alone[i].fk(alone[i].rest_q)
            a = solve_ik(shared[i], target[0], target[1], rng=np.random.default_rng(1))
            b = solve_ik(alone[i], target[0], target[1], rng=np.random.default_rng(1))
            assert a.ok == b.ok and (a.q is None or np.array_equal(a.q, b.q))
        assert shared[0].obstacles == tuple(walls[0]) and shared[1].obstacles == tuple(walls[1])
        with pytest.raises(ValueError, match="margin"):
            ArmScene(model=model, margin=0.01)
        shared[0].close()
        with pytest.raises(ValueError, match="closed"):
            shared[0].collides(qs[0])
        assert not shared[1].collides(shared[1].home_q)  # the model lives on for the other scene
    finally:
        for s in shared + alone:
            s.close()
        model.close()


def test_an_arm_gives_its_planning_scene_and_the_arms_of_a_world_share_one_model(world: World) -> None:
    one = world.add_robot("manipulator", "r1", (0.0, 0.0, 0.0))
    two = world.add_robot("manipulator", "r2", (2.0, 0.0, 1.0))
    assert one.arm is not None and two.arm is not None
    scene_one, scene_two = one.arm.planning_scene(), two.arm.planning_scene()
    assert isinstance(scene_one, ArmScene) and scene_one is one.arm.planning_scene()  # made once
    assert scene_one is not scene_two and scene_one.model is scene_two.model
    plain: ArmPlanningScene = scene_two  # what skills see of it
    position, _ = plain.base_pose()
    assert position == pytest.approx(two.arm.base_pose()[0], abs=1e-9)
    assert scene_one.base_pose()[0] == pytest.approx(one.arm.base_pose()[0], abs=1e-9)
