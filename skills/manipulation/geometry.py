"""Small pose and quaternion helpers (pybullet conventions: quaternions are x, y, z, w).

Everything here is plain Python on tuples, fast enough for a few calls per
planning query, and independent of any physics client.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from alica.worldsim.geometry import quat_multiply, quat_rotate  # the same quaternion algebra as the world's

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Pose = tuple[Vec3, Quat]

IDENTITY_QUAT: Quat = (0.0, 0.0, 0.0, 1.0)


def as_vec3(v: Sequence[float], name: str = "vector") -> Vec3:
    """Return ``v`` as a float 3-tuple, or raise ``ValueError`` if it is not three finite numbers."""
    try:
        out = tuple(float(x) for x in v)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be three numbers, got {v!r}") from exc
    if len(out) != 3 or not all(math.isfinite(x) for x in out):
        raise ValueError(f"{name} must be three finite numbers, got {v!r}")
    return out


def as_quat(q: Sequence[float], name: str = "quaternion") -> Quat:
    """Return ``q`` normalised as a float 4-tuple (x, y, z, w); ``ValueError`` if invalid."""
    try:
        out = tuple(float(x) for x in q)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be four numbers (x, y, z, w), got {q!r}") from exc
    if len(out) != 4 or not all(math.isfinite(x) for x in out):
        raise ValueError(f"{name} must be four finite numbers (x, y, z, w), got {q!r}")
    n = math.sqrt(sum(x * x for x in out))
    if n < 1e-9:
        raise ValueError(f"{name} must not be zero")
    return (out[0] / n, out[1] / n, out[2] / n, out[3] / n)


def as_pose(pose: Sequence[Sequence[float]], name: str = "pose") -> Pose:
    """Validate a ``((x, y, z), (qx, qy, qz, qw))`` pose."""
    if len(pose) != 2:
        raise ValueError(f"{name} must be ((x, y, z), (qx, qy, qz, qw)), got {pose!r}")
    return as_vec3(pose[0], f"{name} position"), as_quat(pose[1], f"{name} orientation")


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


def as_configuration(q: Sequence[float] | np.ndarray, dof: int, name: str = "q") -> np.ndarray:
    """Return ``q`` as a float array of length ``dof``.

    Raises:
        ValueError: wrong length, not numeric, or NaN/inf entries.
    """
    try:
        arr = np.asarray(q, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be {dof} joint values, got {q!r}") from exc
    if arr.shape != (dof,):
        raise ValueError(f"{name} must have {dof} joint values, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contains NaN or infinite values: {arr.tolist()}")
    return arr
