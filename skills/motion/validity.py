"""Validity checks for a round mobile base: a fast grid checker, a vectorised segment validator, an exact FCL checker.

* :class:`GridChecker` answers "may the robot centre be here?" from the occupancy grid
  inflated by the robot radius plus a safety margin, plus other robots as circles. With
  the default margin every grid-valid state is collision-free for obstacles that lie in
  occupied cells (true for :meth:`alica.worldsim.grid.OccupancyGrid.from_obstacles`, conservative
  by default, and for :meth:`~alica.worldsim.grid.OccupancyGrid.mark` of sensor points).
* :class:`SegmentValidator` is an OMPL ``MotionValidator`` that checks a whole straight
  motion at once in numpy (samples every half cell; the margin covers the gaps).
* :class:`~alica.skills.motion.exact.FclChecker` (in :mod:`alica.skills.motion.exact`, re-exported by
  the package) is the exact check: an FCL cylinder against the obstacles (cylinders, boxes,
  convex or triangle meshes) and the other robots.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np
from ompl import base as ob

from alica.worldsim.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

__all__ = ["GridChecker", "Robot", "SegmentValidator", "check_robots", "default_margin", "densify"]

Robot = tuple[float, float, float]
"""Another robot as ``(x, y, radius)``."""


_PROBES = 4
_RAMP = np.arange(4096, dtype=np.float64)
_RAMP.flags.writeable = False


def _ramp(n: int) -> np.ndarray:
    """``0.0, 1.0, ..., n - 1`` (a view of a shared read-only array when it is long enough)."""
    return _RAMP[:n] if n <= _RAMP.size else np.arange(n, dtype=np.float64)


def default_margin(resolution: float) -> float:
    """Safety margin added to the robot radius before inflating a grid of this resolution.

    A cell diagonal (robot centre and obstacle point are each up to half a diagonal from
    their cell centres) plus a quarter cell (motions are sampled every half cell).
    """
    return resolution * (math.sqrt(2.0) + 0.25)


def check_robots(robots: Iterable[Sequence[float]]) -> tuple[Robot, ...]:
    """Validate and normalise ``(x, y, radius)`` triples.

    Raises:
        ValueError: If an entry is not three finite numbers with a radius >= 0.
    """
    out: list[Robot] = []
    for entry in robots:
        if len(entry) != 3:
            raise ValueError(f"other robots must be (x, y, radius) triples, got {entry!r}")
        x, y, r = (float(v) for v in entry)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(r)) or r < 0.0:
            raise ValueError(f"other robot {entry!r} needs finite x, y and a radius >= 0")
        out.append((x, y, r))
    return tuple(out)


class GridChecker:
    """State and segment validity from an inflated occupancy grid (plus other robots as circles).

    Args:
        grid: The raw occupancy grid (not inflated).
        robot_radius: Robot radius in metres (>= 0).
        margin: Extra inflation in metres; default :func:`default_margin` of the grid resolution.
        unknown_is_free: Treat unknown cells as free (default: blocked).
        other_robots: Other robots as ``(x, y, radius)``; the robot is invalid where its disk
            overlaps theirs.

    Raises:
        ValueError: On a negative radius or margin.
    """

    __slots__ = (
        "_blocked",
        "_bytes",
        "_flat",
        "_h",
        "_inv",
        "_ox",
        "_oy",
        "_rr",
        "_w",
        "grid",
        "margin",
        "robot_radius",
        "robots",
        "step",
        "unknown_is_free",
    )

    def __init__(
        self,
        grid: OccupancyGrid,
        robot_radius: float,
        *,
        margin: float | None = None,
        unknown_is_free: bool = False,
        other_robots: Iterable[Sequence[float]] = (),
    ) -> None:
        if not (robot_radius >= 0.0 and math.isfinite(robot_radius)):
            raise ValueError(f"robot_radius must be a finite value >= 0 metres, got {robot_radius}")
        if margin is None:
            margin = default_margin(grid.resolution)
        if not (margin >= 0.0 and math.isfinite(margin)):
            raise ValueError(f"margin must be a finite value >= 0 metres, got {margin}")
        inflated = grid.inflate(robot_radius + margin)
        blocked = inflated.cells == OCCUPIED
        if not unknown_is_free:
            blocked |= inflated.cells == UNKNOWN
        self.grid = grid
        self.robot_radius = float(robot_radius)
        self.margin = float(margin)
        self.unknown_is_free = bool(unknown_is_free)
        self._set_blocked(blocked)
        self._set_robots(check_robots(other_robots))

    def _set_blocked(self, blocked: np.ndarray) -> None:
        g = self.grid
        self._blocked = blocked
        self._flat = blocked.reshape(-1)
        self._bytes = blocked.astype(np.uint8).tobytes()
        self._ox, self._oy = g.origin
        self._inv = 1.0 / g.resolution
        self._w, self._h = g.width, g.height
        self.step = 0.5 * g.resolution

    def _set_robots(self, robots: tuple[Robot, ...]) -> None:
        self.robots = robots
        self._rr = tuple((x, y, (self.robot_radius + r) ** 2) for x, y, r in robots)

    @property
    def blocked(self) -> np.ndarray:
        """Boolean (height, width) array: True where the robot centre may not be (grid only)."""
        return self._blocked

    def with_robots(self, other_robots: Iterable[Sequence[float]]) -> GridChecker:
        """A checker sharing this one's inflated grid with a different set of other robots."""
        twin = object.__new__(GridChecker)
        twin.grid = self.grid
        twin.robot_radius = self.robot_radius
        twin.margin = self.margin
        twin.unknown_is_free = self.unknown_is_free
        twin._set_blocked(self._blocked)
        twin._set_robots(check_robots(other_robots))
        return twin

    def with_blocked_disks(self, centers: np.ndarray, radius: float) -> GridChecker:
        """A checker with the cells whose centre lies within ``radius`` of any of ``centers`` (K x 2) also blocked."""
        g = self.grid
        blocked = self._blocked.copy()
        k = math.ceil(radius / g.resolution) + 1
        for cx0, cy0 in np.asarray(centers, dtype=float).reshape(-1, 2):
            i, j = g.world_to_cell(cx0, cy0)
            i0, i1 = max(0, i - k), min(g.width, i + k + 1)
            j0, j1 = max(0, j - k), min(g.height, j + k + 1)
            if i0 >= i1 or j0 >= j1:
                continue
            cx = g.origin[0] + (np.arange(i0, i1) + 0.5) * g.resolution
            cy = g.origin[1] + (np.arange(j0, j1) + 0.5) * g.resolution
            blocked[j0:j1, i0:i1] |= (cx[None, :] - cx0) ** 2 + (cy[:, None] - cy0) ** 2 <= radius * radius
        twin = self.with_robots(self.robots)
        twin._set_blocked(blocked)
        return twin

    def updated(self, grid: OccupancyGrid, windows: Iterable[tuple[int, int, int, int]]) -> GridChecker:
        """A checker for ``grid``, which differs from this checker's grid only inside ``windows``.

        ``windows`` are cell ranges ``(j0, j1, i0, i1)`` (rows ``j0:j1``, columns
        ``i0:i1``); only they are inflated again (from ``grid``'s cells around them),
        so a map that changed in a few tiles costs a few small inflations, not a whole
        one. The result equals ``GridChecker(grid, ...)`` with this checker's radius,
        margin, unknown handling and other robots. This checker is left unchanged.

        Raises:
            ValueError: ``grid`` has another frame (origin, resolution or size).
        """
        g = self.grid
        if (grid.origin, grid.resolution, grid.width, grid.height) != (g.origin, g.resolution, g.width, g.height):
            raise ValueError("updated() needs a grid of the same origin, resolution and size")
        blocked = self._blocked.copy()
        k = self._reach_cells()  # a changed cell changes the blocked cells up to k cells around it
        for j0, j1, i0, i1 in windows:
            self._inflate_window(grid, blocked, j0 - k, j1 + k, i0 - k, i1 + k)
        twin = self.with_robots(self.robots)
        twin.grid = grid
        twin._set_blocked(blocked)
        return twin

    def with_cleared_disks(self, disks: Iterable[Sequence[float]]) -> GridChecker:
        """A checker as if no cell whose centre lies within a disk ``(x, y, radius)`` were occupied.

        For a map made with lidar, where the robots' own bodies show as occupied
        cells: clearing them (the robots are checked as robots instead) lets a
        robot plan from where it stands. The returned checker's ``grid`` is the
        cleared raw grid; only the cells around the disks are inflated again.
        """
        g = self.grid
        cells: np.ndarray | None = None
        windows: list[tuple[int, int, int, int]] = []
        res = g.resolution
        for x, y, r in check_robots(disks):
            i, j = g.world_to_cell(x, y)
            k = math.ceil(r / res) + 1
            i0, i1 = max(0, i - k), min(g.width, i + k + 1)
            j0, j1 = max(0, j - k), min(g.height, j + k + 1)
            if i0 >= i1 or j0 >= j1:
                continue
            cx = g.origin[0] + (np.arange(i0, i1) + 0.5) * res
            cy = g.origin[1] + (np.arange(j0, j1) + 0.5) * res
            inside = (cx[None, :] - x) ** 2 + (cy[:, None] - y) ** 2 <= r * r
            source = g.cells if cells is None else cells
            window = source[j0:j1, i0:i1]
            hit = inside & (window == OCCUPIED)
            if not hit.any():
                continue
            if cells is None:
                cells = g.cells.copy()
            cells[j0:j1, i0:i1][hit] = FREE
            windows.append((j0, j1, i0, i1))
        if cells is None:
            return self
        return self.updated(OccupancyGrid(g.origin, g.resolution, g.width, g.height, cells), windows)

    def _reach_cells(self) -> int:
        """Cells around an occupied cell that its inflation can block (and one more)."""
        return math.floor((self.robot_radius + self.margin) / self.grid.resolution + 1e-9) + 1

    def _inflate_window(self, grid: OccupancyGrid, blocked: np.ndarray, j0: int, j1: int, i0: int, i1: int) -> None:
        """Set ``blocked[j0:j1, i0:i1]`` from ``grid``'s cells around it, as the whole grid's inflation would."""
        radius = self.robot_radius + self.margin
        k = self._reach_cells()
        j0, j1 = max(0, j0), min(grid.height, j1)
        i0, i1 = max(0, i0), min(grid.width, i1)
        if j0 >= j1 or i0 >= i1:
            return
        a0, a1 = max(0, j0 - k), min(grid.height, j1 + k)
        b0, b1 = max(0, i0 - k), min(grid.width, i1 + k)
        local = OccupancyGrid(grid.origin, grid.resolution, b1 - b0, a1 - a0, grid.cells[a0:a1, b0:b1])
        inflated = local.inflate(radius).cells[j0 - a0 : j1 - a0, i0 - b0 : i1 - b0]
        part = inflated == OCCUPIED
        if not self.unknown_is_free:
            part |= inflated == UNKNOWN
        blocked[j0:j1, i0:i1] = part

    # --------------------------------------------------------------- states
    def __call__(self, state: ob.State) -> bool:
        """OMPL state validity: a Python ``bool`` for an SE2 state."""
        return self.valid_xy(state.getX(), state.getY())

    def valid_xy(self, x: float, y: float) -> bool:
        """Whether the robot centre may be at (x, y)."""
        fx = (x - self._ox) * self._inv
        fy = (y - self._oy) * self._inv
        if fx < 0.0 or fy < 0.0:
            return False
        i = int(fx)
        j = int(fy)
        if i >= self._w or j >= self._h or self._bytes[j * self._w + i]:
            return False
        for rx, ry, rr in self._rr:
            if (x - rx) ** 2 + (y - ry) ** 2 < rr:
                return False
        return True

    def grid_free_xy(self, x: float, y: float) -> bool:
        """Like :meth:`valid_xy` but ignoring other robots."""
        fx = (x - self._ox) * self._inv
        fy = (y - self._oy) * self._inv
        if fx < 0.0 or fy < 0.0 or fx >= self._w or fy >= self._h:
            return False
        return not self._bytes[int(fy) * self._w + int(fx)]

    def valid_points(self, xy: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`valid_xy` for an (N, 2) array; a boolean array of length N."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        fx = (xy[:, 0] - self._ox) * self._inv
        fy = (xy[:, 1] - self._oy) * self._inv
        ok = (fx >= 0.0) & (fy >= 0.0) & (fx < self._w) & (fy < self._h)
        idx = np.where(ok, fy.astype(np.intp) * self._w + fx.astype(np.intp), 0)
        ok &= ~self._flat[idx]
        for rx, ry, rr in self._rr:
            ok &= (xy[:, 0] - rx) ** 2 + (xy[:, 1] - ry) ** 2 >= rr
        return ok

    # ------------------------------------------------------------- segments
    def segment_valid(self, x0: float, y0: float, x1: float, y1: float) -> bool:
        """Whether the straight motion is valid: grid samples every half cell, robots exactly.

        A few evenly spaced samples are probed in plain Python first (most colliding motions
        stop there), then all samples at once in numpy.
        """
        inv = self._inv
        fx0, fy0 = (x0 - self._ox) * inv, (y0 - self._oy) * inv
        fx1, fy1 = (x1 - self._ox) * inv, (y1 - self._oy) * inv
        w, h = self._w, self._h
        # The grid rectangle is convex: both ends inside => the whole segment is inside
        # (a 1e-9 cell guard band keeps interpolation rounding on the grid).
        if min(fx0, fx1, fy0, fy1) < 0.0 or max(fx0, fx1) >= w - 1e-9 or max(fy0, fy1) >= h - 1e-9:
            return False
        dx, dy = x1 - x0, y1 - y0
        n = int(math.hypot(dx, dy) / self.step) + 2
        ix, iy = (fx1 - fx0) / (n - 1), (fy1 - fy0) / (n - 1)
        cells = self._bytes
        probe = (n - 1) / _PROBES
        for q in range(_PROBES + 1):
            t = q * probe
            if cells[int(fy0 + iy * t) * w + int(fx0 + ix * t)]:
                return False
        ramp = _ramp(n)
        idx = (ramp * iy + fy0).astype(np.intp)
        idx *= w
        idx += (ramp * ix + fx0).astype(np.intp)
        if np.count_nonzero(self._flat.take(idx)):
            return False
        if self._rr:
            seg2 = dx * dx + dy * dy
            for rx, ry, rr in self._rr:
                s = 0.0 if seg2 == 0.0 else min(1.0, max(0.0, ((rx - x0) * dx + (ry - y0) * dy) / seg2))
                if (x0 + s * dx - rx) ** 2 + (y0 + s * dy - ry) ** 2 < rr:
                    return False
        return True

    def first_invalid(self, path_xy: np.ndarray, step: float | None = None) -> int | None:
        """Index of the first invalid sample of the polyline densified at ``step`` (half a cell), else None.

        Returns:
            None when the whole polyline is valid, else the sample index (see :func:`densify`).
        """
        pts = densify(path_xy, self.step if step is None else step)
        bad = np.flatnonzero(~self.valid_points(pts))
        return None if bad.size == 0 else int(bad[0])


def densify(path_xy: np.ndarray, step: float) -> np.ndarray:
    """Points along a polyline (N x >=2) at most ``step`` apart, including every vertex; an (M, 2) array."""
    p = np.asarray(path_xy, dtype=float)[:, :2]
    if len(p) < 2:
        return p.copy()
    seg = np.diff(p, axis=0)
    counts = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / step).astype(np.intp))
    frac = np.concatenate([np.arange(c) / c for c in counts])
    rep = np.repeat(np.arange(len(seg)), counts)
    pts = p[rep] + seg[rep] * frac[:, None]
    return np.vstack([pts, p[-1:]])


class SegmentValidator(ob.MotionValidator):
    """OMPL motion validator that checks a whole SE2 straight motion with :meth:`GridChecker.segment_valid`.

    Args:
        si: The OMPL space information (SE2).
        checker: The grid checker.
    """

    def __init__(self, si: ob.SpaceInformation, checker: GridChecker) -> None:
        super().__init__(si)
        self.checker = checker

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:
        """Whether the motion from ``s1`` to ``s2`` is valid (a Python bool)."""
        return self.checker.segment_valid(s1.getX(), s1.getY(), s2.getX(), s2.getY())
