"""The search's cheap bound: an upper bound on a node's completions in O(entry points).

With prices ``lambda_j`` per column (any prices give a valid bound; the
optimal duals of :mod:`alica.allocation.flow` make it exact at the root and
along optimal assignments), reduced values ``r(a, j) = c(a, j) - lambda_j``
and, for the unassigned agents ``s..n-1`` of a node,

    bound = value of the assigned agents
          + sum over unassigned agents of their best allowed r(a, j)
          + sum_j T_j
          - max(deficit loss, overflow loss)

* ``T_j = lambda_j * min(free places, unassigned agents)`` for ``lambda_j > 0``,
  ``lambda_j * (agents still missing)`` for ``lambda_j < 0``: bounds
  ``sum_j lambda_j * (agents that will join j)``.
* deficit loss: for each entry point short of its minimum by d, the d
  smallest reduced losses (best r minus r there) among the unassigned agents.
  Agents on different entry points are different agents, so the sum is a
  lower bound on the reduced loss of every valid completion.
* overflow loss: for each entry point with fewer free places f than
  unassigned agents whose first best column it is, m, the m - f smallest
  differences between those agents' best and second-best r. Each agent has
  one best column: again a lower bound on the loss.

The tables are exact integers, so the bound is never too small by rounding.
A node is dead (no valid completion) when an entry point cannot get its
minimum, the minima need more agents than remain, too many agents must leave
an entry point, or (without idling) the free places are too few.
"""

from __future__ import annotations

from bisect import insort
from dataclasses import dataclass
from itertools import accumulate

from alica.allocation.table import PlanTable
from alica.allocation.utility import fixed_point


@dataclass(frozen=True, slots=True)
class Suffix:
    """Bound tables of one plan, for every suffix of agents ``s..n-1``.

    All values are reduced by the column prices: ``c(a, j) - prices[j]``.

    Args:
        prices: ``lambda_j`` per column (idle last), see :mod:`alica.allocation.flow`.
        best: ``best[s]``: sum of the agents' best allowed reduced values.
        deficit: ``deficit[s][e]``: prefix sums of the sorted reduced losses at
            entry point ``e`` (at most ``lows[e]`` of them); an entry point short
            by ``d`` costs at least ``deficit[s][e][d]``, and is infeasible when
            ``d >= len(deficit[s][e])``.
        movers: ``movers[s][e]``: agents whose (first) best column is ``e``.
        overflow: ``overflow[s][e]``: prefix sums of those agents' sorted
            best-minus-second-best differences (agents without a second choice
            are left out: they cannot move).
        bounded: entry points whose maximum can bind (smaller than the team).
    """

    prices: tuple[int, ...]
    best: tuple[int, ...]
    deficit: tuple[tuple[tuple[int, ...], ...], ...]
    movers: tuple[tuple[int, ...], ...]
    overflow: tuple[tuple[tuple[int, ...], ...], ...]
    bounded: tuple[bool, ...]


def suffix_tables(table: PlanTable, prices: tuple[int, ...]) -> Suffix:
    """The bound tables of a plan whose agents all have an allowed column."""
    n = len(table.cells)
    width = len(table.plan.entry_points)
    lows = table.lows
    bounded = tuple(h < n for h in table.highs)
    best = [0] * (n + 1)
    deficit: list[tuple[tuple[int, ...], ...]] = [()] * (n + 1)
    movers: list[tuple[int, ...]] = [()] * (n + 1)
    overflow: list[tuple[tuple[int, ...], ...]] = [()] * (n + 1)
    losses: list[list[int]] = [[] for _ in range(width)]
    moves: list[list[int]] = [[] for _ in range(width)]
    counts = [0] * width
    deficit[n] = tuple((0,) for _ in range(width))
    movers[n] = tuple(counts)
    overflow[n] = deficit[n]
    for s in range(n - 1, -1, -1):
        row = [None if cell is None else cell - price for cell, price in zip(table.cells[s], prices)]
        allowed = [(cell, j) for j, cell in enumerate(row) if cell is not None]
        top = max(cell for cell, _ in allowed)
        top_column = next(j for cell, j in allowed if cell == top)
        others = [cell for cell, j in allowed if j != top_column]
        best[s] = best[s + 1] + top
        for j in range(width):
            cell = row[j]
            if lows[j] and cell is not None and (len(losses[j]) < lows[j] or top - cell < losses[j][-1]):
                losses[j] = losses[j].copy()
                insort(losses[j], top - cell)
                del losses[j][lows[j] :]
        if top_column < width and bounded[top_column]:
            counts[top_column] += 1
            if others:
                moves[top_column] = moves[top_column].copy()
                insort(moves[top_column], top - max(others))
        deficit[s] = tuple(tuple(accumulate(values, initial=0)) for values in losses)
        movers[s] = tuple(counts)
        overflow[s] = tuple(tuple(accumulate(values, initial=0)) for values in moves)
    return Suffix(prices, tuple(best), tuple(deficit), tuple(movers), tuple(overflow), bounded)


def node_key(
    table: PlanTable, suffix: Suffix, start: int, counts: tuple[int, ...], value: int, allow_idle: bool
) -> int | None:
    """The key of a node whose agents ``0..start-1`` are assigned, ``None`` if it is dead.

    Args:
        table: the plan's table.
        suffix: its bound tables.
        start: the first unassigned agent.
        counts: agents per entry point so far.
        value: the assigned agents' contribution.
        allow_idle: whether the unassigned agents may idle.

    Returns:
        ``round(bound * 10**9)`` as an exact integer, or ``None`` if no valid
        completion exists (by the necessary conditions checked).
    """
    n = len(table.cells)
    remaining = n - start
    lows, highs = table.lows, table.highs
    prices = suffix.prices
    deficits = suffix.deficit[start]
    overflows = suffix.overflow[start]
    movers = suffix.movers[start]
    need = 0
    free = 0
    short = 0
    crowd = 0
    terms = 0
    for e, count in enumerate(counts):
        gap = lows[e] - count
        room = highs[e] - count
        price = prices[e]
        if gap > 0:
            need += gap
            sums = deficits[e]
            if gap >= len(sums):
                return None
            short += sums[gap]
            if price < 0:
                terms += price * gap
        if price > 0:
            terms += price * (min(remaining, room))
        free += room
        if suffix.bounded[e]:
            excess = movers[e] - room
            if excess > 0:
                sums = overflows[e]
                if excess >= len(sums):
                    return None
                crowd += sums[excess]
    if need > remaining or (not allow_idle and free < remaining):
        return None
    price = prices[-1]
    if price > 0:
        terms += price * remaining
    bound = value + suffix.best[start] + terms - (max(crowd, short))
    return fixed_point(bound, table.denominator)
