"""The 2-D simulation of ``bench/exploration.py``: the field, the lidar and the path planner.

No pybullet stepping: the rocks of ``alica.worldsim.scenarios.lunar`` (ground
truth, used only to simulate the sensor, to score and to count contacts) are
rasterised at the map's resolution; robots are points with a radius that move
along planned paths.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from alica.skills.exploration import FREE, OCCUPIED

#: Robot radius (m): the planner keeps the robot's centre this far from known occupied cells.
RADIUS = 0.3
#: Wanted cell size (m) of the planner's coarse grid (a whole number of map cells).
PLAN_RES = 0.25


@dataclass
class Field:
    """One lunar field at the map's resolution."""

    truth: np.ndarray  # occupied [row, col]
    free: np.ndarray
    origin: tuple[float, float]
    resolution: float
    starts: dict[str, tuple[float, float]]
    clearance: np.ndarray  # metres from each cell's centre to the nearest truly occupied cell's centre

    def contact(self, xy: tuple[float, float]) -> bool:
        """Whether a robot at ``xy`` overlaps a rock (its centre within the radius less one cell)."""
        c = int((xy[0] - self.origin[0]) / self.resolution)
        r = int((xy[1] - self.origin[1]) / self.resolution)
        h, w = self.truth.shape
        if not (0 <= r < h and 0 <= c < w):
            return True
        return bool(self.clearance[r, c] < RADIUS - self.resolution)


def make_field(seed: int, resolution: float, rocks: int = 60, size: float = 40.0) -> Field:
    """``lunar(seed, rocks, size)`` rasterised; the robots start where the scenario puts them."""
    from alica.worldsim.grid import OccupancyGrid
    from alica.worldsim.scenarios import lunar

    world = lunar(seed, rocks=rocks, samples=0, size=size)
    try:
        grid = OccupancyGrid.from_obstacles(world.ground_truth_obstacles(), world.bounds, resolution)
        starts = {n: (float(r.pose[0]), float(r.pose[1])) for n, r in world.robots.items()}
    finally:
        world.close()
    truth = grid.cells == OCCUPIED
    clearance = ndimage.distance_transform_edt(~truth) * resolution
    return Field(truth, ~truth, (float(grid.origin[0]), float(grid.origin[1])), resolution, starts, clearance)


def sense(fld: Field, occ: np.ndarray, xy: tuple[float, float], reach: float) -> None:
    """One 180-ray scan at ``xy`` into ``occ``: cells up to the first hit free, the hit occupied."""
    res = fld.resolution
    angles = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    steps = np.arange(0.0, reach, 0.5 * res)
    px = xy[0] + np.cos(angles)[:, None] * steps[None, :]
    py = xy[1] + np.sin(angles)[:, None] * steps[None, :]
    cols = np.floor((px - fld.origin[0]) / res).astype(int)
    rows = np.floor((py - fld.origin[1]) / res).astype(int)
    h, w = occ.shape
    inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
    rc, cc = np.clip(rows, 0, h - 1), np.clip(cols, 0, w - 1)
    blocked = fld.truth[rc, cc] | ~inside
    first = np.where(blocked.any(axis=1), blocked.argmax(axis=1), len(steps))
    before = np.arange(len(steps))[None, :] < first[:, None]
    occ[rc[before], cc[before]] = FREE
    hit = first < len(steps)
    hr, hc = rc[hit, first[hit]], cc[hit, first[hit]]
    ok = inside[hit, first[hit]]
    occ[hr[ok], hc[ok]] = OCCUPIED


class Planner:
    """Shortest paths on a coarse grid of the known map (unknown passable).

    A coarse cell is ``factor`` map cells wide (``step`` metres); it is
    blocked when one of its map cells has its centre within :data:`RADIUS` of
    a known occupied cell's centre. :meth:`update` recomputes the blocked
    cells (cheap; call it whenever the map changed), the graph is rebuilt
    only when a path is planned on a changed map.
    """

    def __init__(self, fld: Field) -> None:
        self.fld = fld
        self.factor = max(1, round(PLAN_RES / fld.resolution))
        self.step = self.factor * fld.resolution
        h, w = fld.truth.shape
        self.shape = (h // self.factor, w // self.factor)
        hh, ww = self.shape
        idx = np.arange(hh * ww).reshape(hh, ww)
        src, dst, cost = [], [], []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            # pairs (r, c) -> (r + dr, c + dc) inside the grid
            a = idx[: hh - dr, max(0, -dc) : ww - max(0, dc)]
            b = idx[dr:, max(0, dc) : ww + min(0, dc)]
            src.append(a.ravel())
            dst.append(b.ravel())
            cost.append(np.full(a.size, math.hypot(dr, dc) * self.step))
        self.src, self.dst, self.cost = np.concatenate(src), np.concatenate(dst), np.concatenate(cost)
        k = math.floor(RADIUS / fld.resolution)
        yy, xx = np.mgrid[-k : k + 1, -k : k + 1]
        self.disc = (yy**2 + xx**2) * fld.resolution**2 < RADIUS**2
        self.blocked = np.zeros(self.shape, dtype=bool)
        self.graph: csr_matrix | None = None

    def update(self, occ: np.ndarray) -> None:
        """The blocked coarse cells of the known map ``occ``."""
        f = self.factor
        hh, ww = self.shape
        near = ndimage.binary_dilation(occ == OCCUPIED, structure=self.disc)
        self.blocked = near[: hh * f, : ww * f].reshape(hh, f, ww, f).any(axis=(1, 3))
        self.graph = None

    def _graph(self) -> csr_matrix:
        if self.graph is None:
            ok = ~self.blocked.ravel()
            keep = ok[self.src] & ok[self.dst]
            n = self.shape[0] * self.shape[1]
            self.graph = csr_matrix((self.cost[keep], (self.src[keep], self.dst[keep])), shape=(n, n))
        return self.graph

    def rc(self, xy: tuple[float, float]) -> tuple[int, int]:
        """The coarse (row, col) of a point (clamped to the grid)."""
        c = int((xy[0] - self.fld.origin[0]) / self.step)
        r = int((xy[1] - self.fld.origin[1]) / self.step)
        return min(max(r, 0), self.shape[0] - 1), min(max(c, 0), self.shape[1] - 1)

    def cell(self, xy: tuple[float, float]) -> int:
        """The coarse cell's index."""
        r, c = self.rc(xy)
        return r * self.shape[1] + c

    def centre(self, k: int) -> tuple[float, float]:
        """World x, y of a coarse cell's centre."""
        r, c = divmod(k, self.shape[1])
        return (self.fld.origin[0] + (c + 0.5) * self.step, self.fld.origin[1] + (r + 0.5) * self.step)

    def is_blocked(self, xy: tuple[float, float]) -> bool:
        """Whether the coarse cell of ``xy`` is blocked."""
        return bool(self.blocked[self.rc(xy)])

    def tree(self, xy: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        """Path lengths and predecessors from ``xy`` (from the nearest open cell when the robot is inside an inflation)."""
        start = self.cell(xy)
        r0, c0 = divmod(start, self.shape[1])
        if self.blocked[r0, c0]:
            lo_r, lo_c = max(0, r0 - 4), max(0, c0 - 4)
            rows, cols = np.nonzero(~self.blocked[lo_r : r0 + 5, lo_c : c0 + 5])
            if len(rows):
                k = int(np.argmin((rows + lo_r - r0) ** 2 + (cols + lo_c - c0) ** 2))
                start = (rows[k] + lo_r) * self.shape[1] + cols[k] + lo_c
        dist, pred = dijkstra(self._graph(), directed=False, indices=int(start), return_predecessors=True)
        return dist, pred

    def nearest_open(self, xy: tuple[float, float], dist: np.ndarray) -> int | None:
        """The reachable coarse cell nearest to ``xy`` within 3 cells (a frontier cell may sit in the inflation)."""
        r0, c0 = self.rc(xy)
        best: tuple[float, int] | None = None
        for dr in range(-3, 4):
            for dc in range(-3, 4):
                r, c = r0 + dr, c0 + dc
                if 0 <= r < self.shape[0] and 0 <= c < self.shape[1]:
                    k = r * self.shape[1] + c
                    if math.isfinite(dist[k]) and (best is None or math.hypot(dr, dc) < best[0]):
                        best = (math.hypot(dr, dc), k)
        return None if best is None else best[1]

    def path(self, pred: np.ndarray, goal: int) -> list[tuple[float, float]]:
        """The cell centres from the tree's root to ``goal``."""
        out = []
        k = goal
        while k >= 0:
            out.append(self.centre(k))
            k = int(pred[k])
        return out[::-1]
