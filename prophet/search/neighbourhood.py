"""Plan neighbourhood graph search: a cheaper plan among the states near a plan.

The states along a plan seed a breadth-first expansion of at most ``limit``
states (no heuristic: successor generation only); uniform-cost search over
the explored graph then gives the cheapest plan inside it, which is never
worse than the seed plan (its states are in the graph). When the expansion
runs out of states before the limit, the graph is the whole reachable state
space and the plan found is optimal. Rounds with a doubling limit repeat
while they pay off.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Generator
from heapq import heappop, heappush

from alica.prophet.planner import Progress
from alica.prophet.search.encoding import CompiledTask
from alica.prophet.search.gbfs import Stats


def neighbourhood(
    ct: CompiledTask, plan: list[int], limit: int, stats: Stats
) -> Generator[Progress, None, tuple[list[int], bool]]:
    """One round around ``plan``.

    Args:
        ct: the compiled task.
        plan: a valid plan (compiled operator ids).
        limit: the most states to expand.
        stats: shared counters.

    Returns:
        ``(cheapest plan in the graph, whether the whole reachable space was explored)``.
    """
    successor = ct.successor
    applicable = ct.applicable
    cost = ct.cost
    gm = ct.goal_mask
    seeds = [ct.init]
    for op in plan:
        seeds.append(successor(seeds[-1], op))
    seen: set[int] = set()
    queue: deque[int] = deque()
    for s in seeds:
        if s not in seen:
            seen.add(s)
            queue.append(s)
    edges: dict[int, list[tuple[int, int]]] = {}
    expanded = 0
    while queue and expanded < limit:
        s = queue.popleft()
        out: list[tuple[int, int]] = []
        for o in applicable(s):
            t = successor(s, o)
            out.append((o, t))
            if t not in seen:
                seen.add(t)
                queue.append(t)
        edges[s] = out
        expanded += 1
        stats.expansions += 1
        if stats.progress_due():
            yield Progress(stats.expansions)
    exhausted = not queue
    init = ct.init
    dist = {init: 0}
    parent: dict[int, tuple[int, int]] = {init: (-1, -1)}
    heap: list[tuple[int, int, int]] = [(0, 0, init)]
    count = 0
    while heap:
        g, _n, s = heappop(heap)
        if dist[s] < g:
            continue
        if s & gm == gm:
            ops: list[int] = []
            while True:
                ps, op = parent[s]
                if op < 0:
                    break
                ops.append(op)
                s = ps
            ops.reverse()
            return ops, exhausted
        for o, t in edges.get(s, ()):
            g2 = g + cost[o]
            old = dist.get(t)
            if old is None or g2 < old:
                dist[t] = g2
                parent[t] = (s, o)
                count += 1
                heappush(heap, (g2, count, t))
    return plan, exhausted  # not reached: the seed plan is in the graph
