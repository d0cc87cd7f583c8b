"""2-D occupancy grids and the 2-D obstacle shapes they are rasterised from.

Pure numpy. Conventions:

* A grid has ``width`` columns and ``height`` rows of square cells of side
  ``resolution`` metres; ``origin`` is the world position of the lower-left
  corner of cell ``(0, 0)``. Cell ``(i, j)`` (``i`` column, ``j`` row) covers
  ``[ox + i*res, ox + (i+1)*res) x [oy + j*res, oy + (j+1)*res)``.
* ``cells[j, i]`` holds :data:`FREE` (0), :data:`OCCUPIED` (1) or
  :data:`UNKNOWN` (255).
* Anything outside the grid counts as occupied.

Example:
    >>> grid = OccupancyGrid.from_obstacles([Obstacle2D("circle", 1.0, 1.0, radius=0.5)],
    ...                                     bounds=(0.0, 0.0, 4.0, 4.0), resolution=0.1)
    >>> grid.occupied(1.0, 1.0), grid.occupied(3.0, 3.0), grid.occupied(-1.0, 0.0)
    (True, False, True)
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "Obstacle2D", "OccupancyGrid"]

FREE: int = 0
OCCUPIED: int = 1
UNKNOWN: int = 255
_VALUES = (FREE, OCCUPIED, UNKNOWN)


@dataclass(frozen=True, slots=True)
class Obstacle2D:
    """A 2-D obstacle footprint in world coordinates.

    Attributes:
        kind: ``"circle"`` (uses ``radius``) or ``"box"`` (uses ``half_x``, ``half_y``, ``yaw``).
        x: Centre x in metres.
        y: Centre y in metres.
        radius: Circle radius in metres.
        half_x: Box half extent along its own x axis.
        half_y: Box half extent along its own y axis.
        yaw: Box rotation in radians (counter-clockwise).
        name: Optional label (e.g. the world object's name).
    """

    kind: str
    x: float
    y: float
    radius: float = 0.0
    half_x: float = 0.0
    half_y: float = 0.0
    yaw: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("circle", "box"):
            raise ValueError(f"Obstacle2D kind must be 'circle' or 'box', got {self.kind!r}")
        if self.kind == "circle" and not self.radius > 0.0:
            raise ValueError(f"circle obstacle {self.name!r} needs radius > 0, got {self.radius}")
        if self.kind == "box" and not (self.half_x > 0.0 and self.half_y > 0.0):
            raise ValueError(
                f"box obstacle {self.name!r} needs half_x > 0 and half_y > 0, got {self.half_x}, {self.half_y}"
            )

    def bounding_radius(self) -> float:
        """Radius of a circle about (x, y) that contains the footprint."""
        return self.radius if self.kind == "circle" else math.hypot(self.half_x, self.half_y)

    def distance(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Euclidean distance from points to the footprint (0 inside), vectorised."""
        dx = np.asarray(px, dtype=float) - self.x
        dy = np.asarray(py, dtype=float) - self.y
        if self.kind == "circle":
            return np.maximum(np.hypot(dx, dy) - self.radius, 0.0)
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        u = np.maximum(np.abs(c * dx + s * dy) - self.half_x, 0.0)
        v = np.maximum(np.abs(-s * dx + c * dy) - self.half_y, 0.0)
        return np.hypot(u, v)


class OccupancyGrid:
    """A 2-D occupancy grid (see the module docstring for the conventions).

    Args:
        origin: World (x, y) of the lower-left corner of cell (0, 0).
        resolution: Cell side in metres (> 0).
        width: Number of columns (> 0).
        height: Number of rows (> 0).
        cells: Optional uint8 array of shape (height, width); all free when omitted.
            The array is used as is (not copied).

    Raises:
        ValueError: On a non-positive resolution or size, or cells of the wrong shape or values.
    """

    __slots__ = ("cells", "height", "origin", "resolution", "width")

    def __init__(
        self,
        origin: tuple[float, float],
        resolution: float,
        width: int,
        height: int,
        cells: np.ndarray | None = None,
    ) -> None:
        if not resolution > 0.0:
            raise ValueError(f"resolution must be > 0 metres, got {resolution}")
        if int(width) <= 0 or int(height) <= 0:
            raise ValueError(f"width and height must be positive cell counts, got {width} x {height}")
        self.origin: tuple[float, float] = (float(origin[0]), float(origin[1]))
        self.resolution: float = float(resolution)
        self.width: int = int(width)
        self.height: int = int(height)
        if cells is None:
            cells = np.zeros((self.height, self.width), dtype=np.uint8)
        else:
            cells = np.asarray(cells)
            if cells.shape != (self.height, self.width):
                raise ValueError(
                    f"cells must have shape (height, width) = {(self.height, self.width)}, got {cells.shape}"
                )
            if cells.dtype != np.uint8:
                cells = cells.astype(np.uint8)
        self.cells: np.ndarray = cells

    # ----------------------------------------------------------------- geometry
    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """World extent ``(xmin, ymin, xmax, ymax)`` of the grid."""
        ox, oy = self.origin
        return (ox, oy, ox + self.width * self.resolution, oy + self.height * self.resolution)

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """Cell ``(i, j)`` containing the world point (may lie outside the grid; see :meth:`inside`)."""
        return (
            math.floor((x - self.origin[0]) / self.resolution),
            math.floor((y - self.origin[1]) / self.resolution),
        )

    def world_to_cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Vectorised :meth:`world_to_cell` for an (N, 2) array: integer arrays ``(i, j)``."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        i = np.floor((xy[:, 0] - self.origin[0]) / self.resolution).astype(np.intp)
        j = np.floor((xy[:, 1] - self.origin[1]) / self.resolution).astype(np.intp)
        return i, j

    def cell_to_world(self, i: int, j: int) -> tuple[float, float]:
        """World position of the centre of cell ``(i, j)``."""
        return (self.origin[0] + (i + 0.5) * self.resolution, self.origin[1] + (j + 0.5) * self.resolution)

    def cell_inside(self, i: int, j: int) -> bool:
        """Whether cell ``(i, j)`` is part of the grid."""
        return 0 <= i < self.width and 0 <= j < self.height

    def inside(self, x: float, y: float) -> bool:
        """Whether the world point lies on the grid."""
        return self.cell_inside(*self.world_to_cell(x, y))

    # ------------------------------------------------------------------ queries
    def value(self, x: float, y: float) -> int:
        """Cell value at the world point; :data:`OCCUPIED` outside the grid."""
        i, j = self.world_to_cell(x, y)
        if not self.cell_inside(i, j):
            return OCCUPIED
        return int(self.cells[j, i])

    def occupied(self, x: float, y: float, *, unknown_is_occupied: bool = False) -> bool:
        """Whether the world point is occupied (outside the grid counts as occupied).

        Args:
            x: World x.
            y: World y.
            unknown_is_occupied: Also count :data:`UNKNOWN` cells as occupied.
        """
        v = self.value(x, y)
        return v == OCCUPIED or (unknown_is_occupied and v == UNKNOWN)

    def occupied_mask(self, *, unknown_is_occupied: bool = False) -> np.ndarray:
        """Boolean (height, width) array of the occupied cells."""
        if unknown_is_occupied:
            return self.cells != FREE
        return self.cells == OCCUPIED

    # ---------------------------------------------------------------- mutation
    def mark(self, points_xy: np.ndarray, value: int = OCCUPIED) -> int:
        """Set the cells containing the given world points to ``value``; points off the grid are ignored.

        Args:
            points_xy: (N, 2) array of world points.
            value: :data:`FREE`, :data:`OCCUPIED` or :data:`UNKNOWN`.

        Returns:
            The number of points that fell on the grid.

        Raises:
            ValueError: If ``value`` is not one of the three cell values.
        """
        if value not in _VALUES:
            raise ValueError(f"value must be FREE (0), OCCUPIED (1) or UNKNOWN (255), got {value}")
        i, j = self.world_to_cells(points_xy)
        ok = (i >= 0) & (i < self.width) & (j >= 0) & (j < self.height)
        self.cells[j[ok], i[ok]] = value
        return int(ok.sum())

    def add_obstacles(self, obstacles: Iterable[Obstacle2D], *, conservative: bool = True) -> None:
        """Mark the cells covered by the obstacles as occupied (in place).

        Args:
            obstacles: Footprints to rasterise.
            conservative: When true, mark every cell the footprint may touch (cells whose centre
                lies within half a cell diagonal of the shape), so that every point of an obstacle
                lies in an occupied cell. When false, mark the cells whose centre is inside.
        """
        grow = 0.5 * math.sqrt(2.0) * self.resolution if conservative else 0.0
        res = self.resolution
        ox, oy = self.origin
        for ob in obstacles:
            reach = ob.bounding_radius() + grow
            i0 = max(0, math.floor((ob.x - reach - ox) / res))
            i1 = min(self.width, math.floor((ob.x + reach - ox) / res) + 1)
            j0 = max(0, math.floor((ob.y - reach - oy) / res))
            j1 = min(self.height, math.floor((ob.y + reach - oy) / res) + 1)
            if i0 >= i1 or j0 >= j1:
                continue
            cx = ox + (np.arange(i0, i1) + 0.5) * res
            cy = oy + (np.arange(j0, j1) + 0.5) * res
            inside = ob.distance(cx[None, :], cy[:, None]) <= grow + 1e-12
            window = self.cells[j0:j1, i0:i1]
            window[inside] = OCCUPIED

    # -------------------------------------------------------------- derivation
    def inflate(self, radius: float) -> OccupancyGrid:
        """A new grid whose occupied cells are grown by ``radius`` with a disk kernel.

        A cell becomes occupied when its centre lies within ``radius`` of the centre of an
        occupied cell (exact Euclidean, computed separably with numpy). Unknown cells stay
        unknown unless inflation makes them occupied; free cells next to unknown stay free.

        Args:
            radius: Growth in metres (>= 0).

        Raises:
            ValueError: On a negative radius.
        """
        if radius < 0.0 or not math.isfinite(radius):
            raise ValueError(f"inflation radius must be a finite value >= 0 metres, got {radius}")
        occ = self.cells == OCCUPIED
        out = self.cells.copy()
        k = math.floor(radius / self.resolution + 1e-9)
        if k == 0 or not occ.any():
            return OccupancyGrid(self.origin, self.resolution, self.width, self.height, out)
        r2 = (radius / self.resolution) ** 2 + 1e-9
        # Pass 1: per row, horizontal distance (in cells) to the nearest occupied cell.
        big = float(self.width + k + 1)
        idx = np.arange(self.width, dtype=np.float32)[None, :]
        left = np.where(occ, idx, np.float32(-big))
        np.maximum.accumulate(left, axis=1, out=left)
        right = np.where(occ, idx, np.float32(2.0 * big))
        right = np.minimum.accumulate(right[:, ::-1], axis=1)[:, ::-1]
        dx = np.minimum(idx - left, right - idx)
        dx2 = np.minimum(dx, np.float32(k + 1.0)) ** 2
        # Pass 2: min over vertical offsets within k of dx^2 + dy^2.
        best = dx2.copy()
        for dy in range(1, k + 1):
            add = float(dy * dy)
            if add > r2:
                break
            np.minimum(best[dy:], dx2[:-dy] + np.float32(add), out=best[dy:])
            np.minimum(best[:-dy], dx2[dy:] + np.float32(add), out=best[:-dy])
        out[best <= r2] = OCCUPIED
        return OccupancyGrid(self.origin, self.resolution, self.width, self.height, out)

    def copy(self) -> OccupancyGrid:
        """A deep copy (the cells array is copied)."""
        return OccupancyGrid(self.origin, self.resolution, self.width, self.height, self.cells.copy())

    @classmethod
    def from_obstacles(
        cls,
        obstacles: Iterable[Obstacle2D],
        bounds: tuple[float, float, float, float],
        resolution: float = 0.05,
        *,
        conservative: bool = True,
    ) -> OccupancyGrid:
        """Rasterise obstacle footprints into a new grid covering ``bounds``.

        Args:
            obstacles: Circles and (rotated) boxes.
            bounds: ``(xmin, ymin, xmax, ymax)`` in metres; the grid covers at least this area.
            resolution: Cell side in metres.
            conservative: See :meth:`add_obstacles` (default: mark every cell a shape may touch).

        Raises:
            ValueError: On empty bounds or a non-positive resolution.
        """
        xmin, ymin, xmax, ymax = (float(b) for b in bounds)
        if not (xmax > xmin and ymax > ymin):
            raise ValueError(f"bounds must be (xmin, ymin, xmax, ymax) with xmax > xmin and ymax > ymin, got {bounds}")
        if not resolution > 0.0:
            raise ValueError(f"resolution must be > 0 metres, got {resolution}")
        width = max(1, math.ceil((xmax - xmin) / resolution - 1e-9))
        height = max(1, math.ceil((ymax - ymin) / resolution - 1e-9))
        grid = cls((xmin, ymin), resolution, width, height)
        grid.add_obstacles(obstacles, conservative=conservative)
        return grid

    def __repr__(self) -> str:
        occ = int((self.cells == OCCUPIED).sum())
        return (
            f"OccupancyGrid(origin={self.origin}, resolution={self.resolution}, "
            f"width={self.width}, height={self.height}, occupied={occ})"
        )
