"""LAMA's first search: lazy greedy search alternating four open lists, FF and landmarks.

As in LAMA (Richter and Westphal 2010) and Fast Downward's ``lama-first``:
every state popped is evaluated with two heuristics, FF (h_add supporters,
every action costing 1, relaxed plan length) and the landmark count
(:mod:`alica.prophet.search.landmarks`, every landmark counting 1). Its
successors enter four open lists with their parent's estimates (lazy): all
successors keyed by FF, all keyed by the landmark count, and the successors
through a preferred operator (FF's helpful actions together with the
landmark heuristic's) keyed by each. The lists take turns, the one with the
fewest turns going next (ties: the order above); whenever either estimate
reaches a new best, the two preferred lists get ``boost`` turns back. A
state FF finds a relaxed dead end is dropped. Ties in a list go to the
earliest insertion, so a run is deterministic; a ``seed`` shuffles each
state's successors first, as in :mod:`alica.prophet.search.gbfs`.

The landmark count depends on the path: each state keeps the landmarks its
first path has accepted (a bitset ``int``), computed from its parent's when
the state is popped. Closed states are never reopened (greedy search).
"""

from __future__ import annotations

from collections.abc import Generator
from heapq import heappop, heappush

from alica.prophet.planner import Progress
from alica.prophet.search.encoding import CompiledTask
from alica.prophet.search.gbfs import Stats, loop_setup, trace
from alica.prophet.search.heuristics import INF, Evaluator
from alica.prophet.search.landmarks import LandmarkCount


def lama_search(
    ct: CompiledTask,
    ff: Evaluator,
    lmcount: LandmarkCount,
    stats: Stats,
    *,
    weight: float | None = None,
    boost: int = 1000,
    max_expansions: float = INF,
    seed: int | None = None,
    landmark_preferred: bool = True,
    bound: float = INF,
) -> Generator[Progress, None, tuple[list[int] | None, bool]]:
    """LAMA's lazy search with FF and the landmark count (see the module docstring).

    Args:
        ct: the compiled task.
        ff: the FF heuristic (state -> (h, helpful operators)).
        lmcount: the landmark-count heuristic of ``ct``.
        stats: shared counters (also sets how often ``Progress`` comes).
        weight: ``None`` for greedy search, else the weight w of ``g + w*h`` in every list.
        boost: turns given back to the preferred lists on progress.
        max_expansions: give up after this many expansions.
        seed: shuffle each state's successors with this seed; ``None`` keeps the operators' order.
        bound: successors whose ``g`` reaches it are not inserted (only cheaper plans are found).

    Returns:
        ``(plan, exhausted)`` as :func:`~alica.prophet.search.gbfs.lazy_search` does.
    """
    setup = loop_setup(ct, weight, seed)
    successor, applicable, op_cost, gm = setup.successor, setup.applicable, setup.op_cost, setup.goal_mask
    greedy, w, shuffle = setup.greedy, setup.w, setup.shuffle
    progress = lmcount.progress
    needed_of = lmcount.needed
    lm_preferred = lmcount.preferred
    unit = lmcount.unit
    parent: dict[int, tuple[int, int]] = {}
    accepted_of: dict[int, int] = {}
    closed: set[int] = set()
    # 0: FF, 1: FF preferred, 2: landmarks, 3: landmarks preferred
    lists: tuple[list[tuple[float, int, int, int, int]], ...] = ([], [], [], [])
    prio = [0, 0, 0, 0]
    count = 0
    expanded = 0
    best_ff = INF
    best_lm = INF
    entry: tuple[float, int, int, int, int] | None = (0.0, 0, -1, -1, 0)
    while True:
        if entry is None:
            which = -1
            for i in range(4):
                if lists[i] and (which < 0 or prio[i] < prio[which]):
                    which = i
            if which < 0:
                return None, True
            prio[which] += 1
            entry = heappop(lists[which])
        _key, _n, pstate, op, g = entry
        entry = None
        if op < 0:
            state = ct.init
            accepted = lmcount.initial
        else:
            state = successor(pstate, op)
            if state in closed:
                continue
            accepted = progress(accepted_of[pstate], state)
        closed.add(state)
        parent[state] = (pstate, op)
        if state & gm == gm:
            return trace(parent, state), False
        h_ff, ff_pref = ff(state)
        stats.evaluations += 1
        if h_ff == INF:
            continue
        needed = needed_of(state, accepted)
        h_lm: float = needed.bit_count() if unit else lmcount.count(needed)
        accepted_of[state] = accepted
        stats.expansions += 1
        expanded += 1
        if expanded > max_expansions:
            return None, False
        if stats.progress_due():
            yield Progress(stats.expansions)
        successors = applicable(state)
        improved = False
        if h_ff < best_ff:
            best_ff = h_ff
            improved = True
        if h_lm < best_lm:
            best_lm = h_lm
            improved = True
        if improved:
            prio[1] -= boost
            prio[3] -= boost
        pref = set(ff_pref)
        if landmark_preferred:
            pref.update(lm_preferred(state, accepted, needed, successors))
        if shuffle is not None:
            successors = list(successors)
            shuffle(successors)
        for o in successors:
            g2 = g + op_cost[o]
            if g2 >= bound:
                continue
            count += 1
            k_ff = h_ff if greedy else g2 + w * h_ff
            k_lm = h_lm if greedy else g2 + w * h_lm
            heappush(lists[0], (k_ff, count, state, o, g2))
            heappush(lists[2], (k_lm, count, state, o, g2))
            if o in pref:
                heappush(lists[1], (k_ff, count, state, o, g2))
                heappush(lists[3], (k_lm, count, state, o, g2))


__all__ = ["lama_search"]
