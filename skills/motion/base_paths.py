"""Base motion planning for a round robot on an occupancy grid with OMPL (SE2, RRTConnect, optional AORRTC).

:func:`plan_path` is the entry point. Every OMPL object lives inside one call and paths are
copied to numpy before returning, so nothing OMPL outlives the call.

Reproducibility: OMPL has one process-wide seed that can be set only before the first
planner or sampler exists. The first :func:`plan_path` call of a process that passes a
``seed`` sets it (to ``seed + 1``; OMPL ignores 0). Later seeds cannot take effect and are
only logged. So: the same seed and the same sequence of calls in a fresh process give the
same paths, as long as the first solution is found within the first search slice and no
time-limited optimisation runs (``optimize_time > 0`` is not reproducible).
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from alica.skills.motion.exact import FclChecker
from alica.skills.motion.search import Query, configure_ompl, search, xy_length
from alica.skills.motion.validity import GridChecker
from alica.worldsim.grid import OccupancyGrid

__all__ = ["STATUSES", "PathResult", "configure_ompl", "plan_path"]

_log = logging.getLogger(__name__)

STATUSES = ("exact", "approximate", "invalid_start", "invalid_goal", "timeout", "unreachable")

_MAX_REPAIRS = 6


@dataclass(frozen=True, slots=True, eq=False)
class PathResult:
    """The outcome of :func:`plan_path`.

    Attributes:
        status: One of :data:`STATUSES`. Only ``"exact"`` reaches the goal; ``"approximate"``
            is a valid path that ends short of it.
        path: (N, 3) array of ``(x, y, yaw)`` waypoints (empty (0, 3) on failure). The yaw of
            a waypoint is the heading of the segment leaving it (start: the start yaw; end: the
            goal yaw, or the arrival heading for an any-yaw goal).
        length: Length of the path in the plane, metres.
        plan_time_s: Wall time of the whole call.
        reason: Human-readable explanation (always set).
        first_solution_s: Wall time of the RRTConnect search(es) for the first solution.
        first_solution_cpu_s: CPU time (``time.process_time``) of the same searches.
    """

    status: str
    path: np.ndarray = field(repr=False)
    length: float
    plan_time_s: float
    reason: str
    first_solution_s: float = math.nan
    first_solution_cpu_s: float = math.nan

    @property
    def ok(self) -> bool:
        """True when the path reaches the goal (status ``"exact"``)."""
        return self.status == "exact"


def _with_headings(path: np.ndarray, start_yaw: float, goal_yaw: float | None) -> np.ndarray:
    out = np.array(path, dtype=float, copy=True)
    if len(out) >= 2:
        d = np.diff(out[:, :2], axis=0)
        out[:-1, 2] = np.arctan2(d[:, 1], d[:, 0])
        out[-1, 2] = out[-2, 2] if goal_yaw is None else goal_yaw
    out[0, 2] = start_yaw
    return out


def _polyline_valid(checker: GridChecker, path: np.ndarray) -> bool:
    """Dense re-check of every segment with the grid checker (half-cell samples, robots exactly)."""
    p = path[:, :2]
    if not all(checker.valid_xy(float(x), float(y)) for x, y in p):
        return False
    return all(checker.segment_valid(*map(float, (*a, *b))) for a, b in itertools.pairwise(p))


def _why_invalid(checker: GridChecker, x: float, y: float, what: str) -> str:
    grid = checker.grid
    if not grid.inside(x, y):
        return f"{what} ({x:.2f}, {y:.2f}) is outside the grid {grid.bounds}"
    for rx, ry, rr in checker.robots:
        if math.hypot(x - rx, y - ry) < checker.robot_radius + rr:
            return f"{what} ({x:.2f}, {y:.2f}) overlaps another robot at ({rx:.2f}, {ry:.2f})"
    value = grid.value(x, y)
    if value == 1:
        where = "inside an obstacle"
    elif value == 255 and not checker.unknown_is_free:
        where = "in unknown space"
    else:
        where = "too close to an obstacle"
    return (
        f"{what} ({x:.2f}, {y:.2f}) is {where}: it needs {checker.robot_radius + checker.margin:.2f} m clearance "
        f"(robot radius {checker.robot_radius:.2f} + margin {checker.margin:.2f})"
    )


def _parse_pose(value: Sequence[float], what: str, sizes: tuple[int, ...]) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in value)
    except TypeError as exc:
        raise ValueError(f"{what} must be a sequence of numbers, got {value!r}") from exc
    if len(out) not in sizes or not all(math.isfinite(v) for v in out):
        shapes = " or ".join({2: "(x, y)", 3: "(x, y, yaw)"}[s] for s in sizes)
        raise ValueError(f"{what} must be finite {shapes}, got {value!r}")
    return out


def plan_path(
    start: Sequence[float],
    goal: Sequence[float],
    grid: OccupancyGrid | GridChecker,
    robot_radius: float,
    *,
    obstacles_exact: FclChecker | None = None,
    other_robots: Iterable[Sequence[float]] = (),
    time_limit: float = 1.0,
    optimize_time: float = 0.0,
    seed: int | None = None,
    goal_tolerance: float = 0.1,
    any_yaw: bool = True,
    simplify: bool = True,
    unknown_is_free: bool = False,
    margin: float | None = None,
) -> PathResult:
    """Plan a collision-free path for a round robot from ``start`` to ``goal``.

    Args:
        start: Robot pose ``(x, y, yaw)``; must lie on the grid.
        goal: ``(x, y)`` or ``(x, y, yaw)``.
        grid: The raw occupancy grid (inflated here by ``robot_radius`` + ``margin``), or a
            prepared :class:`GridChecker` for this radius (saves the inflation, ~30 ms on 800 x 800).
        robot_radius: Robot radius in metres (>= 0).
        obstacles_exact: Exact checker for the final path (its other robots are set to
            ``other_robots``); a path that collides there is repaired or reported, never returned.
        other_robots: Other robots as ``(x, y, radius)`` (not this robot itself); when empty,
            a prepared GridChecker keeps its own robots.
        time_limit: Seconds for the first (RRTConnect) solution, including repairs.
        optimize_time: Seconds of AORRTC after the first solution; the shorter path is kept.
        seed: OMPL seed; see the module docstring for what is reproducible.
        goal_tolerance: Metres; for a goal with yaw, OMPL's SE2 distance (xy + 0.5 |dyaw|).
        any_yaw: Reach the goal point with any heading (a 3-element goal's yaw is then ignored).
        simplify: Shortcut the first path (OMPL simplifyMax, a few ms).
        unknown_is_free: Plan through unknown cells.
        margin: Extra clearance; default :func:`~alica.skills.motion.validity.default_margin`.

    Returns:
        A :class:`PathResult`; failures are statuses with a reason, not exceptions.

    Raises:
        ValueError: For bad arguments: malformed poses, a start outside the grid, a negative
            radius, non-positive time limit or tolerance, a checker built for another radius.
        TypeError: When ``grid`` is neither an OccupancyGrid nor a GridChecker.
    """
    t0 = time.perf_counter()
    sx, sy, syaw = _parse_pose(start, "start", (3,))
    goal_v = _parse_pose(goal, "goal", (2, 3))
    gx, gy = goal_v[0], goal_v[1]
    if not any_yaw and len(goal_v) != 3:
        raise ValueError("any_yaw=False needs a goal (x, y, yaw); pass the heading or leave any_yaw=True")
    gyaw = None if any_yaw else goal_v[2]
    if not (robot_radius >= 0.0 and math.isfinite(robot_radius)):
        raise ValueError(f"robot_radius must be a finite value >= 0 metres, got {robot_radius}")
    if not time_limit > 0.0:
        raise ValueError(f"time_limit must be > 0 seconds, got {time_limit}")
    if not optimize_time >= 0.0:
        raise ValueError(f"optimize_time must be >= 0 seconds, got {optimize_time}")
    if not goal_tolerance > 0.0:
        raise ValueError(f"goal_tolerance must be > 0 metres, got {goal_tolerance}")
    if seed is not None and int(seed) < 0:
        raise ValueError(f"seed must be >= 0 or None, got {seed}")
    if isinstance(grid, GridChecker):
        if abs(grid.robot_radius - robot_radius) > 1e-9:
            raise ValueError(
                f"the GridChecker was built for radius {grid.robot_radius}, not {robot_radius}; build one for this radius"
            )
        base = grid
    elif isinstance(grid, OccupancyGrid):
        base = GridChecker(grid, robot_radius, margin=margin, unknown_is_free=unknown_is_free)
    else:
        raise TypeError(f"grid must be an OccupancyGrid or a GridChecker, got {type(grid).__name__}")
    robots = list(other_robots)
    checker = base.with_robots(robots) if robots else base
    robots = list(checker.robots)
    if not checker.grid.inside(sx, sy):
        raise ValueError(
            f"start ({sx:.2f}, {sy:.2f}) is outside the grid {checker.grid.bounds}; use a grid that covers it"
        )
    if obstacles_exact is not None:
        if abs(obstacles_exact.robot_radius - robot_radius) > 1e-9:
            raise ValueError(f"obstacles_exact was built for radius {obstacles_exact.robot_radius}, not {robot_radius}")
        obstacles_exact.set_other_robots(robots)

    def done(
        status: str, path: np.ndarray, reason: str, first: tuple[float, float] = (math.nan, math.nan)
    ) -> PathResult:
        if len(path):
            path = _with_headings(path, syaw, gyaw if status == "exact" else None)
        return PathResult(status, path, xy_length(path), time.perf_counter() - t0, reason, first[0], first[1])

    empty = np.empty((0, 3))
    if not checker.valid_xy(sx, sy):
        return done("invalid_start", empty, _why_invalid(checker, sx, sy, "start"))
    if obstacles_exact is not None and not obstacles_exact.valid_xy(sx, sy):
        return done("invalid_start", empty, f"start ({sx:.2f}, {sy:.2f}) collides in the exact (FCL) check")
    if not checker.valid_xy(gx, gy):
        return done("invalid_goal", empty, _why_invalid(checker, gx, gy, "goal"))
    if obstacles_exact is not None and not obstacles_exact.valid_xy(gx, gy):
        return done("invalid_goal", empty, f"goal ({gx:.2f}, {gy:.2f}) collides in the exact (FCL) check")

    q = Query(sx, sy, syaw, gx, gy, gyaw, goal_tolerance)
    if math.hypot(gx - sx, gy - sy) <= goal_tolerance and checker.segment_valid(sx, sy, gx, gy):
        trivial = np.array([[sx, sy, syaw], [gx, gy, syaw if gyaw is None else gyaw]])
        if obstacles_exact is None or obstacles_exact.first_collision(trivial) is None:
            return done("exact", trivial, "already at the goal", (0.0, 0.0))

    configure_ompl(seed)
    deadline = t0 + time_limit
    first_wall = first_cpu = 0.0
    current = checker
    hit = (math.nan, math.nan)
    for attempt in range(_MAX_REPAIRS + 1):
        found = search(
            current, q, deadline, simplify=simplify, optimize_time=optimize_time, check_reachability=attempt == 0
        )
        first_wall += found.first_solution_s
        first_cpu += found.first_solution_cpu_s
        first_total = (first_wall, first_cpu)
        if found.status != "exact" and found.status != "approximate":
            return done(found.status, empty, found.reason, first_total)
        if not _polyline_valid(current, found.path):
            _log.warning("planned path failed the dense grid re-check; not returned")
            return done("timeout", empty, "the planned path failed the dense grid re-check", first_total)
        if obstacles_exact is None:
            return done(found.status, found.path, found.reason, first_total)
        hits = obstacles_exact.collisions(found.path, checker.grid.resolution)
        if len(hits) == 0:
            return done(found.status, found.path, found.reason, first_total)
        hit = (float(hits[0, 0]), float(hits[0, 1]))
        _log.info(
            "path collides in the exact check at %d samples from (%.2f, %.2f); blocking them, replanning",
            len(hits),
            *hit,
        )
        current = current.with_blocked_disks(hits, current.robot_radius + current.margin)
        if not (current.valid_xy(sx, sy) and current.valid_xy(gx, gy)):
            break
        if time.perf_counter() >= deadline:
            break
    return done(
        "timeout",
        empty,
        f"paths found on the grid collide in the exact (FCL) check (last at ({hit[0]:.2f}, {hit[1]:.2f})): "
        "the grid misses obstacles that the exact model has; no valid path within the time limit",
        (first_wall, first_cpu),
    )
