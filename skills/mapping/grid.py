"""A log-odds occupancy grid updated from 2-D lidar scans.

Pure numpy. Conventions follow :class:`alica.worldsim.grid.OccupancyGrid`:
cell ``(i, j)`` is column ``i``, row ``j``; ``origin`` is the world position of
the lower-left corner of cell ``(0, 0)``; ``logodds[j, i]`` is the cell's
log-odds of being occupied (0 = never observed).

A scan is ray traced: every cell a ray crosses before its hit gets
:data:`L_MISS`, the cell of the hit gets :data:`L_HIT` (each cell at most
once per scan, a hit wins over a miss), and the result is clamped to
``[L_MIN, L_MAX]`` so that the map can change its mind about a cell (a robot
that stood there and left). Rays are sampled every half cell, which visits
the cells a Bresenham line visits (and the odd corner cell more).

The grid is cut into square *tiles* of :data:`TILE` cells; :meth:`LogOddsGrid.update`
marks the tiles it changed, so that a map shared with a team sends only those
(:mod:`alica.skills.mapping.sharing`).

Example:
    >>> import numpy as np
    >>> grid = LogOddsGrid.covering((0.0, 0.0, 4.0, 4.0), 0.1)
    >>> angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    >>> _ = grid.update((1.0, 2.0, 0.0), np.full(360, 3.0), angles, max_range=3.0)
    >>> int(grid.occupancy()[20, 15]), int(grid.occupancy()[20, 39])
    (0, -1)
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["FREE", "L_HIT", "L_MAX", "L_MIN", "L_MISS", "OCCUPIED", "THRESHOLD", "TILE", "UNKNOWN", "LogOddsGrid"]

#: Log-odds added to a cell a ray ends in (p = 0.7).
L_HIT = 0.85
#: Log-odds added to a cell a ray passes through (p = 0.4).
L_MISS = -0.4
#: Clamp of the log-odds: a cell is never so sure that a few scans cannot change it.
L_MIN = -4.0
L_MAX = 4.0
#: Cells with log-odds within +-THRESHOLD count as unknown.
THRESHOLD = 0.2
#: Tile side in cells.
TILE = 32
#: The values of :meth:`LogOddsGrid.occupancy`.
UNKNOWN = -1
FREE = 0
OCCUPIED = 1


class LogOddsGrid:
    """A log-odds occupancy grid (see the module docstring).

    Args:
        origin: world ``(x, y)`` of the lower-left corner of cell ``(0, 0)``.
        resolution: cell side in metres (> 0).
        nx: columns (> 0).
        ny: rows (> 0).
        logodds: optional float32 array of shape ``(ny, nx)``, used as is; all 0 (unknown) when omitted.

    Attributes:
        resolution: cell side in metres.
        origin: world ``(x, y)`` of cell ``(0, 0)``'s lower-left corner.
        logodds: ``(ny, nx)`` float32 log-odds, ``logodds[j, i]``.

    Raises:
        ValueError: a non-positive or non-finite resolution or size, or log-odds of the wrong shape.
    """

    __slots__ = ("_dirty", "logodds", "origin", "resolution")

    def __init__(
        self, origin: Sequence[float], resolution: float, nx: int, ny: int, logodds: np.ndarray | None = None
    ) -> None:
        resolution = float(resolution)
        if not (resolution > 0.0 and math.isfinite(resolution)):
            raise ValueError(f"resolution must be a positive number of metres, got {resolution}")
        if int(nx) <= 0 or int(ny) <= 0:
            raise ValueError(f"a grid needs at least one cell each way, got {nx} x {ny}")
        self.resolution: float = resolution
        self.origin: tuple[float, float] = (float(origin[0]), float(origin[1]))
        if logodds is None:
            logodds = np.zeros((int(ny), int(nx)), dtype=np.float32)
        elif logodds.shape != (int(ny), int(nx)):
            raise ValueError(f"logodds must have shape (ny, nx) = {(int(ny), int(nx))}, got {logodds.shape}")
        self.logodds: np.ndarray = logodds.astype(np.float32, copy=False)
        self._dirty = np.zeros(self.tile_shape, dtype=bool)

    @classmethod
    def covering(cls, bounds: Sequence[float], resolution: float) -> LogOddsGrid:
        """An all-unknown grid covering ``bounds`` ``(xmin, ymin, xmax, ymax)`` (e.g. ``world.bounds``).

        Raises:
            ValueError: empty bounds or a non-positive resolution.
        """
        xmin, ymin, xmax, ymax = (float(b) for b in bounds)
        if not (xmax > xmin and ymax > ymin):
            raise ValueError(f"bounds must be (xmin, ymin, xmax, ymax) with xmax > xmin and ymax > ymin, got {bounds}")
        resolution = float(resolution)
        if not (resolution > 0.0 and math.isfinite(resolution)):
            raise ValueError(f"resolution must be a positive number of metres, got {resolution}")
        nx = max(1, math.ceil((xmax - xmin) / resolution - 1e-9))
        ny = max(1, math.ceil((ymax - ymin) / resolution - 1e-9))
        return cls((xmin, ymin), resolution, nx, ny)

    # ----------------------------------------------------------------- geometry
    @property
    def nx(self) -> int:
        """Columns."""
        return int(self.logodds.shape[1])

    @property
    def ny(self) -> int:
        """Rows."""
        return int(self.logodds.shape[0])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """World extent ``(xmin, ymin, xmax, ymax)``."""
        ox, oy = self.origin
        return (ox, oy, ox + self.nx * self.resolution, oy + self.ny * self.resolution)

    @property
    def tile_shape(self) -> tuple[int, int]:
        """Tiles ``(rows, columns)``."""
        return (-(-self.ny // TILE), -(-self.nx // TILE))

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """Cell ``(i, j)`` containing the world point (may lie outside; see :meth:`inside`)."""
        return (
            math.floor((x - self.origin[0]) / self.resolution),
            math.floor((y - self.origin[1]) / self.resolution),
        )

    def cell_to_world(self, i: int, j: int) -> tuple[float, float]:
        """World position of the centre of cell ``(i, j)``."""
        return (self.origin[0] + (i + 0.5) * self.resolution, self.origin[1] + (j + 0.5) * self.resolution)

    def inside(self, i: int, j: int) -> bool:
        """Whether cell ``(i, j)`` is part of the grid."""
        return 0 <= i < self.nx and 0 <= j < self.ny

    def same_frame(self, other: LogOddsGrid) -> bool:
        """Whether ``other`` has the same origin, resolution and size (cells line up one to one)."""
        return (
            self.origin == other.origin
            and self.resolution == other.resolution
            and self.logodds.shape == other.logodds.shape
        )

    # ------------------------------------------------------------------ queries
    def occupancy(self) -> np.ndarray:
        """int8 ``(ny, nx)``: -1 unknown, 0 free, 1 occupied (log-odds beyond +-:data:`THRESHOLD`)."""
        out = np.full(self.logodds.shape, UNKNOWN, dtype=np.int8)
        out[self.logodds < -THRESHOLD] = FREE
        out[self.logodds > THRESHOLD] = OCCUPIED
        return out

    def known_fraction(self, x: float, y: float, radius: float) -> float:
        """The fraction of the cells whose centre lies within ``radius`` of ``(x, y)`` that are known."""
        i0, j0 = self.world_to_cell(x - radius, y - radius)
        i1, j1 = self.world_to_cell(x + radius, y + radius)
        i0, j0 = max(0, i0), max(0, j0)
        i1, j1 = min(self.nx - 1, i1), min(self.ny - 1, j1)
        if i1 < i0 or j1 < j0:
            return 0.0
        cx = self.origin[0] + (np.arange(i0, i1 + 1) + 0.5) * self.resolution
        cy = self.origin[1] + (np.arange(j0, j1 + 1) + 0.5) * self.resolution
        disk = (cx[None, :] - x) ** 2 + (cy[:, None] - y) ** 2 <= radius * radius
        if not disk.any():
            return 0.0
        window = np.abs(self.logodds[j0 : j1 + 1, i0 : i1 + 1]) > THRESHOLD
        return float(window[disk].mean())

    def occupied_points(self) -> np.ndarray:
        """World ``(x, y)`` of the centres of the occupied cells, an ``(N, 2)`` array."""
        j, i = np.nonzero(self.logodds > THRESHOLD)
        return np.column_stack(
            [self.origin[0] + (i + 0.5) * self.resolution, self.origin[1] + (j + 0.5) * self.resolution]
        )

    # ---------------------------------------------------------------- mutation
    def update(
        self,
        pose: Sequence[float],
        ranges: np.ndarray | Sequence[float],
        angles: np.ndarray | Sequence[float],
        max_range: float,
    ) -> int:
        """Ray trace one scan taken at ``pose`` into the grid.

        Args:
            pose: ``(x, y, yaw)`` of the scanner (the robot's pose estimate).
            ranges: one range per ray in metres; a range at or beyond ``max_range`` (or not finite)
                is no hit: the ray is free up to ``max_range``.
            angles: the rays' angles relative to the heading (e.g. :func:`alica.worldsim.sensors.lidar_angles`).
            max_range: the longest range traced, in metres (> 0).

        Returns:
            The number of cells updated.

        Raises:
            ValueError: ranges and angles of different lengths, or a non-positive ``max_range``.
        """
        r = np.asarray(ranges, dtype=float).reshape(-1)
        a = np.asarray(angles, dtype=float).reshape(-1)
        if r.shape != a.shape:
            raise ValueError(f"ranges and angles must have the same length, got {len(r)} and {len(a)}")
        max_range = float(max_range)
        if not (max_range > 0.0 and math.isfinite(max_range)):
            raise ValueError(f"max_range must be a positive number of metres, got {max_range}")
        if len(r) == 0:
            return 0
        x, y, yaw = (float(v) for v in pose[:3])
        res = self.resolution
        ox, oy = self.origin
        nx, ny = self.nx, self.ny
        finite = np.isfinite(r)
        hit = finite & (r < max_range)
        reach = np.where(hit, np.maximum(r, 0.0), max_range)
        c, s = np.cos(yaw + a), np.sin(yaw + a)
        step = 0.5 * res
        along = np.arange(0.0, float(reach.max()), step)
        # free cells: samples strictly before the ray's end
        keep = along[None, :] < reach[:, None]
        fi = np.floor((x + c[:, None] * along[None, :] - ox) / res).astype(np.intp)[keep]
        fj = np.floor((y + s[:, None] * along[None, :] - oy) / res).astype(np.intp)[keep]
        ok = (fi >= 0) & (fi < nx) & (fj >= 0) & (fj < ny)
        free = np.zeros(nx * ny, dtype=bool)
        free[fj[ok] * nx + fi[ok]] = True
        hi = np.floor((x + c[hit] * reach[hit] - ox) / res).astype(np.intp)
        hj = np.floor((y + s[hit] * reach[hit] - oy) / res).astype(np.intp)
        ok = (hi >= 0) & (hi < nx) & (hj >= 0) & (hj < ny)
        hit_cells = np.unique(hj[ok] * nx + hi[ok])
        free[hit_cells] = False
        free_cells = np.flatnonzero(free)
        flat = self.logodds.reshape(-1)
        flat[free_cells] += L_MISS
        flat[hit_cells] += L_HIT
        touched = np.concatenate([free_cells, hit_cells])
        flat[touched] = np.clip(flat[touched], L_MIN, L_MAX)
        if len(touched):
            self._dirty[(touched // nx) // TILE, (touched % nx) // TILE] = True
        return len(touched)

    # ------------------------------------------------------------------- tiles
    def take_dirty_tiles(self) -> list[tuple[int, int]]:
        """The tiles ``(tj, ti)`` changed since the last call, in row order; clears the marks."""
        tj, ti = np.nonzero(self._dirty)
        self._dirty[:] = False
        return [(int(a), int(b)) for a, b in zip(tj, ti, strict=True)]

    def tile(self, tj: int, ti: int) -> np.ndarray:
        """A view of the log-odds of tile ``(tj, ti)`` (edge tiles are smaller)."""
        return self.logodds[tj * TILE : (tj + 1) * TILE, ti * TILE : (ti + 1) * TILE]

    def copy(self) -> LogOddsGrid:
        """A deep copy (without the changed-tile marks)."""
        return LogOddsGrid(self.origin, self.resolution, self.nx, self.ny, self.logodds.copy())

    def __repr__(self) -> str:
        occ = self.occupancy()
        return (
            f"LogOddsGrid(origin={self.origin}, resolution={self.resolution}, {self.nx} x {self.ny}, "
            f"known={int((occ >= 0).sum())}, occupied={int((occ == 1).sum())})"
        )
