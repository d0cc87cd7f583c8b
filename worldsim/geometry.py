"""Small pose helpers, the 2-D footprint checks used to stop driving robots, and the checked values of arm planning.

Pure Python and numpy (no pybullet): quaternions are ``(x, y, z, w)`` as in
pybullet. :class:`Box` and the ``as_*`` checks are the values the arm's
planning scene takes (skills and the world's scene share them). The footprint checks measure the *penetration depth* of a robot's
circle into obstacles: positive means overlap.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "IDENTITY_QUAT",
    "Box",
    "Footprints",
    "Pose",
    "Quat",
    "Vec3",
    "as_configuration",
    "as_pose",
    "as_quat",
    "as_vec3",
    "circle_box_depth",
    "pose_inverse",
    "pose_multiply",
    "quat_multiply",
    "quat_rotate",
    "quat_to_yaw",
    "wrap_angle",
    "yaw_to_quat",
]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Pose = tuple[Vec3, Quat]

IDENTITY_QUAT: Quat = (0.0, 0.0, 0.0, 1.0)


def wrap_angle(angle: float) -> float:
    """The angle in ``[-pi, pi)``."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def yaw_to_quat(yaw: float) -> Quat:
    """The quaternion of a rotation by ``yaw`` about +z."""
    return (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


def quat_to_yaw(q: Sequence[float]) -> float:
    """The heading (rotation about +z) of a quaternion."""
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quat_multiply(a: Sequence[float], b: Sequence[float]) -> Quat:
    """The Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def quat_rotate(q: Sequence[float], v: Sequence[float]) -> Vec3:
    """The vector ``v`` rotated by the unit quaternion ``q``."""
    x, y, z, w = q
    vx, vy, vz = v
    # t = 2 * cross(q.xyz, v); v' = v + w * t + cross(q.xyz, t)
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def pose_multiply(
    p1: Sequence[float], q1: Sequence[float], p2: Sequence[float], q2: Sequence[float]
) -> tuple[Vec3, Quat]:
    """The composition ``T1 * T2`` of two poses given as position and quaternion."""
    r = quat_rotate(q1, p2)
    return (p1[0] + r[0], p1[1] + r[1], p1[2] + r[2]), quat_multiply(q1, q2)


def pose_inverse(p: Sequence[float], q: Sequence[float]) -> tuple[Vec3, Quat]:
    """The inverse of a pose."""
    qi = (-q[0], -q[1], -q[2], q[3])
    r = quat_rotate(qi, p)
    return (-r[0], -r[1], -r[2]), qi


def circle_box_depth(
    x: float, y: float, r: float, bx: float, by: float, hx: float, hy: float, c: float, s: float
) -> float:
    """Penetration of a circle into a rotated box (positive when they overlap).

    Args:
        x: circle centre x.
        y: circle centre y.
        r: circle radius.
        bx: box centre x.
        by: box centre y.
        hx: box half extent along its x axis.
        hy: box half extent along its y axis.
        c: cosine of the box yaw.
        s: sine of the box yaw.
    """
    dx, dy = x - bx, y - by
    u = c * dx + s * dy
    v = -s * dx + c * dy
    ou = abs(u) - hx
    ov = abs(v) - hy
    if ou <= 0.0 and ov <= 0.0:
        return r - max(ou, ov)
    return r - math.hypot(max(ou, 0.0), max(ov, 0.0))


class Footprints:
    """A set of static circles and rotated boxes with a coarse neighbourhood query.

    Each entry carries the name of the object it belongs to. :meth:`near` returns compact tuples for the pure-Python :func:`depth` check.
    """

    __slots__ = ("_boxes", "_cache", "_circles")

    def __init__(self) -> None:
        self._circles: list[tuple[str, float, float, float]] = []
        self._boxes: list[tuple[str, float, float, float, float, float]] = []
        self._cache: tuple[np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self._circles) + len(self._boxes)

    def add_circle(self, name: str, x: float, y: float, radius: float) -> None:
        """Add a circle footprint."""
        self._circles.append((name, float(x), float(y), float(radius)))
        self._cache = None

    def add_box(self, name: str, x: float, y: float, half_x: float, half_y: float, yaw: float) -> None:
        """Add a rotated box footprint."""
        self._boxes.append((name, float(x), float(y), float(half_x), float(half_y), float(yaw)))
        self._cache = None

    def remove(self, name: str) -> None:
        """Drop every footprint of that name."""
        self._circles = [c for c in self._circles if c[0] != name]
        self._boxes = [b for b in self._boxes if b[0] != name]
        self._cache = None

    def _arrays(self) -> tuple[np.ndarray, np.ndarray]:
        if self._cache is None:
            circles = np.array([c[1:4] for c in self._circles], dtype=float).reshape(-1, 3)
            boxes = np.array([(b[1], b[2], math.hypot(b[3], b[4])) for b in self._boxes], dtype=float).reshape(-1, 3)
            self._cache = (circles, boxes)
        return self._cache

    def near(self, x: float, y: float, reach: float) -> list[tuple[float, ...]]:
        """Footprints whose bounding circle comes within ``reach`` of ``(x, y)``.

        Returns:
            tuples ``(0, cx, cy, r)`` for circles and ``(1, bx, by, hx, hy, cos, sin)`` for boxes.
        """
        circles, boxes = self._arrays()
        out: list[tuple[float, ...]] = []
        if len(circles):
            d = np.hypot(circles[:, 0] - x, circles[:, 1] - y) - circles[:, 2]
            for k in np.flatnonzero(d <= reach):
                _, cx, cy, r = self._circles[int(k)]
                out.append((0, cx, cy, r))
        if len(boxes):
            d = np.hypot(boxes[:, 0] - x, boxes[:, 1] - y) - boxes[:, 2]
            for k in np.flatnonzero(d <= reach):
                _, bx, by, hx, hy, yaw = self._boxes[int(k)]
                out.append((1, bx, by, hx, hy, math.cos(yaw), math.sin(yaw)))
        return out

    @staticmethod
    def depth(x: float, y: float, r: float, entries: Sequence[tuple[float, ...]]) -> float:
        """The deepest penetration of the circle into any of the entries (``-inf`` if none)."""
        worst = -math.inf
        for e in entries:
            if e[0] == 0:
                d = r + e[3] - math.hypot(x - e[1], y - e[2])
            else:
                d = circle_box_depth(x, y, r, e[1], e[2], e[3], e[4], e[5], e[6])
            worst = max(worst, d)
        return worst


# -- checked values for arm planning (the arm's planning scene takes and gives them) --------------


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


@dataclass(frozen=True, slots=True)
class Box:
    """A box: world obstacle, object to pick, or (for a held object) a box in the tool frame.

    The value the arm's planning scene (:class:`~alica.worldsim.arm_interface.ArmPlanningScene`)
    takes for obstacles and held objects.

    Attributes:
        name: unique name among a scene's obstacles.
        center: centre (x, y, z) in metres.
        half_extents: half sizes (hx, hy, hz) in metres, all > 0.
        yaw: rotation about the z axis in radians.
    """

    name: str
    center: Vec3
    half_extents: Vec3
    yaw: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Box name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "center", as_vec3(self.center, f"Box {self.name!r} center"))
        half = as_vec3(self.half_extents, f"Box {self.name!r} half_extents")
        if min(half) <= 0.0:
            raise ValueError(f"Box {self.name!r} half_extents must be > 0, got {half}")
        object.__setattr__(self, "half_extents", half)
        yaw = float(self.yaw)
        if not math.isfinite(yaw):
            raise ValueError(f"Box {self.name!r} yaw must be finite, got {self.yaw!r}")
        object.__setattr__(self, "yaw", yaw)

    @property
    def pose(self) -> Pose:
        """The box's pose ``(center, quat_xyzw)``."""
        return self.center, yaw_to_quat(self.yaw)

    @property
    def top(self) -> float:
        """Height of the top face (for an upright box in the world)."""
        return self.center[2] + self.half_extents[2]
