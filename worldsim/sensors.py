"""Simulated sensors: a 2-D lidar, an object perception model, and lidar-to-grid mapping.

* :func:`lidar_scan` casts all rays in one ``rayTestBatch`` from the robot's
  scan plane; rays that hit the robot's own arm or held object are continued
  past it. Ranges are from the robot centre; a ray without a hit reads the
  maximum range.
* :func:`perceive` reports the samples and blocks in range, inside the field
  of view and in line of sight, with position noise and (for samples) a
  chance of a wrong kind: larger for a ``camera`` than for ``3d`` perception.
* :func:`scan_to_grid` marks a scan in a :class:`~alica.worldsim.grid.OccupancyGrid`.

Noise comes from the world's seeded rng and ``world.noise``.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.worldsim.errors import WorldError
from alica.worldsim.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from alica.worldsim.kinds import SAMPLE_KINDS

if TYPE_CHECKING:
    from alica.worldsim.sensing import SensingRobot, SensingWorld

__all__ = ["Detection", "lidar_angles", "lidar_scan", "perceive", "scan_to_grid", "unknown_grid"]

# Rays start just outside the base so that the robot's own cylinder is never hit.
_RAY_START_GAP = 0.01
_CAMERA_HEIGHT_ABOVE_BASE = 0.3
#: Coordinates beyond this are an unbounded box (a ground plane's).
_UNBOUNDED = 1e20


@dataclass(frozen=True, slots=True)
class Detection:
    """One perceived object.

    Attributes:
        name: the object's name (data association is assumed).
        kind: the perceived kind: a sample container kind, or ``"block"``.
        position: the perceived ``(x, y, z)`` (noisy).
        confidence: in (0, 1], lower far away and for a camera.
    """

    name: str
    kind: str
    position: tuple[float, float, float]
    confidence: float


def lidar_angles(n_rays: int) -> np.ndarray:
    """Ray angles relative to the robot heading: ``n_rays`` evenly spaced from -pi (inclusive) to pi."""
    return -math.pi + (2.0 * math.pi / n_rays) * np.arange(n_rays)


def _level_at_zero(client: Any, body: int) -> bool:
    """Whether a body sits at z = 0 unrotated (the ground plane as the world makes it)."""
    position, orientation = client.getBasePositionAndOrientation(body)
    return abs(position[2]) < 1e-9 and abs(abs(orientation[3]) - 1.0) < 1e-9


def _own_bodies(robot: SensingRobot) -> set[int]:
    own = {robot.body_id}
    if robot.arm is not None:
        own.add(robot.arm.body_id)
        if robot.arm.held is not None:
            own.add(robot.arm.held.body_id)
    return own


def _cast(world: SensingWorld, starts: np.ndarray, ends: np.ndarray, skip: set[int]) -> tuple[np.ndarray, np.ndarray]:
    """First hit fraction along each segment and its body id, passing through ``skip`` bodies."""
    c = world.client
    fractions = np.ones(len(starts))
    bodies = np.full(len(starts), -1, dtype=int)
    todo = np.arange(len(starts))
    offset = np.zeros(len(starts))
    seg = ends - starts
    for _ in range(4):
        if len(todo) == 0:
            break
        s = starts[todo] + seg[todo] * offset[todo, None]
        hits = c.rayTestBatch(s.tolist(), ends[todo].tolist())
        body = np.fromiter((hit[0] for hit in hits), dtype=int, count=len(hits))
        frac = np.fromiter((hit[2] for hit in hits), dtype=float, count=len(hits))
        total = offset[todo] + (1.0 - offset[todo]) * frac
        own = np.isin(body, list(skip))
        done = (body >= 0) & ~own
        fractions[todo[done]] = total[done]
        bodies[todo[done]] = body[done]
        # a ray that hit the robot itself goes on from just past that hit
        offset[todo[own]] = np.minimum(1.0, total[own] + 1e-4)
        todo = todo[own]
    return fractions, bodies


#: Metres added around a body's box when deciding which rays can hit it (pybullet's boxes carry margins).
_BOX_PAD = 0.02


def _boxes(world: SensingWorld, own: set[int], z: float) -> np.ndarray | None:
    """The axis-aligned boxes ``(xmin, ymin, zmin, xmax, ymax, zmax)`` of every body and link but ``own``,
    grown by :data:`_BOX_PAD`; ``None`` when one is unbounded (other than a ground plane below ``z``).

    Rocks never move: their boxes are kept until the world's bodies change.
    """
    c = world.client
    cached = _STILL.get(world)
    if cached is None or cached[0] != world._version:
        kinds = {obj.body_id: obj.kind for obj in world.objects.values()}
        still = {obj.body_id: c.getAABB(obj.body_id) for obj in world.objects.values() if obj.kind == "rock"}
        cached = (world._version, kinds, still)
        _STILL[world] = cached
    _, kinds, still = cached
    rows = []
    for k in range(c.getNumBodies()):
        body = c.getBodyUniqueId(k)
        if body in own:
            continue
        box = still.get(body)
        if box is not None:
            rows.append((*box[0], *box[1]))
            continue
        for link in range(-1, c.getNumJoints(body)):
            lo, hi = c.getAABB(body, link)
            if max(abs(v) for v in (*lo, *hi)) >= _UNBOUNDED:
                if kinds.get(body) == "terrain" and link == -1 and z > 1e-3 and _level_at_zero(c, body):
                    continue  # the scan runs above the ground plane
                return None
            rows.append((*lo, *hi))
    boxes = np.array(rows, dtype=float).reshape(-1, 6)
    boxes[:, :3] -= _BOX_PAD
    boxes[:, 3:] += _BOX_PAD
    return boxes


_STILL: weakref.WeakKeyDictionary[Any, tuple[int, dict[int, str], dict[int, Any]]] = weakref.WeakKeyDictionary()


def _ray_reach(
    world: SensingWorld, origin: np.ndarray, yaw: float, n_rays: int, rng_max: float, own: set[int]
) -> np.ndarray:
    """How far each ray of a horizontal scan from ``origin`` must be cast: beyond the farthest box it meets.

    A ray meets a body's (or link's) axis-aligned box only if its angle lies
    between the angles of the box's corners seen from the origin; 0 for a ray
    that meets no box (a miss, not cast at all). The robot's own bodies are
    passed through anyway and a flat ground plane below the scan is never met.
    ``rng_max`` for every ray when some body has no bounded box.
    """
    x, y, z = (float(v) for v in origin)
    boxes = _boxes(world, own, z)
    if boxes is None:
        return np.full(n_rays, rng_max)
    boxes = boxes[(boxes[:, 2] <= z) & (z <= boxes[:, 5])]
    x0, y0, x1, y1 = boxes[:, 0], boxes[:, 1], boxes[:, 3], boxes[:, 4]
    far = np.sqrt(np.maximum((x0 - x) ** 2, (x1 - x) ** 2) + np.maximum((y0 - y) ** 2, (y1 - y) ** 2))
    inside = (x0 <= x) & (x <= x1) & (y0 <= y) & (y <= y1)
    near = np.hypot(x - np.clip(x, x0, x1), y - np.clip(y, y0, y1))
    reach = np.zeros(n_rays)
    if inside.any():  # the scanner is inside a box: every ray meets it
        reach[:] = far[inside].max()
    seen = ~inside & (near <= rng_max)
    x0, y0, x1, y1, far = x0[seen], y0[seen], x1[seen], y1[seen], far[seen]
    middle = np.arctan2(0.5 * (y0 + y1) - y, 0.5 * (x0 + x1) - x)
    corners = np.arctan2(np.stack([y0, y1, y0, y1]) - y, np.stack([x0, x0, x1, x1]) - x)
    spread = (corners - middle + math.pi) % math.tau - math.pi  # corner angles about the middle, (-pi, pi)
    step = math.tau / n_rays
    first = yaw - math.pi  # the angle of ray 0
    k0 = np.floor((middle + spread.min(axis=0) - first) / step).astype(int) - 1
    k1 = np.ceil((middle + spread.max(axis=0) - first) / step).astype(int) + 1
    for a, b, d in zip(k0.tolist(), k1.tolist(), far.tolist(), strict=True):
        count = b - a + 1  # rays a..b, around the end of the scan if need be
        if count >= n_rays:
            np.maximum(reach, d, out=reach)
            continue
        a %= n_rays
        part = reach[a : min(a + count, n_rays)]
        np.maximum(part, d, out=part)
        if a + count > n_rays:
            part = reach[: a + count - n_rays]
            np.maximum(part, d, out=part)
    return reach


def lidar_scan(
    robot: SensingRobot, n_rays: int = 360, max_range: float | None = None, *, noise: float | None = None
) -> np.ndarray:
    """One 2-D scan: ranges in metres from the robot centre, at the angles of :func:`lidar_angles`.

    Args:
        robot: the scanning robot (its own bodies are not seen).
        n_rays: rays over the full circle.
        max_range: the range of a ray without a hit; the spec's ``lidar_range`` when omitted.
        noise: standard deviation of Gaussian range noise on hits; ``world.noise.lidar_sigma`` when omitted.

    Raises:
        WorldError: fewer than 1 ray or a non-positive range.
    """
    world = robot.world
    if int(n_rays) < 1:
        raise WorldError(f"lidar_scan needs at least 1 ray, got {n_rays}")
    rng_max = robot.spec.lidar_range if max_range is None else float(max_range)
    start_r = robot.spec.radius + _RAY_START_GAP
    if not rng_max > start_r:
        raise WorldError(f"lidar_scan: max_range must exceed the robot radius plus {_RAY_START_GAP} m, got {max_range}")
    x, y, yaw = robot.pose
    n = int(n_rays)
    angles = yaw + lidar_angles(n)
    dirs = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
    origin = np.array([x, y, robot.spec.lidar_height])
    own = _own_bodies(robot)
    # cast only the rays that can hit something, and only as far as that can be
    reach = _ray_reach(world, origin, yaw, n, rng_max, own)
    cast = np.flatnonzero(reach > start_r)
    ranges = np.full(n, rng_max)
    hit = np.zeros(n, dtype=bool)
    if len(cast):
        ends = np.minimum(reach[cast], rng_max)
        starts = origin + start_r * dirs[cast]
        fractions, bodies = _cast(world, starts, origin + ends[:, None] * dirs[cast], own)
        hit[cast] = bodies >= 0
        ranges[cast] = np.where(bodies >= 0, start_r + fractions * (ends - start_r), rng_max)
    sigma = world.noise.lidar_sigma if noise is None else float(noise)
    if sigma > 0.0 and hit.any():
        ranges[hit] += world.rng.normal(0.0, sigma, int(hit.sum()))
        np.clip(ranges, 0.0, rng_max, out=ranges)
    return ranges


def perceive(robot: SensingRobot, max_range: float | None = None, *, fov: float | None = None) -> list[Detection]:
    """The samples and blocks the robot sees now, in name order.

    An object is seen when its centre is within ``max_range`` of the robot,
    within half the field of view of the heading, not held, and no other body
    blocks the line of sight from the camera (on top of the base).

    Args:
        robot: the perceiving robot; ``spec.perception`` selects the error model.
        max_range: the spec's ``perception_range`` when omitted.
        fov: horizontal field of view in radians; the spec's ``camera_fov`` when omitted.
    """
    world = robot.world
    spec = robot.spec
    reach = spec.perception_range if max_range is None else float(max_range)
    view = spec.camera_fov if fov is None else float(fov)
    if not reach > 0.0:
        raise WorldError(f"perceive: max_range must be positive, got {max_range}")
    x, y, yaw = robot.pose
    held = world._held_bodies()
    candidates = []
    for name in sorted(world.objects):
        obj = world.objects[name]
        if obj.kind not in ("sample", "block") or obj.body_id in held:
            continue
        p = obj.position()
        d = math.hypot(p[0] - x, p[1] - y)
        bearing = math.atan2(p[1] - y, p[0] - x) - yaw
        bearing = (bearing + math.pi) % (2.0 * math.pi) - math.pi
        if d <= reach and abs(bearing) <= 0.5 * view:
            candidates.append((obj, p, d))
    if not candidates:
        return []
    eye = np.array([x, y, spec.height + _CAMERA_HEIGHT_ABOVE_BASE])
    targets = np.array([p for _, p, _ in candidates])
    _, bodies = _cast(world, np.repeat(eye[None, :], len(candidates), axis=0), targets, _own_bodies(robot))
    noise = world.noise
    stereo = spec.perception == "3d"
    sigma0 = noise.position_sigma * (0.25 if stereo else 1.0)
    wrong = noise.stereo_misclassification if stereo else noise.camera_misclassification
    out = []
    for (obj, p, d), body in zip(candidates, bodies, strict=True):
        if body not in (-1, obj.body_id):
            continue
        sigma = sigma0 * (1.0 + d / reach)
        position = p + world.rng.normal(0.0, sigma, 3)
        kind = "block"
        if obj.kind == "sample":
            kind = obj.sample_kind or SAMPLE_KINDS[0]
            if wrong > 0.0 and world.rng.random() < wrong:
                others = [k for k in SAMPLE_KINDS if k != kind]
                kind = others[int(world.rng.integers(len(others)))]
        confidence = (0.95 if stereo else 0.85) * (1.0 - 0.5 * d / reach)
        out.append(Detection(obj.name, kind, (float(position[0]), float(position[1]), float(position[2])), confidence))
    return out


def unknown_grid(bounds: tuple[float, float, float, float], resolution: float = 0.1) -> OccupancyGrid:
    """An all-unknown grid covering ``bounds`` (e.g. ``world.bounds``), for :func:`scan_to_grid`."""
    grid = OccupancyGrid.from_obstacles([], bounds, resolution)
    grid.cells[:] = UNKNOWN
    return grid


def scan_to_grid(grid: OccupancyGrid, robot: SensingRobot, ranges: np.ndarray, max_range: float | None = None) -> int:
    """Mark a scan of :func:`lidar_scan` taken at the robot's current pose: rays free, hits occupied.

    Args:
        grid: the grid to update in place.
        robot: the robot that took the scan (its pose and spec).
        ranges: the ranges, one per ray at the angles of :func:`lidar_angles`.
        max_range: the scan's maximum range (a reading at it is no hit); the spec's ``lidar_range`` when omitted.

    Returns:
        The number of hits marked.
    """
    ranges = np.asarray(ranges, dtype=float).reshape(-1)
    rng_max = robot.spec.lidar_range if max_range is None else float(max_range)
    x, y, yaw = robot.pose
    angles = yaw + lidar_angles(len(ranges))
    c, s = np.cos(angles), np.sin(angles)
    res = grid.resolution
    hit = ranges < rng_max - 1e-6
    free_to = np.where(hit, ranges - 0.5 * res, ranges)
    along = np.arange(0.0, float(free_to.max(initial=0.0)), 0.5 * res)
    if len(along):
        keep = along[None, :] < free_to[:, None]
        px = x + c[:, None] * along[None, :]
        py = y + s[:, None] * along[None, :]
        grid.mark(np.column_stack([px[keep], py[keep]]), FREE)
    hits = np.column_stack([x + c[hit] * ranges[hit], y + s[hit] * ranges[hit]])
    if len(hits):
        grid.mark(hits, OCCUPIED)
    return int(hit.sum())
