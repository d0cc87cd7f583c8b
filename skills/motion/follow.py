"""Following a planned path with a unicycle (pure pursuit), noticing lack of progress and blockage, escaping.

Pure numpy; no OMPL objects (but :class:`~alica.skills.motion.validity.FclChecker` may be passed).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from alica.skills.motion.exact import FclChecker
from alica.skills.motion.validity import GridChecker, check_robots, densify
from alica.worldsim.grid import FREE, OCCUPIED, OccupancyGrid

__all__ = ["PathFollower", "escape_goal"]


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def _positive(name: str, value: float) -> float:
    if not (value > 0.0 and math.isfinite(value)):
        raise ValueError(f"{name} must be a finite value > 0, got {value}")
    return float(value)


class PathFollower:
    """Pure-pursuit follower for a unicycle ``(v, w)`` along a polyline.

    Args:
        path: (N, 2) or (N, 3) waypoints (only x, y are used); N >= 1.
        lookahead: Pursuit distance along the path, metres.
        max_speed: Forward speed limit, m/s.
        max_yaw_rate: Turn rate limit, rad/s.
        tolerance: Done when within this distance of the last waypoint, metres.
        stuck_time: :meth:`stuck` fires after this many seconds without progress.
        stuck_distance: Progress along the path that counts, metres.
        turn_in_place: Heading error (rad) above which the robot turns on the spot.

    Raises:
        ValueError: On an empty path or non-positive parameters.
    """

    def __init__(
        self,
        path: np.ndarray,
        lookahead: float = 0.6,
        max_speed: float = 0.5,
        max_yaw_rate: float = 1.0,
        tolerance: float = 0.1,
        *,
        stuck_time: float = 3.0,
        stuck_distance: float = 0.05,
        turn_in_place: float = math.radians(60.0),
    ) -> None:
        pts = np.asarray(path, dtype=float)
        if pts.ndim != 2 or pts.shape[0] < 1 or pts.shape[1] < 2:
            raise ValueError(f"path must be an (N, 2) or (N, 3) array with N >= 1, got shape {pts.shape}")
        self.path = pts[:, :2].copy()
        self.lookahead = _positive("lookahead", lookahead)
        self.max_speed = _positive("max_speed", max_speed)
        self.max_yaw_rate = _positive("max_yaw_rate", max_yaw_rate)
        self.tolerance = _positive("tolerance", tolerance)
        self.stuck_time = _positive("stuck_time", stuck_time)
        self.stuck_distance = _positive("stuck_distance", stuck_distance)
        self.turn_in_place = _positive("turn_in_place", turn_in_place)
        seg = np.diff(self.path, axis=0)
        self._seg = seg
        self._seg_len = np.hypot(seg[:, 0], seg[:, 1])
        self._cum = np.concatenate([[0.0], np.cumsum(self._seg_len)])
        self.total_length = float(self._cum[-1])
        self._s = 0.0
        self._done = False
        self._ref: tuple[float, float, float] | None = None  # (progress, heading error, time)

    # ------------------------------------------------------------ progress
    @property
    def progress(self) -> float:
        """Arc length covered so far (monotone), metres."""
        return self._s

    @property
    def remaining_length(self) -> float:
        """Arc length still to go, metres."""
        return self.total_length - self._s

    def remaining(self, step: float | None = None, horizon: float | None = None) -> np.ndarray:
        """The rest of the path from the last known progress: an (M, 2) array starting at the projection.

        Args:
            step: When given, densify so that points are at most ``step`` apart.
            horizon: Only this many metres ahead along the path.
        """
        s = self._s
        end = self.total_length if horizon is None else min(self.total_length, s + horizon)
        inner = self.path[(self._cum > s) & (self._cum < end)]
        pts = np.vstack([np.array([self.point_at(s)]), inner, np.array([self.point_at(end)])])
        return pts if step is None else densify(pts, step)

    @property
    def done(self) -> bool:
        """Whether the goal was reached."""
        return self._done

    def point_at(self, s: float) -> tuple[float, float]:
        """The path point at arc length ``s`` (clamped to the path)."""
        if len(self._seg) == 0:
            return (float(self.path[0, 0]), float(self.path[0, 1]))
        s = min(max(s, 0.0), self.total_length)
        k = min(int(np.searchsorted(self._cum, s, side="right")) - 1, len(self._seg) - 1)
        frac = 0.0 if self._seg_len[k] == 0.0 else (s - self._cum[k]) / self._seg_len[k]
        p = self.path[k] + self._seg[k] * frac
        return (float(p[0]), float(p[1]))

    def update_progress(self, pose: Sequence[float]) -> float:
        """Project the pose on the path ahead of the current progress (within a window); returns progress."""
        if len(self._seg) == 0:
            return self._s
        window = max(2.0 * self.lookahead, 1.0)
        k0 = min(int(np.searchsorted(self._cum, self._s, side="right")) - 1, len(self._seg) - 1)
        k1 = int(np.searchsorted(self._cum, self._s + window, side="right"))
        k1 = min(max(k1, k0 + 1), len(self._seg))
        a = self.path[k0:k1]
        d = self._seg[k0:k1]
        ln2 = np.maximum(self._seg_len[k0:k1] ** 2, 1e-12)
        rel = np.array([pose[0], pose[1]]) - a
        t = np.clip((rel * d).sum(axis=1) / ln2, 0.0, 1.0)
        closest = a + d * t[:, None]
        dist = np.hypot(closest[:, 0] - pose[0], closest[:, 1] - pose[1])
        best = int(np.argmin(dist))
        s = float(self._cum[k0 + best] + t[best] * self._seg_len[k0 + best])
        if s > self._s:
            self._s = min(s, self.total_length)
        return self._s

    # ------------------------------------------------------------- control
    def command(self, pose: Sequence[float], dt: float) -> tuple[float, float, bool]:
        """Velocity command for the current pose ``(x, y, yaw)``.

        Args:
            pose: Current pose.
            dt: Control period in seconds (>= 0); when positive, the speed is capped so as not
                to overshoot the goal within one period.

        Returns:
            ``(v, w, done)``: forward speed, turn rate, whether the goal is reached (then 0, 0).
        """
        if not (dt >= 0.0 and math.isfinite(dt)):
            raise ValueError(f"dt must be a finite value >= 0 seconds, got {dt}")
        x, y, yaw = float(pose[0]), float(pose[1]), float(pose[2])
        self.update_progress(pose)
        gx, gy = (float(v) for v in self.path[-1])
        to_goal = math.hypot(gx - x, gy - y)
        if self._done or (to_goal <= self.tolerance and self.remaining_length <= self.lookahead + self.tolerance):
            self._done = True
            return (0.0, 0.0, True)
        tx, ty = self.point_at(self._s + self.lookahead)
        ld = math.hypot(tx - x, ty - y)
        if ld < 1e-6:
            tx, ty, ld = gx, gy, to_goal
        alpha = _wrap(math.atan2(ty - y, tx - x) - yaw)
        if abs(alpha) > self.turn_in_place:
            w = math.copysign(min(self.max_yaw_rate, 2.0 * abs(alpha)), alpha)
            return (0.0, w, False)
        v = min(self.max_speed, max(0.05, 1.0 * to_goal))
        if dt > 0.0:
            v = min(v, to_goal / dt)
        v *= max(math.cos(alpha), 0.2)
        curvature = 2.0 * math.sin(alpha) / max(ld, 1e-6)
        w = v * curvature
        if abs(w) > self.max_yaw_rate:
            w = math.copysign(self.max_yaw_rate, w)
            v = self.max_yaw_rate / abs(curvature)
        return (v, w, False)

    # ------------------------------------------------------------ failures
    def stuck(self, pose: Sequence[float], now: float) -> bool:
        """Whether there was no progress for ``stuck_time`` seconds up to ``now``.

        Progress is the arc length along the path growing by ``stuck_distance``, or the
        heading error to the pursuit point shrinking by 0.2 rad (turning on the spot).
        """
        if self._done:
            return False
        s = self.update_progress(pose)
        tx, ty = self.point_at(s + self.lookahead)
        err = abs(_wrap(math.atan2(ty - pose[1], tx - pose[0]) - pose[2]))
        if self._ref is None or s >= self._ref[0] + self.stuck_distance or err <= self._ref[1] - 0.2:
            self._ref = (s, err, float(now))
            return False
        return float(now) - self._ref[2] > self.stuck_time

    def reset_stuck(self) -> None:
        """Forget the progress reference (e.g. after a pause that was intended)."""
        self._ref = None

    def remaining_points(self, pose: Sequence[float], step: float, horizon: float | None = None) -> np.ndarray:
        """The rest of the path from the current projection, densified at ``step``; an (M, 2) array."""
        self.update_progress(pose)
        return self.remaining(step, horizon)

    def blocked(
        self,
        grid_or_checker: OccupancyGrid | GridChecker | FclChecker,
        pose: Sequence[float],
        *,
        robot_radius: float | None = None,
        other_robots: Iterable[Sequence[float]] = (),
        horizon: float | None = None,
    ) -> bool:
        """Whether the rest of the path (optionally only ``horizon`` metres) is no longer free.

        Args:
            grid_or_checker: A :class:`GridChecker` (fast; its margin applies), a raw
                :class:`OccupancyGrid` (the robot disk must not cover an occupied cell; unknown
                cells do not block) or an :class:`FclChecker` (exact, slower).
            pose: Current pose.
            robot_radius: Needed for a raw grid.
            other_robots: Robots to avoid, ``(x, y, radius)``; for an FclChecker they replace its robots.
            horizon: Only look this far ahead along the path.

        Raises:
            ValueError: For a raw grid without a robot radius.
            TypeError: For an unsupported checker.
        """
        robots = check_robots(other_robots)
        if isinstance(grid_or_checker, GridChecker):
            checker = grid_or_checker.with_robots(robots) if robots else grid_or_checker
            pts = self.remaining_points(pose, checker.step, horizon)
            return not bool(checker.valid_points(pts).all())
        if isinstance(grid_or_checker, FclChecker):
            if robots:
                grid_or_checker.set_other_robots(robots)
            pts = self.remaining_points(pose, 0.05, horizon)
            return any(not grid_or_checker.valid_xy(float(x), float(y)) for x, y in pts)
        if isinstance(grid_or_checker, OccupancyGrid):
            if robot_radius is None or not robot_radius >= 0.0:
                raise ValueError("blocked() on a raw OccupancyGrid needs robot_radius >= 0")
            grid = grid_or_checker
            pts = self.remaining_points(pose, 0.5 * grid.resolution, horizon)
            for rx, ry, rr in robots:
                if (np.hypot(pts[:, 0] - rx, pts[:, 1] - ry) < robot_radius + rr).any():
                    return True
            return _disk_hits(grid, pts, robot_radius)
        raise TypeError(
            f"blocked() needs an OccupancyGrid, GridChecker or FclChecker, got {type(grid_or_checker).__name__}"
        )


def _disk_hits(grid: OccupancyGrid, pts: np.ndarray, radius: float) -> bool:
    """Whether a disk of ``radius`` at any of the points covers the centre of an occupied (or off-grid) cell."""
    res = grid.resolution
    k = math.ceil(radius / res)
    di, dj = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1))
    i, j = grid.world_to_cells(pts)
    ci = i[:, None] + di.reshape(1, -1)
    cj = j[:, None] + dj.reshape(1, -1)
    cx = grid.origin[0] + (ci + 0.5) * res
    cy = grid.origin[1] + (cj + 0.5) * res
    near = (cx - pts[:, :1]) ** 2 + (cy - pts[:, 1:2]) ** 2 <= radius * radius
    near |= (di.reshape(1, -1) == 0) & (dj.reshape(1, -1) == 0)
    inside = (ci >= 0) & (ci < grid.width) & (cj >= 0) & (cj < grid.height)
    if (near & ~inside).any():
        return True
    vals = grid.cells[np.clip(cj, 0, grid.height - 1), np.clip(ci, 0, grid.width - 1)]
    return bool((near & inside & (vals == OCCUPIED)).any())


#: What counts as touching for :func:`escape_goal` ``body_radius``: within the radius plus this (m).
TOUCH_MARGIN = 0.02


def escape_goal(
    grid: OccupancyGrid,
    pose: Sequence[float],
    clearance: float,
    max_distance: float,
    *,
    unknown_is_free: bool = False,
    other_robots: Iterable[Sequence[float]] = (),
    keep_away: Iterable[Sequence[float]] = (),
    body_radius: float = 0.0,
) -> tuple[float, float] | None:
    """The nearest cell centre with ``clearance`` to every obstacle, for "drive into free space".

    Only cells within ``max_distance`` of the pose are considered, and only those reachable
    by a straight line that crosses no occupied cell (samples within one cell of the pose are
    ignored, as the robot may sit on marked cells). Off-grid space counts as occupied.

    Args:
        grid: Raw occupancy grid.
        pose: Current ``(x, y[, yaw])``.
        clearance: Required distance from the cell centre to occupied cells (e.g. robot radius + margin).
        max_distance: Search radius, metres.
        unknown_is_free: Count unknown cells as free.
        other_robots: Robots ``(x, y, radius)`` to keep ``clearance`` from as well.
        keep_away: Points ``(x, y, distance)`` the cell centre must be at least ``distance`` from
            (work sites such as stacks of blocks, which a waiting robot must not crowd).
        body_radius: The robot's radius, when it may touch something now: occupied cells and
            other robots within this distance (plus 2 cm) of the pose are what it touches, and
            the spots whose straight way out leads away from each of them come first (a robot
            base refuses to push deeper into what it touches, so a straight line past it would
            not get out); the others only when none of those can be reached.

    Returns:
        ``(x, y)`` or None when no such cell exists.

    Raises:
        ValueError: On a negative clearance or non-positive max_distance.
    """
    if not (clearance >= 0.0 and math.isfinite(clearance)):
        raise ValueError(f"clearance must be a finite value >= 0 metres, got {clearance}")
    max_distance = _positive("max_distance", max_distance)
    px, py = float(pose[0]), float(pose[1])
    res = grid.resolution
    half = math.ceil((max_distance + clearance) / res) + 2
    ci, cj = grid.world_to_cell(px, py)
    i0, j0 = ci - half, cj - half
    n = 2 * half + 1
    window = np.full((n, n), OCCUPIED, dtype=np.uint8)
    a0, a1 = max(0, i0), min(grid.width, i0 + n)
    b0, b1 = max(0, j0), min(grid.height, j0 + n)
    if a0 < a1 and b0 < b1:
        window[b0 - j0 : b1 - j0, a0 - i0 : a1 - i0] = grid.cells[b0:b1, a0:a1]
    origin = (grid.origin[0] + i0 * res, grid.origin[1] + j0 * res)
    local = OccupancyGrid(origin, res, n, n, window)
    inflated = local.inflate(clearance).cells
    free = inflated != OCCUPIED if unknown_is_free else inflated == FREE
    xs = origin[0] + (np.arange(n) + 0.5) * res
    ys = origin[1] + (np.arange(n) + 0.5) * res
    dist = np.hypot(xs[None, :] - px, ys[:, None] - py)
    for rx, ry, rr in check_robots(other_robots):
        free &= np.hypot(xs[None, :] - rx, ys[:, None] - ry) >= clearance + rr
    for kx, ky, kd in check_robots(keep_away):
        free &= np.hypot(xs[None, :] - kx, ys[:, None] - ky) >= kd
    free &= dist <= max_distance
    cand_j, cand_i = np.nonzero(free)
    if cand_i.size == 0:
        return None
    occupied = window == OCCUPIED
    rank = dist[cand_j, cand_i]
    if body_radius > 0.0:
        # the spots that lead away from everything the robot touches come first, the others after them
        touch = body_radius + TOUCH_MARGIN
        near_j, near_i = np.nonzero(occupied & (dist <= touch + 0.5 * res))
        touched = [(float(xs[i]) - px, float(ys[j]) - py) for j, i in zip(near_j, near_i, strict=True)]
        touched += [
            (rx - px, ry - py)
            for rx, ry, rr in check_robots(other_robots)
            if math.hypot(rx - px, ry - py) <= touch + rr
        ]
        dx, dy = xs[cand_i] - px, ys[cand_j] - py
        towards = np.zeros(cand_i.size, dtype=bool)
        for tx, ty in touched:
            towards |= dx * tx + dy * ty > 0.0
        rank = rank + towards * (2.0 * max_distance + 1.0)
    order = np.argsort(rank, kind="stable")
    samples = math.ceil(2.0 * max_distance / res) + 2
    t = np.linspace(0.0, 1.0, samples)[None, :]
    for start in range(0, order.size, 256):
        batch = order[start : start + 256]
        bx, by = xs[cand_i[batch]], ys[cand_j[batch]]
        lx = px + (bx[:, None] - px) * t
        ly = py + (by[:, None] - py) * t
        li = np.floor((lx - origin[0]) / res).astype(np.intp)
        lj = np.floor((ly - origin[1]) / res).astype(np.intp)
        skip = (np.abs(li - (ci - i0)) <= 1) & (np.abs(lj - (cj - j0)) <= 1)
        hits = occupied[np.clip(lj, 0, n - 1), np.clip(li, 0, n - 1)] & ~skip
        clear = np.flatnonzero(~hits.any(axis=1))
        if clear.size:
            k = batch[clear[0]]
            return (float(xs[cand_i[k]]), float(ys[cand_j[k]]))
    return None
