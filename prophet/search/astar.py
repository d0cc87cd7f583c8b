"""Eager A* with an admissible heuristic, pruned by a cost bound (the optimality pass).

With a consistent admissible heuristic (h_max is one), the first goal state
A* expands is reached by an optimal path; with ``g + h >= bound`` pruned, an
exhausted open list proves that no plan cheaper than ``bound`` exists.
"""

from __future__ import annotations

from collections.abc import Generator
from heapq import heappop, heappush

from alica.prophet.planner import Progress
from alica.prophet.search.encoding import CompiledTask
from alica.prophet.search.gbfs import Stats, loop_setup, trace
from alica.prophet.search.heuristics import INF, Evaluator


def astar(
    ct: CompiledTask,
    evaluate: Evaluator,
    stats: Stats,
    *,
    bound: float = INF,
    max_expansions: float = INF,
) -> Generator[Progress, None, tuple[list[int] | None, bool]]:
    """A* on ``f = g + h`` (ties: lower h, then insertion order), pruning ``f >= bound``.

    Args:
        ct: the compiled task.
        evaluate: an admissible heuristic (its preferred operators are ignored).
        stats: shared counters.
        bound: only plans cheaper than this are sought.
        max_expansions: give up after this many expansions.

    Returns:
        ``(plan, exhausted)``: an optimal plan cheaper than ``bound`` (compiled
        operator ids) or ``None``; ``exhausted`` when none exists (not when the
        budget ran out).
    """
    setup = loop_setup(ct)
    successor, applicable, op_cost, gm = setup.successor, setup.applicable, setup.op_cost, setup.goal_mask
    init = ct.init
    h0 = evaluate(init)[0]
    stats.evaluations += 1
    if h0 >= bound:
        return None, True
    best_g: dict[int, int] = {init: 0}
    parent: dict[int, tuple[int, int]] = {init: (-1, -1)}
    hcache: dict[int, float] = {init: h0}
    heap: list[tuple[float, float, int, int, int]] = [(h0, h0, 0, 0, init)]
    count = 0
    expanded = 0
    while heap:
        _f, _h, _n, g, state = heappop(heap)
        if best_g[state] < g:
            continue
        if state & gm == gm:
            return trace(parent, state), False
        stats.expansions += 1
        expanded += 1
        if expanded > max_expansions:
            return None, False
        if stats.progress_due():
            yield Progress(stats.expansions)
        for o in applicable(state):
            g2 = g + op_cost[o]
            s2 = successor(state, o)
            old = best_g.get(s2)
            if old is not None and old <= g2:
                continue
            h2 = hcache.get(s2)
            if h2 is None:
                h2 = evaluate(s2)[0]
                stats.evaluations += 1
                hcache[s2] = h2
                if stats.evaluations % stats.progress_every == 0:  # evaluations dominate here
                    yield Progress(stats.expansions)
            if g2 + h2 >= bound:
                continue
            best_g[s2] = g2
            parent[s2] = (state, o)
            count += 1
            heappush(heap, (g2 + h2, h2, count, g2, s2))
    return None, True
