"""Frontier cells and their information gain (IMPERA Section 6.4.1, Algorithm 1).

Pure numpy/scipy on an occupancy array ``occ[row, col]`` of int8:
:data:`UNKNOWN` (-1), :data:`FREE` (0), :data:`OCCUPIED` (1); row ``j``,
column ``i`` covers ``[ox + i*res, ox + (i+1)*res) x [oy + j*res, oy + (j+1)*res)``
with ``origin = (ox, oy)`` the world position of cell ``(0, 0)``'s lower-left corner.

* :func:`frontier_mask`: free cells with an unknown 8-neighbour (Yamauchi 1997).
* :func:`information_gain`: Algorithm 1. For each frontier cell still in the
  list, a wave front starts in its unknown neighbours and travels across
  unknown cells up to ``reach`` cells (8-connected steps); the information
  gain is the number of travelled cells ``|A|``, the boundary relation whether
  any travelled cell lies next to the map's edge; every frontier cell the wave
  front touched gets the same result and leaves the list.
* :func:`extract_frontiers`: frontier cells grouped into candidates (8-connected
  groups, cut into chunks of at most ``chunk`` metres), each with a position on
  a frontier cell, its gain in square metres and a stable name derived from
  its place (``f_<col>_<row>`` of the chunk), sorted by gain, then boundary
  relation.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "FrontierCandidate",
    "GainMap",
    "coverage",
    "extract_frontiers",
    "frontier_mask",
    "information_gain",
]

UNKNOWN: int = -1
FREE: int = 0
OCCUPIED: int = 1

_EIGHT = np.ones((3, 3), dtype=bool)


def _check(occ: np.ndarray) -> np.ndarray:
    grid = np.asarray(occ)
    if grid.ndim != 2:
        raise ValueError(f"an occupancy grid is a 2-D array, got shape {grid.shape}")
    return grid


def frontier_mask(occ: np.ndarray) -> np.ndarray:
    """Free cells with at least one unknown cell among their 8 neighbours (cells outside the grid are not unknown)."""
    grid = _check(occ)
    unknown = grid == UNKNOWN
    # the 8-neighbourhood dilation of the unknown cells, as shifted copies (cheaper than ndimage on a large map)
    rows = unknown.copy()
    rows[1:] |= unknown[:-1]
    rows[:-1] |= unknown[1:]
    near_unknown = rows.copy()
    near_unknown[:, 1:] |= rows[:, :-1]
    near_unknown[:, :-1] |= rows[:, 1:]
    return (grid == FREE) & near_unknown


@dataclass(frozen=True, slots=True)
class GainMap:
    """The result of Algorithm 1 for every frontier cell.

    Attributes:
        gain: cells ``[row, col]``: the information gain ``|A|`` in cells of the
            frontier cell's propagation (0 off the frontier).
        boundary: cells: the boundary relation (a travelled cell next to the map's edge).
        propagations: how many wave fronts were started (the others were observed).
    """

    gain: np.ndarray
    boundary: np.ndarray
    propagations: int


#: Propagations remembered by :func:`_propagate` (a map changes in a few places between two readings;
#: a reading of a 40 m field starts about 100; more memory finds no more).
_CACHE_SIZE = 1024
_PROPAGATIONS: OrderedDict[tuple[object, ...], tuple[int, bool, np.ndarray]] = OrderedDict()


def _propagate(
    win_unknown: np.ndarray, lr: int, lc: int, reach: int, edges: tuple[bool, bool, bool, bool]
) -> tuple[int, bool, np.ndarray]:
    """One wave front of Algorithm 1 in a window around its frontier cell ``(lr, lc)``.

    Returns ``|A|``, the boundary relation and the cells next to the travelled
    ones (the window's cells the wave front touched, before intersecting with
    the frontier list). Depends on the window's unknown cells only, so the
    results of the last propagations are remembered by the window's contents
    (a reading of a map that changed in a few places repeats most of them).
    """
    key = (lr, lc, reach, edges, win_unknown.shape, np.packbits(win_unknown).tobytes())
    known = _PROPAGATIONS.get(key)
    if known is not None:
        _PROPAGATIONS.move_to_end(key)
        return known
    seed = np.zeros(win_unknown.shape, dtype=bool)
    # line 2: the unknown neighbours of f start the wave front
    seed[max(0, lr - 1) : lr + 2, max(0, lc - 1) : lc + 2] = True
    seed &= win_unknown
    if not seed.any():
        result = (0, False, np.zeros(win_unknown.shape, dtype=bool))
    else:
        # lines 3-6: the wave front travels across unknown cells, reach steps from f
        travelled = seed
        if reach > 1:  # (iterations=0 would mean: until nothing changes)
            travelled = ndimage.binary_dilation(seed, structure=_EIGHT, iterations=reach - 1, mask=win_unknown) | seed
        size = int(travelled.sum())  # line 7: InfoGain_f = |A|
        # line 6: cells next to the map boundary (edges: the window touches the map's top, bottom, left, right)
        top, bottom, left, right = edges
        at_edge = bool(
            (top and travelled[0].any())
            or (bottom and travelled[-1].any())
            or (left and travelled[:, 0].any())
            or (right and travelled[:, -1].any())
        )
        result = (size, at_edge, ndimage.binary_dilation(travelled, structure=_EIGHT))
    result[2].flags.writeable = False
    _PROPAGATIONS[key] = result
    if len(_PROPAGATIONS) > _CACHE_SIZE:
        _PROPAGATIONS.popitem(last=False)
    return result


def information_gain(
    occ: np.ndarray, reach: int, frontier: np.ndarray | None = None, order: Sequence[tuple[int, int]] | None = None
) -> GainMap:
    """IMPERA Algorithm 1: information gain and boundary relation of every frontier cell.

    Args:
        occ: the occupancy array.
        reach: how far (in 8-connected cell steps) a wave front travels into unknown cells, >= 1.
        frontier: the frontier mask (:func:`frontier_mask` of ``occ`` by default).
        order: the order in which frontier cells start propagations (row-major by default).

    Raises:
        ValueError: ``reach`` < 1, or ``frontier`` has another shape.
    """
    grid = _check(occ)
    if int(reach) < 1:
        raise ValueError(f"reach must be at least 1 cell, got {reach}")
    reach = int(reach)
    mask = frontier_mask(grid) if frontier is None else np.asarray(frontier, dtype=bool)
    if mask.shape != grid.shape:
        raise ValueError(f"frontier mask of shape {mask.shape} for a grid of shape {grid.shape}")
    unknown = grid == UNKNOWN
    rows, cols = grid.shape
    gain = np.zeros(grid.shape, dtype=np.int64)
    boundary = np.zeros(grid.shape, dtype=bool)
    todo = mask.copy()  # the frontier cell list f_cells
    if order is None:
        found = np.nonzero(mask)
        cells: list[tuple[int, int]] = list(zip(found[0].tolist(), found[1].tolist(), strict=True))
    else:
        cells = [(int(r), int(c)) for r, c in order]
    started = 0
    for r, c in cells:
        if not todo[r, c]:
            continue  # observed by an earlier propagation (line 16)
        # a window that holds every cell the wave front can reach (and their neighbours)
        r0, r1 = max(0, r - reach - 2), min(rows, r + reach + 3)
        c0, c1 = max(0, c - reach - 2), min(cols, c + reach + 3)
        started += 1
        size, at_edge, near = _propagate(
            unknown[r0:r1, c0:c1], r - r0, c - c0, reach, (r0 == 0, r1 == rows, c0 == 0, c1 == cols)
        )
        # line 5: the frontier cells the wave front touched; f itself among them
        touched = near & todo[r0:r1, c0:c1]
        touched[r - r0, c - c0] = True
        tr, tc = np.nonzero(touched)
        tr += r0
        tc += c0
        # lines 13-16: store the result for the observed cells and remove them from the list
        gain[tr, tc] = size
        boundary[tr, tc] = at_edge
        todo[tr, tc] = False
    return GainMap(gain, boundary, started)


@dataclass(frozen=True, slots=True)
class FrontierCandidate:
    """One frontier to drive to.

    Attributes:
        name: a name derived from its place: ``f_<i>_<j>``, the chunk's column and row.
        position: ``(x, y)`` of its frontier cell nearest to the chunk's centroid (world metres).
        cell: that cell as ``(row, col)``.
        size: frontier cells in the chunk.
        gain: information gain in square metres (the largest of its cells').
        boundary: the boundary relation of that cell.
    """

    name: str
    position: tuple[float, float]
    cell: tuple[int, int]
    size: int
    gain: float
    boundary: bool


def _clear(occupied: np.ndarray, rows: np.ndarray, cols: np.ndarray, resolution: float, clearance: float) -> np.ndarray:
    """Which cells ``(rows, cols)`` lie at least ``clearance`` metres (centre to centre) from every occupied cell.

    The same test as ``distance_transform_edt(~occupied) * resolution >= clearance``,
    made only at the given cells: an occupied cell at offset ``(dr, dc)`` is too
    close when ``sqrt(dr² + dc²) * resolution < clearance``.
    """
    keep = np.ones(len(rows), dtype=bool)
    if len(rows) == 0 or not occupied.any():
        return keep
    n = math.ceil(clearance / resolution) + 1
    dr, dc = np.mgrid[-n : n + 1, -n : n + 1]
    close = np.sqrt((dr * dr + dc * dc).astype(float)) * resolution < clearance
    # occupied cells per row up to each column (a leading 0): a run of columns is counted in two look-ups
    counts = np.zeros((occupied.shape[0] + 2 * n, occupied.shape[1] + 2 * n + 1), dtype=np.int32)
    np.cumsum(np.pad(occupied, n), axis=1, out=counts[:, 1:])
    for i in range(2 * n + 1):
        reach = np.flatnonzero(close[i])
        if len(reach) == 0:
            continue
        lo, hi = int(dc[i, reach[0]]), int(dc[i, reach[-1]])  # the close columns of this row: one run
        at = rows + n + int(dr[i, 0])
        keep &= counts[at, cols + n + hi + 1] == counts[at, cols + n + lo]
    return keep


def extract_frontiers(
    occ: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    *,
    reach: float = 3.0,
    chunk: float = 2.0,
    min_size: int = 3,
    min_gain: float = 0.0,
    clearance: float = 0.0,
) -> list[FrontierCandidate]:
    """The frontier candidates of an occupancy array, best first (gain, then boundary relation, then name).

    Args:
        occ: the occupancy array.
        resolution: cell size in metres.
        origin: world ``(x, y)`` of cell ``(0, 0)``'s lower-left corner.
        reach: wave-front range of Algorithm 1 in metres.
        chunk: candidates are 8-connected groups of frontier cells cut at a grid of this many metres.
        min_size: smaller chunks are dropped (specks of noise).
        min_gain: candidates with at most this gain (m²) are dropped.
        clearance: frontier cells closer than this many metres to an occupied cell make no candidate
            (a robot cannot stand there; the unseen inside of a rock borders such cells). Algorithm 1 still
            counts them.

    Raises:
        ValueError: a non-positive resolution, reach or chunk.
    """
    grid = _check(occ)
    if not resolution > 0.0 or not reach > 0.0 or not chunk > 0.0:
        raise ValueError(f"resolution, reach and chunk must be > 0, got {resolution}, {reach}, {chunk}")
    mask = frontier_mask(grid)
    if not mask.any():
        return []
    result = information_gain(grid, max(1, round(reach / resolution)), mask)
    labels, _count = ndimage.label(mask, structure=_EIGHT)
    rows, cols = np.nonzero(mask)
    if clearance > 0.0:
        keep = _clear(grid == OCCUPIED, rows, cols, resolution, clearance)
        rows, cols = rows[keep], cols[keep]
    if len(rows) == 0:
        return []
    ox, oy = float(origin[0]), float(origin[1])
    xs = ox + (cols + 0.5) * resolution
    ys = oy + (rows + 0.5) * resolution
    bi = np.floor((xs - ox) / chunk).astype(np.int64)
    bj = np.floor((ys - oy) / chunk).astype(np.int64)
    group = labels[rows, cols]
    # one candidate per (chunk, group); the name is the chunk's (a group split by a chunk line gives two)
    keys = np.stack([bi, bj, group], axis=1)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    out: dict[str, FrontierCandidate] = {}
    cell_gain = result.gain[rows, cols]
    # the cells of each key, in cell order (a stable sort by key)
    by_key = np.argsort(inverse, kind="stable")
    ends = np.cumsum(np.bincount(inverse, minlength=len(uniq)))
    for k in range(len(uniq)):
        members = by_key[ends[k - 1] if k else 0 : ends[k]]
        if len(members) < min_size:
            continue
        cx, cy = xs[members].mean(), ys[members].mean()
        pick = members[int(np.argmin((xs[members] - cx) ** 2 + (ys[members] - cy) ** 2))]
        best = members[int(np.argmax(cell_gain[members]))]
        gain = float(cell_gain[best]) * resolution * resolution
        if gain <= min_gain:
            continue
        name = f"f_{int(uniq[k][0])}_{int(uniq[k][1])}"
        cand = FrontierCandidate(
            name,
            (float(xs[pick]), float(ys[pick])),
            (int(rows[pick]), int(cols[pick])),
            len(members),
            round(gain, 4),
            bool(result.boundary[rows[best], cols[best]]),
        )
        # two groups in one chunk: keep the better one under the chunk's name
        old = out.get(name)
        if old is None or (cand.gain, cand.size) > (old.gain, old.size):
            out[name] = cand
    return sorted(out.values(), key=lambda f: (-f.gain, not f.boundary, f.name))


def coverage(occ: np.ndarray, truth_free: np.ndarray | None = None) -> float:
    """The fraction of known cells, or with ``truth_free`` (a mask) of the truly free cells that are known."""
    grid = _check(occ)
    known = grid != UNKNOWN
    if truth_free is None:
        return float(known.mean()) if known.size else 1.0
    free = np.asarray(truth_free, dtype=bool)
    total = int(free.sum())
    return float((known & free).sum() / total) if total else 1.0
