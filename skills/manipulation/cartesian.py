"""Straight tool motions (approach, descend, lift, retreat) as joint waypoints.

The line is cut into steps of ``step`` metres; each waypoint is an IK solution
seeded with the previous one, so the arm stays on one branch. Collisions are
the caller's business (they depend on what is held and what counts as an
obstacle at that moment).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from alica.skills.manipulation.geometry import Pose, Quat, as_configuration, as_pose, quat_angle
from alica.skills.manipulation.ik import solve_ik
from alica.worldsim.arm_interface import ArmPlanningScene

#: Distance between waypoints along the line, metres.
LINE_STEP = 0.05
#: Largest change of one joint between neighbouring waypoints (a larger one means the IK jumped branch).
MAX_JOINT_JUMP = 0.25


def _nlerp(a: Quat, b: Quat, t: float) -> Quat:
    sign = 1.0 if sum(x * y for x, y in zip(a, b)) >= 0.0 else -1.0
    q = [(1.0 - t) * x + t * sign * y for x, y in zip(a, b)]
    n = math.sqrt(sum(x * x for x in q))
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def straight_line(
    scene: ArmPlanningScene,
    q_from: Sequence[float] | np.ndarray,
    pose_to: Pose,
    *,
    rng: np.random.Generator,
    step: float = LINE_STEP,
    tolerance: float = 0.002,
) -> tuple[np.ndarray | None, str]:
    """Joint waypoints moving the tool on a straight line from its pose at ``q_from`` to ``pose_to``.

    Args:
        scene: the arm scene.
        q_from: start configuration (its tool pose is the line's start).
        pose_to: the line's end pose; the orientation is interpolated (normalised lerp).
        rng: passed to :func:`solve_ik` (no restarts are made, it is not drawn from).
        step: distance between waypoints in metres (> 0).
        tolerance: position tolerance of each waypoint in metres.

    Returns:
        ``(waypoints (N, 7) starting with q_from, "ok")`` or ``(None, reason)``.
    """
    q = as_configuration(q_from, 7, "q_from")
    end_pos, end_quat = as_pose(pose_to, "pose_to")
    if not step > 0:
        raise ValueError(f"step must be > 0, got {step!r}")
    start_pos, start_quat = scene.fk(q)
    delta = np.array(end_pos) - np.array(start_pos)
    length = float(np.linalg.norm(delta))
    n = max(1, math.ceil(length / step - 1e-9), math.ceil(quat_angle(start_quat, end_quat) / 0.05))
    waypoints = [q]
    for i in range(1, n + 1):
        t = i / n
        target = np.array(start_pos) + delta * t
        result = solve_ik(
            scene,
            target,
            _nlerp(start_quat, end_quat, t),
            restarts=0,
            tolerance=tolerance,
            rng=rng,
            q_seed=q,
            check_collision=False,
        )
        if not result.ok or result.q is None:
            return None, f"straight line: no IK at {t:.0%} of {length:.3f} m ({result.reason})"
        jump = float(np.max(np.abs(result.q - q)))
        if jump > MAX_JOINT_JUMP:
            return None, f"straight line: the arm would swing {jump:.2f} rad between waypoints at {t:.0%}"
        q = result.q
        waypoints.append(q)
    return np.array(waypoints), "ok"
