"""The relaxation that makes the search fast: a plan's best value, exactly, and its prices.

Without the tie rule, allocation in one plan is a transportation problem:
agents go to columns (entry points, then idle) with a minimum and a maximum
count per column and additive integer values (:mod:`alica.allocation.table`).
It is a min-cost flow on a tiny graph: the columns and a sink ``t``. Agents
are inserted one by one along longest augmenting paths; a path may shift
other agents along a chain of columns. The first ``min`` places of a column
carry a bonus ``M`` larger than twice any value difference, so minima are met
whenever they can be (and a solution that needs ``-M`` is infeasible).

A solution is optimal iff its residual graph (move an agent from column i to
j, gain ``c(b, j) - c(b, i)``; one more agent at j: ``j -> t``; one fewer at
i: ``t -> i``) has no positive cycle. Two uses:

* Prices: longest-path potentials of the optimal residual graph, the dual
  ``lambda_j`` per column. For any prices and every valid assignment x,
  ``sum_a c(a, x_a) <= sum_a max_j (c(a, j) - lambda_j) + sum_j T_j`` with
  ``T_j = lambda_j * max'`` (``lambda_j > 0``) or ``lambda_j * min'``
  (``lambda_j < 0``): the search's cheap bound (:mod:`alica.allocation.bound`).
* Fixing one agent: if x is optimal with agents ``0..k-1`` fixed, the best
  solution with agent k also fixed, at column j, is x plus agent k's move
  ``x_k -> j`` plus a longest path from j back to ``x_k`` that moves only agents
  ``k+1..`` (any better solution would differ from x by that cycle plus cycles
  of a conformal decomposition, which are not positive). So each search node
  can carry the exact best value of its completions.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from alica.allocation.table import PlanTable

#: ``arcs[i][j]``: the best ``(gain, agent)`` of moving one agent from column i to j, or ``None``.
Arcs = list[list[tuple[int, int] | None]]


@dataclass(frozen=True, slots=True)
class Basis:
    """A complete assignment of one plan, optimal for some set of fixed agents.

    Args:
        total: the sum of the agents' contributions (U times the denominator).
        columns: the column of each agent (entry point index, idle last).
        counts: agents per column.
    """

    total: int
    columns: tuple[int, ...]
    counts: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class Relaxation:
    """The optimum of a plan and what the search needs from it.

    Args:
        basis: an optimal assignment (no agent fixed).
        prices: ``lambda_j`` per column (idle last).
        bonus: M, the bonus on a column's first ``min`` places.
        lows: minimum per column (idle: 0).
        highs: maximum per column (idle: the team size).
    """

    basis: Basis
    prices: tuple[int, ...]
    bonus: int
    lows: tuple[int, ...]
    highs: tuple[int, ...]


def move_arcs(table: PlanTable, columns: tuple[int, ...] | list[int], movable: range | list[int], width: int) -> Arcs:
    """The best gain of moving one of the ``movable`` agents from column i to column j, per pair."""
    arcs: Arcs = [[None] * width for _ in range(width)]
    cells = table.cells
    for b in movable:
        i = columns[b]
        row = cells[b]
        here = row[i]
        if here is None:  # pragma: no cover - agents only sit in allowed columns
            continue
        out = arcs[i]
        for j, cell in enumerate(row):
            if cell is None or j == i:
                continue
            gain = cell - here
            current = out[j]
            if current is None or gain > current[0]:
                out[j] = (gain, b)
    return arcs


def _longest(start: list[int | None], arcs: Arcs) -> tuple[list[int | None], list[tuple[int, int] | None]]:
    """Longest paths from a source whose arcs into the nodes have gains ``start``.

    Label-correcting (a queue of nodes whose distance grew); the graph has no
    positive cycle, so it ends, after at most ``nodes`` passes over each node.

    Returns:
        ``(distance, predecessor)`` per node; the predecessor is ``(node, agent
        moved from it)`` (agent ``-1`` for arcs that move none), ``None`` when
        the node was entered from the source.
    """
    size = len(start)
    dist = list(start)
    pred: list[tuple[int, int] | None] = [None] * size
    queue = deque(i for i in range(size) if dist[i] is not None)
    waiting = [d is not None for d in dist]
    budget = size * size + size
    while queue:
        budget -= 1
        if budget < 0:  # pragma: no cover - only a positive cycle could keep it going
            raise RuntimeError("allocation relaxation: positive cycle")
        i = queue.popleft()
        waiting[i] = False
        base = dist[i]
        if base is None:  # pragma: no cover - only reached nodes are queued
            continue
        for j, arc in enumerate(arcs[i]):
            if arc is None:
                continue
            candidate = base + arc[0]
            target = dist[j]
            if target is None or candidate > target:
                dist[j] = candidate
                pred[j] = (i, arc[1])
                if not waiting[j]:
                    waiting[j] = True
                    queue.append(j)
    return dist, pred


def _with_sink(
    arcs: Arcs, counts: tuple[int, ...] | list[int], lows: tuple[int, ...], highs: tuple[int, ...], bonus: int
) -> Arcs:
    """The residual graph: column moves plus the sink ``t`` (last node) and its arcs."""
    width = len(counts)
    graph: Arcs = [row + [None] for row in arcs]
    graph.append([None] * (width + 1))
    for j in range(width):
        if counts[j] < highs[j]:
            graph[j][width] = (bonus if counts[j] < lows[j] else 0, -1)
        if counts[j] > 0:
            graph[width][j] = (0 if counts[j] > lows[j] else -bonus, -1)
    return graph


def solve(table: PlanTable) -> Relaxation | None:
    """The plan's optimum without the tie rule, ``None`` if it has no valid assignment."""
    n = len(table.cells)
    width = len(table.plan.entry_points) + 1
    lows = (*table.lows, 0)
    highs = (*table.highs, n)
    spread = 0
    for row in table.cells:
        allowed = [cell for cell in row if cell is not None]
        if not allowed:
            return None
        spread += max(allowed) - min(allowed)
    bonus = 2 * spread + 1
    columns = [0] * n
    counts = [0] * width
    members: list[list[int]] = [[] for _ in range(width)]
    arcs: Arcs = [[None] * width for _ in range(width)]
    for a in range(n):
        dist, pred = _longest(list(table.cells[a]), arcs)
        end = None
        best = 0
        for j in range(width):
            d = dist[j]
            if d is None or counts[j] >= highs[j]:
                continue
            gain = d + (bonus if counts[j] < lows[j] else 0)
            if end is None or gain > best:
                end, best = j, gain
        if end is None:
            return None
        counts[end] += 1
        changed = {end}
        j = end
        for _ in range(width):
            step = pred[j]
            if step is None:
                break
            i, b = step
            columns[b] = j
            members[i].remove(b)
            members[j].append(b)
            changed.add(i)
            j = i
        else:  # pragma: no cover - a chain visits each column at most once
            raise RuntimeError("allocation relaxation: augmenting chain does not end")
        columns[a] = j
        members[j].append(a)
        changed.add(j)
        for i in changed:
            arcs[i] = move_arcs(table, columns, members[i], width)[i]
    if any(c < lo for c, lo in zip(counts, lows)):
        return None
    total = sum(table.cells[a][j] or 0 for a, j in enumerate(columns))
    graph = _with_sink(move_arcs(table, columns, range(n), width), counts, lows, highs, bonus)
    potential, _ = _longest([0] * (width + 1), graph)
    top = potential[width] or 0
    prices = tuple((p or 0) - top for p in potential[:width])
    return Relaxation(Basis(total, tuple(columns), tuple(counts)), prices, bonus, lows, highs)


def fix(table: PlanTable, relaxation: Relaxation, basis: Basis, agent: int, column: int, arcs: Arcs) -> Basis | None:
    """The best assignment with agents ``0..agent`` fixed and ``agent`` at ``column``.

    Args:
        table: the plan's table.
        relaxation: the plan's relaxation (bonus and bounds).
        basis: optimal with agents ``0..agent-1`` fixed; ``agent`` is not at ``column``.
        agent: the agent to fix.
        column: its column; ``table.cells[agent][column]`` is allowed.
        arcs: :func:`move_arcs` of ``basis`` over agents ``agent+1..``.

    Returns:
        The new optimal basis, ``None`` if no valid assignment has ``agent`` there.
    """
    origin = basis.columns[agent]
    graph = _with_sink(arcs, basis.counts, relaxation.lows, relaxation.highs, relaxation.bonus)
    start: list[int | None] = [None] * len(graph)
    start[column] = 0
    dist, pred = _longest(start, graph)
    gain = dist[origin]
    if gain is None or gain < -(relaxation.bonus - 1) // 2:
        return None
    here, there = table.cells[agent][origin], table.cells[agent][column]
    if here is None or there is None:  # pragma: no cover - both are allowed
        return None
    columns = list(basis.columns)
    node = origin
    for _ in range(len(graph)):
        if node == column:
            break
        step = pred[node]
        if step is None:  # pragma: no cover - the path starts at column
            raise RuntimeError("allocation relaxation: path does not reach its start")
        previous, moved = step
        if moved >= 0:
            columns[moved] = node
        node = previous
    else:  # pragma: no cover - a longest path visits each node at most once
        raise RuntimeError("allocation relaxation: path does not end")
    columns[agent] = column
    counts = [0] * len(basis.counts)
    for j in columns:
        counts[j] += 1
    return Basis(basis.total + there - here + gain, tuple(columns), tuple(counts))
