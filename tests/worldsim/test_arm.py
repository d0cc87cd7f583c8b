"""The Panda arm on a base: reach (IK), path following, attach/detach, gripper, grasp slip."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.worldsim.arm import Arm
from alica.worldsim.errors import WorldError
from alica.worldsim.faults import set_grasp_slip
from alica.worldsim.robots import Robot
from alica.worldsim.scenarios import blocks_facts
from alica.worldsim.world import World

DOWN = (1.0, 0.0, 0.0, 0.0)  # gripper pointing at the ground


def ik(arm: Arm, target: tuple[float, float, float], restarts: int = 20) -> np.ndarray | None:
    """IK on the world's own client: limit-checked, with random restarts (as the motion notes advise)."""
    c = arm.robot.world.client
    lo, hi = arm.joint_limits
    rng = np.random.default_rng(0)
    saved = arm.q()
    best = None
    for k in range(restarts):
        start = arm.home_q if k == 0 else rng.uniform(lo, hi)
        for j, v in zip(arm.joint_indices, start, strict=True):
            c.resetJointState(arm.body_id, j, float(v))
        sol = c.calculateInverseKinematics(
            arm.body_id, arm.ee_link, target, DOWN, maxNumIterations=200, residualThreshold=1e-5
        )
        q = np.array(sol[:7])
        if np.any(q < lo) or np.any(q > hi):
            continue
        arm.set_q(q)
        if np.linalg.norm(arm.ee_pose()[0] - target) < 5e-3:
            best = q
            break
    arm.set_q(saved)
    return best


def lowest_link_z(arm: Arm) -> float:
    c = arm.robot.world.client
    return min(c.getAABB(arm.body_id, link)[0][2] for link in range(c.getNumJoints(arm.body_id)))


@pytest.fixture
def manipulator(world: World) -> Robot:
    return world.add_robot("manipulator", "r1", (0.0, 0.0, 0.0))


def test_arm_api(manipulator: Robot) -> None:
    arm = manipulator.arm
    assert arm is not None and manipulator.gripper is arm
    assert arm.urdf_path.endswith("franka_panda/panda.urdf")
    assert arm.joint_indices == (0, 1, 2, 3, 4, 5, 6)
    lo, hi = arm.joint_limits
    assert lo.shape == hi.shape == (7,) and (lo < hi).all()
    c = manipulator.world.client
    assert c.getJointInfo(arm.body_id, arm.ee_link)[12] == b"panda_grasptarget"
    assert np.allclose(arm.q(), arm.home_q)
    pos, _quat = arm.base_pose()
    assert pos == pytest.approx((arm.mount_offset[0], 0.0, manipulator.spec.height))
    assert arm.mount_offset[2] == manipulator.spec.height
    assert len(arm.ee_pose()[1]) == 4
    assert arm.held is None and arm.grip_force() == 0.0
    assert World.__name__ and manipulator.world.robots["r1"].arm is arm


def test_robots_without_an_arm(world: World) -> None:
    assert world.add_robot("scout", "s", (0.0, 0.0, 0.0)).arm is None


@pytest.mark.parametrize(
    ("kind", "reach"),
    [("manipulator", 0.35), ("manipulator", 0.55), ("manipulator", 0.65), ("stummel", 0.55), ("amparo", 0.55)],
)
def test_ik_reaches_a_block_on_the_ground_in_front(world: World, kind: str, reach: float) -> None:
    robot = world.add_robot(kind, "r", (0.0, 0.0, 0.0))
    arm = robot.arm
    x = arm.mount_offset[0] + reach
    block = world.add_block("b", (x, 0.0))
    assert x - block.size / 2 > robot.spec.radius  # the block is in front of the base, not under it
    target = tuple(block.position())
    q = ik(arm, target)
    assert q is not None, f"no IK solution to a block {reach} m ahead of the arm base"
    arm.set_q(q)
    assert np.linalg.norm(arm.ee_pose()[0] - target) < 5e-3
    assert lowest_link_z(arm) > 0.0  # the fingertips stay above the ground
    assert world.contacts(robot) <= {"b"}  # the arm touches nothing else
    c = world.client
    moving_links = range(c.getNumJoints(arm.body_id))  # link0 (-1) sits on the base by design
    assert not any(c.getClosestPoints(arm.body_id, robot.body_id, 0.0, linkIndexA=k) for k in moving_links)


def test_follow_moves_along_the_path_in_simulated_time(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    goal = arm.home_q + np.array([0.5, 0.2, 0.0, 0.3, 0.0, -0.2, 0.0])
    path = np.linspace(arm.home_q, goal, 5)
    used = arm.follow(path, 2.0)
    assert used == 2.0 and arm.busy
    world.step(1.0)
    assert arm.busy
    assert np.allclose(arm.q(), 0.5 * (arm.home_q + goal), atol=1e-9)
    world.step(1.1)
    assert not arm.busy
    assert np.allclose(arm.q(), goal)
    c = world.client
    assert [c.getJointState(arm.body_id, j)[0] for j in arm.joint_indices] == pytest.approx(goal.tolist())


def test_follow_stretches_a_too_fast_duration_and_checks_limits(manipulator: Robot) -> None:
    arm = manipulator.arm
    goal = arm.home_q + np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert arm.follow(goal[None, :], 0.01) == pytest.approx(1.0 / arm.max_velocity[0])
    assert arm.min_duration(goal[None, :]) == pytest.approx(1.0 / arm.max_velocity[0])
    bad = arm.home_q.copy()
    bad[3] = 1.0  # joint 4 must be <= 0
    with pytest.raises(WorldError, match="joint 4 = 1.0000 at row 0 is outside its limits"):
        arm.follow(bad[None, :], 1.0)
    with pytest.raises(WorldError, match=r"\(N x 7\)"):
        arm.follow(np.zeros((3, 6)), 1.0)
    with pytest.raises(WorldError, match="outside its limits"):
        arm.set_q(bad)


def _grasp(world: World, robot: Robot, block_name: str) -> np.ndarray:
    arm = robot.arm
    q = ik(arm, tuple(world.objects[block_name].position()))
    assert q is not None
    arm.open()
    arm.set_q(q)
    arm.close()
    assert arm.attach(block_name)
    return q


def test_the_grip_force_is_the_force_the_gripper_closed_with(world: World, manipulator: Robot) -> None:
    from alica.worldsim.arm import GRIP_FORCE

    arm = manipulator.arm
    world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    assert arm.grip_force() == GRIP_FORCE  # the default
    arm.detach()
    arm.close(5.0)
    assert arm.grip_force() == 0.0  # nothing held
    assert arm.attach("b") and arm.grip_force() == 5.0
    with pytest.raises(WorldError, match="needs a finger force > 0 newtons, got -1"):
        arm.close(-1.0)


def test_attach_carries_and_detach_releases(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    block = world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    assert arm.held is block and arm.grip_force() > 0.0
    assert arm.finger_opening() == pytest.approx(block.size)
    offset = block.position() - arm.ee_pose()[0]
    arm.follow(arm.home_q[None, :], 2.0)
    world.step(2.5)
    assert np.allclose(block.position() - arm.ee_pose()[0], offset, atol=1e-6)
    assert block.position()[2] > 0.2  # lifted
    manipulator.drive(0.5, 0.3)
    world.step(2.0)
    assert np.linalg.norm(block.position() - arm.ee_pose()[0]) == pytest.approx(np.linalg.norm(offset), abs=1e-6)
    manipulator.stop()
    released = arm.detach()
    assert released is block and arm.held is None and arm.grip_force() == 0.0
    world.step(2.0)
    _x, _y, z = block.position()
    assert z == pytest.approx(0.025, abs=2e-3)  # fell and rests on the ground
    assert ("ontable", "b") in blocks_facts(world)


def test_a_block_put_on_another_rests_on_it(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    x0 = arm.mount_offset[0] + 0.5
    world.add_block("low", (x0, 0.15))
    top = world.add_block("top", (x0, -0.15))
    _grasp(world, manipulator, "top")
    above = ik(arm, (x0, 0.15, 0.05 + 0.025 + 0.004))  # 4 mm above the lower block
    assert above is not None
    arm.follow(np.vstack([arm.home_q, above]), 3.0)
    world.step(3.5)
    arm.detach()
    arm.open()
    arm.follow(arm.home_q[None, :], 2.0)
    world.step(2.5)
    assert top.position() == pytest.approx((x0, 0.15, 0.075), abs=3e-3)
    facts = blocks_facts(world)
    assert {("on", "top", "low"), ("ontable", "low"), ("clear", "top"), ("handempty", "r1")} <= facts
    assert ("clear", "low") not in facts


def test_a_block_lifted_from_under_another_lets_it_fall(world: World, manipulator: Robot) -> None:
    # the upper block has rested long enough to sleep in pybullet; lifting the lower one away must wake it
    arm = manipulator.arm
    x0 = arm.mount_offset[0] + 0.5
    world.add_block("low", (x0, 0.0))
    upper = world.add_block("upper", (x0, 0.0, 0.075))
    world.step(5.0)
    assert ("on", "upper", "low") in blocks_facts(world)
    _grasp(world, manipulator, "low")
    arm.follow(arm.home_q[None, :], 2.0)
    world.step(3.0)
    assert upper.position()[2] == pytest.approx(0.025, abs=3e-3)  # it fell to the ground, not floating where it was
    assert ("ontable", "upper") in blocks_facts(world)


def test_attach_needs_the_object_between_the_fingers(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    assert arm.attach("b") is False  # the gripper is up in the home pose
    assert arm.held is None and arm.grip_force() == 0.0
    world.add_rock("rock", (3.0, 3.0), 0.4)
    with pytest.raises(WorldError, match="rock 'rock' is not graspable"):
        arm.attach("rock")
    with pytest.raises(WorldError, match="no object 'nothing'"):
        arm.attach("nothing")
    assert arm.detach() is None


def test_grasp_slip_with_probability_one_drops_the_object(world: World, manipulator: Robot) -> None:
    set_grasp_slip(world, 1.0)
    arm = manipulator.arm
    block = world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    assert arm.held is block  # the grasp looks fine at first
    arm.follow(arm.home_q[None, :], 2.0)
    world.step(1.0)  # slips within 0.6 s
    assert arm.held is None and arm.grip_force() == 0.0
    world.step(2.0)
    assert block.position()[2] == pytest.approx(0.025, abs=2e-3)


def test_grasp_slip_zero_keeps_the_object(world: World, manipulator: Robot) -> None:
    set_grasp_slip(world, 0.0)
    arm = manipulator.arm
    world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    world.step(3.0)
    assert arm.held is not None


def test_opening_the_gripper_releases(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    arm.open()
    assert arm.held is None and arm.finger_opening() == pytest.approx(0.08)
    arm.close()
    assert arm.finger_opening() == pytest.approx(0.05)  # closes on the block still between the fingers


def _in_hand(arm: Arm, obj_name: str) -> tuple[float, float, float]:
    """Where object ``obj_name`` is in the end-effector's frame."""
    from alica.worldsim.geometry import pose_inverse, pose_multiply

    ee_pos, ee_quat = arm.ee_pose()
    inv = pose_inverse(tuple(ee_pos), ee_quat)
    pos, _ = pose_multiply(inv[0], inv[1], *arm.robot.world.objects[obj_name].pose())
    return pos


@pytest.mark.parametrize(("off_x", "off_y"), [(0.0, 0.012), (0.006, -0.015), (0.004, 0.0005)])
def test_closing_fingers_centre_the_object_between_them(
    world: World, manipulator: Robot, off_x: float, off_y: float
) -> None:
    # the hand comes down off the block's centre; the fingers close along the tool's y axis (the world's -y here)
    from alica.worldsim.gripper import GRIP_SLACK

    arm = manipulator.arm
    block = world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    x, y, z = block.position()
    q = ik(arm, (x - off_x, y + off_y, z))
    assert q is not None
    arm.open()
    arm.set_q(q)
    arm.close()
    before = _in_hand(arm, "b")
    assert arm.attach("b")
    world.step(0.1)
    held = _in_hand(arm, "b")
    # pushed to the middle along the fingers (an offset within the pads' give stays), not moved along the others
    assert held[1] == pytest.approx(max(-GRIP_SLACK, min(GRIP_SLACK, before[1])), abs=1e-6)
    assert (held[0], held[2]) == pytest.approx((before[0], before[2]), abs=1e-6)
    assert abs(before[1]) <= GRIP_SLACK or abs(held[1]) < abs(before[1])


def test_samples_are_graspable(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    sample = world.add_sample("a", "red-white-red", (arm.mount_offset[0] + 0.5, 0.0))
    q = ik(arm, tuple(sample.position()))
    assert q is not None
    arm.set_q(q)
    assert arm.attach(sample)
    assert arm.finger_opening() == pytest.approx(2 * sample.radius)
    arm.set_q(arm.home_q)
    assert sample.position()[2] > 0.3
    assert math.isfinite(sample.yaw())


def test_a_crash_opens_the_gripper_and_the_held_block_falls(world: World, manipulator: Robot) -> None:
    arm = manipulator.arm
    block = world.add_block("b", (arm.mount_offset[0] + 0.5, 0.0))
    _grasp(world, manipulator, "b")
    arm.follow(arm.home_q[None, :], 2.0)
    world.step(2.5)
    assert block.position()[2] > 0.2  # lifted
    version = world._version
    world.faults.crash(manipulator.name)  # power loss
    assert manipulator.crashed and arm.held is None and arm.grip_force() == 0.0
    assert world._version > version  # the perception sees the world changed
    world.step(2.0)
    assert block.position()[2] == pytest.approx(0.025, abs=2e-3)  # fell where it was and rests on the ground
    assert arm.attach("b") is False  # a crashed robot does not grasp


def test_a_recovered_robot_takes_commands_again(world: World, manipulator: Robot) -> None:
    world.faults.crash(manipulator.name)
    manipulator.drive(0.5, 0.0)
    world.step(1.0)
    assert manipulator.velocity == (0.0, 0.0)
    world.faults.recover(manipulator.name)
    assert not manipulator.crashed
    here = manipulator.pose
    manipulator.drive(0.5, 0.0)
    world.step(1.0)
    assert manipulator.pose != here
