"""What the planners need to know about a loaded arm: joints, limits, tool link, collision pairs, reach.

Read once from the pybullet body (:func:`read_arm_model`), at the body's
initial (all-zero) joint values.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from pybullet_utils.bullet_client import BulletClient

from alica.worldsim.geometry import Pose, Vec3, pose_inverse, pose_multiply

#: Panda "ready" pose: the IK seed and rest configuration.
PANDA_REST_Q = (0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785)
#: Panda transport pose: upper arm tilted back, forearm folded over the base, tool down.
PANDA_HOME_Q = (0.0, -1.2, 0.0, -2.85, 0.0, 1.65, 0.785)

_JOINT_FIXED = 4  # pybullet.JOINT_FIXED
_ARM_DOF = 7


@dataclass(frozen=True, slots=True, eq=False)
class ArmModel:
    """Joint and link facts of one arm body (indices are pybullet's)."""

    arm_joints: tuple[int, ...]
    movable_joints: tuple[int, ...]
    gripper_joints: tuple[int, ...]
    gripper_links: tuple[int, ...]
    lower: np.ndarray
    upper: np.ndarray
    ee_link: int
    base_links: tuple[int, ...]
    allowed_self_pairs: tuple[tuple[int, int], ...]
    gripper_open: float
    gripper_closed: float
    max_opening: float
    reach: float
    shoulder_offset: Vec3
    base_inertial: Pose
    rest_q: np.ndarray
    home_q: np.ndarray


def _find(parent: list[int], i: int) -> int:
    while parent[i + 1] != i:
        parent[i + 1] = parent[parent[i + 1] + 1]
        i = parent[i + 1]
    return i


def read_arm_model(c: BulletClient, body: int) -> ArmModel:
    """Inspect ``body`` (joint values must still be the URDF's zeros).

    Raises:
        ValueError: the body has fewer than 7 movable joints.
    """
    n = c.getNumJoints(body)
    infos = [c.getJointInfo(body, j) for j in range(n)]
    names = {info[12].decode(): j for j, info in enumerate(infos)}
    parent_of = [info[16] for info in infos]
    movable = tuple(j for j, info in enumerate(infos) if info[2] != _JOINT_FIXED)
    if len(movable) < _ARM_DOF:
        raise ValueError(f"the arm needs {_ARM_DOF} movable joints, the URDF has {len(movable)}")
    arm = movable[:_ARM_DOF]
    gripper = movable[_ARM_DOF:]
    lower = np.array([infos[j][8] for j in arm], dtype=float)
    upper = np.array([infos[j][9] for j in arm], dtype=float)
    free = lower >= upper  # continuous joints report lower > upper
    lower[free], upper[free] = -math.pi, math.pi

    # Rigid groups: links joined by fixed joints move together (index -1 is the base).
    group = list(range(-1, n))  # group[i + 1] is the representative of link i
    for j in range(n):
        if infos[j][2] == _JOINT_FIXED:
            a, b = _find(group, j), _find(group, parent_of[j])
            group[max(a, b) + 1] = min(a, b)
    rep = {link: _find(group, link) for link in range(-1, n)}
    adjacent = {frozenset((rep[j], rep[parent_of[j]])) for j in movable}
    gripper_groups = {rep[j] for j in gripper}
    gripper_links = tuple(link for link in range(n) if rep[link] in gripper_groups)
    pairs = []
    for a in range(-1, n):
        for b in range(a + 1, n):
            same = rep[a] == rep[b]
            near = frozenset((rep[a], rep[b])) in adjacent
            fingers = rep[a] in gripper_groups and rep[b] in gripper_groups
            if same or near or fingers:
                pairs.append((a, b))
    base_links = tuple(link for link in range(-1, n) if rep[link] == rep[-1])

    if "panda_grasptarget" in names:
        ee = names["panda_grasptarget"]
    elif "panda_hand" in names:
        ee = names["panda_hand"]
    else:
        ee = n - 1

    # Reach: sum of the link-frame distances from the shoulder (second arm joint) to the tool.
    frames = {link: np.array(c.getLinkState(body, link, computeForwardKinematics=True)[4]) for link in range(n)}
    chain = [ee]
    while chain[-1] != arm[1] and parent_of[chain[-1]] >= 0:
        chain.append(parent_of[chain[-1]])
    reach = float(sum(np.linalg.norm(frames[a] - frames[b]) for a, b in itertools.pairwise(chain)))

    com_pos, com_quat = c.getBasePositionAndOrientation(body)
    dyn = c.getDynamicsInfo(body, -1)
    inertial: Pose = (tuple(dyn[3]), tuple(dyn[4]))
    base_frame = pose_multiply(tuple(com_pos), tuple(com_quat), *pose_inverse(*inertial))
    shoulder = pose_multiply(*pose_inverse(*base_frame), tuple(frames[arm[1]]), (0.0, 0.0, 0.0, 1.0))[0]

    g_lo = [infos[j][8] for j in gripper]
    g_hi = [infos[j][9] for j in gripper]
    gripper_open = float(min(g_hi)) if gripper else 0.0
    gripper_closed = float(max(g_lo)) if gripper else 0.0

    panda = all(infos[j][1].decode().startswith("panda_joint") for j in arm)
    mid = (lower + upper) / 2.0
    rest = np.array(PANDA_REST_Q) if panda else mid
    home = np.array(PANDA_HOME_Q) if panda else mid
    return ArmModel(
        arm_joints=arm,
        movable_joints=movable,
        gripper_joints=gripper,
        gripper_links=gripper_links,
        lower=lower,
        upper=upper,
        ee_link=ee,
        base_links=base_links,
        allowed_self_pairs=tuple(pairs),
        gripper_open=gripper_open,
        gripper_closed=gripper_closed,
        max_opening=2.0 * gripper_open if len(gripper) == 2 else 0.0,
        reach=reach,
        shoulder_offset=shoulder,
        base_inertial=inertial,
        rest_q=rest,
        home_q=home,
    )
