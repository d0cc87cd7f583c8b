"""Small pose and quaternion helpers (pybullet conventions: quaternions are x, y, z, w).

Everything here is plain Python on tuples, fast enough for a few calls per
planning query, and independent of any physics client.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from alica.worldsim.geometry import (  # the same quaternion algebra and checked values as the world's
    IDENTITY_QUAT,
    Pose,
    Quat,
    Vec3,
    as_configuration,
    as_pose,
    as_quat,
    as_vec3,
    quat_multiply,
    quat_rotate,
)

__all__ = [
    "IDENTITY_QUAT",
    "Pose",
    "Quat",
    "Vec3",
    "as_configuration",
    "as_pose",
    "as_quat",
    "as_vec3",
    "pose_inverse",
    "pose_multiply",
    "quat_angle",
    "quat_conjugate",
    "quat_from_yaw",
    "top_down_quat",
    "upright_box",
    "vertical_yaw",
    "wrap_angle",
]


def quat_conjugate(q: Quat) -> Quat:
    """Inverse of a unit quaternion."""
    return (-q[0], -q[1], -q[2], q[3])


def quat_from_yaw(yaw: float) -> Quat:
    """Rotation by ``yaw`` radians about the world z axis."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def top_down_quat(yaw: float) -> Quat:
    """Tool orientation pointing straight down (tool z = world -z), turned by ``yaw`` about world z.

    This is ``Rz(yaw) * Rx(pi)``: at ``yaw = 0`` the tool x axis is world x.
    """
    return quat_multiply(quat_from_yaw(yaw), (1.0, 0.0, 0.0, 0.0))


def quat_angle(a: Sequence[float], b: Sequence[float]) -> float:
    """Angle in radians of the rotation between two unit quaternions (0..pi)."""
    d = abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3])
    return 2.0 * math.acos(min(1.0, d))


def vertical_yaw(q: Quat, tol: float = 1e-3) -> float:
    """Yaw of a rotation that keeps the z axis vertical (pointing up or down).

    A box turned by such a rotation is the same set of points as the box turned
    by ``Rz(yaw)`` alone (boxes are symmetric under a half turn about x).

    Raises:
        ValueError: if the rotation tilts the z axis.
    """
    x, y, z, w = q
    r22 = 1.0 - 2.0 * (x * x + y * y)
    if abs(abs(r22) - 1.0) > tol:
        raise ValueError(f"rotation {q!r} tilts the box: only yaw (and upside-down) boxes are supported")
    r00 = 1.0 - 2.0 * (y * y + z * z)
    r10 = 2.0 * (x * y + w * z)
    return math.atan2(r10, r00)


def upright_box(q: Sequence[float], half_extents: Sequence[float]) -> tuple[float, Vec3]:
    """The yaw and half extents of a box turned by ``q``, seen with its most vertical axis as up.

    A box that fell over onto a side (a quarter turn about a horizontal axis)
    is again a box turned about z alone, with its extents swapped; its Euler
    yaw says nothing about its faces then (the pitch is at the gimbal lock).
    A box left leaning gets the nearest upright box.
    """
    axes = [quat_rotate(q, e) for e in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))]
    up = max(range(3), key=lambda k: abs(axes[k][2]))
    first, second = (k for k in range(3) if k != up)
    yaw = math.atan2(axes[first][1], axes[first][0])
    half = (float(half_extents[first]), float(half_extents[second]), float(half_extents[up]))
    return yaw, half


def pose_multiply(a: Pose, b: Pose) -> Pose:
    """Compose two poses: ``b`` expressed in frame ``a`` -> world."""
    pa, qa = a
    pb, qb = b
    rp = quat_rotate(qa, pb)
    return (pa[0] + rp[0], pa[1] + rp[1], pa[2] + rp[2]), quat_multiply(qa, qb)


def pose_inverse(a: Pose) -> Pose:
    """Inverse of a rigid transform."""
    qi = quat_conjugate(a[1])
    p = quat_rotate(qi, a[0])
    return (-p[0], -p[1], -p[2]), qi


def wrap_angle(a: float) -> float:
    """Angle wrapped into (-pi, pi]."""
    w = math.fmod(a + math.pi, 2.0 * math.pi)
    if w <= 0.0:
        w += 2.0 * math.pi
    return w - math.pi
