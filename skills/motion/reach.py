"""A cheap, sound "is the goal unreachable?" test on a blocked-cell mask (pure numpy).

The mask is reduced to at most ``max_cells`` cells a side; a coarse cell is free when
*any* of its fine cells is free. Every path of free fine cells (8-connected) maps to a path
of free coarse cells, so "no coarse path" proves "no fine path": the test never calls a
reachable goal unreachable. It may call an unreachable goal reachable (a wall thinner than
a coarse cell); the planner then simply fails to find a path in time.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["coarse_reachable"]


def _coarse_free(blocked: np.ndarray, factor: int) -> np.ndarray:
    h, w = blocked.shape
    hh, ww = math.ceil(h / factor), math.ceil(w / factor)
    padded = np.ones((hh * factor, ww * factor), dtype=bool)
    padded[:h, :w] = blocked
    # ``all`` over some axes is typed as possibly a scalar; over two of four axes it is a 2-d array
    coarse_blocked: npt.NDArray[np.bool_] = np.asarray(padded.reshape(hh, factor, ww, factor).all(axis=(1, 3)))
    return ~coarse_blocked


def coarse_reachable(
    blocked: np.ndarray,
    start_ij: tuple[int, int],
    goal_ij: tuple[int, int],
    *,
    max_cells: int = 256,
) -> bool:
    """Whether the goal cell may be reachable from the start cell through unblocked cells.

    Args:
        blocked: Boolean (height, width) array, True where the robot may not be.
        start_ij: Start cell (column, row).
        goal_ij: Goal cell (column, row).
        max_cells: Largest side of the coarse grid the flood fill runs on.

    Returns:
        False only when the goal is certainly unreachable (8-connected flood fill).
    """
    h, w = blocked.shape
    factor = max(1, math.ceil(max(h, w) / max_cells))
    free = _coarse_free(blocked, factor)
    si, sj = start_ij[0] // factor, start_ij[1] // factor
    gi, gj = goal_ij[0] // factor, goal_ij[1] // factor
    if not (free[sj, si] and free[gj, gi]):
        return False
    reached = np.zeros_like(free)
    reached[sj, si] = True
    grown = np.empty_like(free)
    count = 1
    iteration = 0
    while True:
        iteration += 1
        np.copyto(grown, reached)
        grown[1:] |= reached[:-1]
        grown[:-1] |= reached[1:]
        rows = grown.copy()
        grown[:, 1:] |= rows[:, :-1]
        grown[:, :-1] |= rows[:, 1:]
        grown &= free
        if grown[gj, gi]:
            return True
        reached, grown = grown, reached
        if iteration % 8 == 0:
            new_count = int(np.count_nonzero(reached))
            if new_count == count:
                return False
            count = new_count
