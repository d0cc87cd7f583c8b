"""A close look with the robot's own camera: where a sample container stands, before the arm grasps it.

The team's perception (Verify2DObject, the point-cloud pipeline) places a
sample as ``pos(s)``, a few centimetres off: enough to drive to it, not to
close a gripper around a 6 cm container. Before the grasp, the robot looks at
that place with its own camera from where it stands (the arm's reach ahead of
it, well inside the camera's view) and measures the container:
:func:`look_at` takes one depth picture (``robot.camera(believed=True)``: its
points are in the robot's believed frame, as the arm's are), keeps the points
within :data:`SEARCH` metres of the expected place that stand above the local
ground (the median height of a ring around it, so a slope does not count),
keeps the cluster nearest the expected place
(:func:`alica.skills.pointcloud.euclidean_clusters`) and fits it:

* a container higher than halfway between its length and its diameter stands
  upright: its axis is the centre of a circle of the container's radius
  fitted to the points seen from one side (:func:`fit_circle_of_radius`);
* a lower one lies: its axis is the cluster's main horizontal direction, its
  centre the middle of the points along the axis, half a diameter behind the
  visible surface across it.

The container's dimensions are the mission's data (a lunar sample container
is a standard part); its place and how it lies come from the picture only.
VerifyPlaced uses the same look to check where a container lies after it was
put down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from alica.skills.pointcloud import euclidean_clusters
from alica.worldsim.geometry import Box, quat_rotate
from alica.worldsim.interface import MobileRobot

__all__ = [
    "GROUND_CUT",
    "SEARCH",
    "Sighting",
    "fit_circle_of_radius",
    "in_arm_frame",
    "look_at",
    "sighting_from_points",
]

#: Metres around the expected place searched for the container's points.
SEARCH = 0.2
#: Points this many metres above the local ground belong to something standing on it.
GROUND_CUT = 0.012
#: Metres between two points of one cluster.
CLUSTER_TOLERANCE = 0.02
#: Fewest points of a container seen.
MIN_POINTS = 12
#: Width and height of the picture, pixels.
PICTURE = (320, 240)


@dataclass(frozen=True, slots=True)
class Sighting:
    """A sample container as the camera saw it.

    Attributes:
        x: its centre (the axis' middle), metres, in the robot's believed frame.
        y: metres.
        ground: the local ground's height there, metres.
        top: the highest point seen, metres.
        bottom: the lowest point seen above the ground cut, metres.
        upright: whether it stands on its end (else it lies on its side).
        yaw: the direction of its axis when it lies, radians (0 when upright).
        points: how many points were seen on it.
    """

    x: float
    y: float
    ground: float
    top: float
    bottom: float
    upright: bool
    yaw: float
    points: int

    @property
    def xy(self) -> tuple[float, float]:
        """``(x, y)``."""
        return (self.x, self.y)

    def box(self, name: str, size: float, radius: float) -> Box:
        """The container as the arm planner's box: upright ``(r, r, size/2)``, lying ``(size/2, r, r)`` along ``yaw``."""
        if self.upright:
            return Box(name, (self.x, self.y, self.ground + 0.5 * size), (radius, radius, 0.5 * size), 0.0)
        return Box(name, (self.x, self.y, self.ground + radius), (0.5 * size, radius, radius), self.yaw)


def in_arm_frame(
    seen: Sighting,
    estimate: tuple[float, float, float],
    mount_offset: tuple[float, float, float],
    arm_base: tuple[tuple[float, float, float], tuple[float, float, float, float]],
) -> Sighting:
    """``seen`` (in the robot's believed frame) in the frame the arm plans in (its base at ``arm_base``).

    The camera and the arm sit on one body: what the camera measured relative
    to the robot is where it is relative to the arm's base (the mount offset),
    whatever the robot believes of its own place. So a pose estimate a few
    centimetres off does not move the grasp.
    """
    x, y, yaw = (float(v) for v in estimate)
    mx, my = float(mount_offset[0]), float(mount_offset[1])
    bx, by = x + mx * math.cos(yaw) - my * math.sin(yaw), y + mx * math.sin(yaw) + my * math.cos(yaw)
    axis = quat_rotate(tuple(arm_base[1]), (1.0, 0.0, 0.0))
    turn = math.atan2(axis[1], axis[0]) - yaw
    dx, dy = seen.x - bx, seen.y - by
    ax = float(arm_base[0][0]) + dx * math.cos(turn) - dy * math.sin(turn)
    ay = float(arm_base[0][1]) + dx * math.sin(turn) + dy * math.cos(turn)
    return replace(seen, x=ax, y=ay, yaw=seen.yaw + turn if not seen.upright else 0.0)


def fit_circle_of_radius(xy: np.ndarray, radius: float, start: tuple[float, float]) -> tuple[float, float]:
    """The centre of the circle of ``radius`` nearest to 2-D points (Gauss-Newton from ``start``).

    With the radius known, points on one side of a small cylinder fix its
    axis far better than a free circle fit does.
    """
    c = np.asarray(start, dtype=float)
    p = np.asarray(xy, dtype=float)
    for _ in range(20):
        diff = p - c
        dist = np.maximum(np.linalg.norm(diff, axis=1), 1e-9)
        jac = -diff / dist[:, None]
        step, *_ = np.linalg.lstsq(jac, -(dist - radius), rcond=None)
        c = c + step
        if float(np.abs(step).max()) < 1e-7:
            break
    return float(c[0]), float(c[1])


def sighting_from_points(
    points: np.ndarray, viewpoint: np.ndarray, prior: tuple[float, float], *, size: float, radius: float
) -> Sighting | None:
    """The container near ``prior`` in a cloud of world points seen from ``viewpoint`` (see the module docstring).

    Returns:
        The sighting, or None when fewer than :data:`MIN_POINTS` points stand there.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) == 0:
        return None
    off = np.hypot(pts[:, 0] - prior[0], pts[:, 1] - prior[1])
    ring = pts[(off >= SEARCH) & (off < SEARCH + 0.25)]
    ground = float(np.median(ring[:, 2])) if len(ring) >= MIN_POINTS else 0.0
    near = pts[(off < SEARCH) & (pts[:, 2] > ground + GROUND_CUT) & (pts[:, 2] < ground + 2.0 * size + 0.1)]
    if len(near) < MIN_POINTS:
        return None
    clusters = [c for c in euclidean_clusters(near, CLUSTER_TOLERANCE, MIN_POINTS) if len(c) >= MIN_POINTS]
    if not clusters:
        return None
    cloud = min(
        (near[c] for c in clusters),
        key=lambda q: math.hypot(float(q[:, 0].mean()) - prior[0], float(q[:, 1].mean()) - prior[1]),
    )
    top = float(np.percentile(cloud[:, 2], 98.0))
    bottom = float(cloud[:, 2].min())
    centroid = cloud[:, :2].mean(axis=0)
    view = centroid - np.asarray(viewpoint, dtype=float)[:2]
    view = view / max(float(np.linalg.norm(view)), 1e-9)
    upright = top - ground > 0.5 * (size + 2.0 * radius)
    if upright:
        start = centroid + (2.0 / math.pi) * radius * view  # the mean of a half circle seen from outside
        x, y = fit_circle_of_radius(cloud[:, :2], radius, (float(start[0]), float(start[1])))
        if math.hypot(x - start[0], y - start[1]) > radius:  # a poor fit (few or noisy points): the start serves
            x, y = float(start[0]), float(start[1])
        return Sighting(x, y, ground, top, bottom, True, 0.0, len(cloud))
    flat = cloud[:, :2] - centroid
    _, vecs = np.linalg.eigh(np.cov(flat.T)) if len(flat) > 2 else (None, np.eye(2))
    axis = vecs[:, -1]
    along = flat @ axis
    lo, hi = np.percentile(along, [2.0, 98.0])
    across = np.array([-axis[1], axis[0]])
    if float(across @ view) < 0.0:
        across = -across  # pointing away from the camera
    centre = centroid + 0.5 * (lo + hi) * axis + (2.0 / math.pi) * radius * across
    yaw = math.atan2(float(axis[1]), float(axis[0]))
    return Sighting(float(centre[0]), float(centre[1]), ground, top, bottom, False, yaw, len(cloud))


def look_at(
    robot: MobileRobot, prior: tuple[float, float], *, size: float, radius: float, far: float = 4.0
) -> Sighting | None:
    """Look at ``prior`` with ``robot``'s camera (panned toward it when it can pan) and measure the container there.

    Returns:
        The sighting, or None when the robot has no camera, cannot turn it
        there, or sees no container within :data:`SEARCH` of ``prior``.
    """
    spec = robot.spec
    if not ({"camera", "stereo_camera"} & spec.capabilities):
        return None
    x, y, yaw = robot.estimate
    bearing = math.remainder(math.atan2(prior[1] - y, prior[0] - x) - yaw, math.tau)
    limit = float(spec.camera_pan_limit)
    pan = max(-limit, min(limit, bearing))
    if abs(bearing - pan) > 0.5 * float(spec.camera_fov) - 0.1:
        return None  # out of the view the camera can turn to
    distance = math.hypot(prior[0] - x, prior[1] - y)
    width, height = PICTURE
    image = robot.camera(width=width, height=height, pan=pan, believed=True, far=min(far, distance + 1.5))
    return sighting_from_points(image.points(max_depth=distance + 1.0), image.position, prior, size=size, radius=radius)
