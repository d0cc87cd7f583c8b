"""Lazy best-first search with preferred operators: greedy (GBFS) or weighted A*.

As in FF and LAMA, successors enter the open lists with their parent's
estimate and are evaluated only when popped. Two open lists alternate: all
successors, and the successors through preferred operators; each time the
search finds a state with a lower estimate than before, the preferred list
gets ``boost`` extra turns. Ties go to the earliest insertion, and states
are plain ``int`` bitsets, so a run is deterministic. A ``seed`` shuffles
the order in which each state's successors are inserted (so ties between
siblings break another way, the same for the same seed); without one the
order is the operators' own.

The searches are generators: they yield :class:`~alica.prophet.planner.Progress`
every ``progress_every`` expansions and *return* the plan (compiled operator
ids) or ``None``, and whether the open lists ran dry; use
``plan, exhausted = yield from ...``.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass
from heapq import heappop, heappush

from alica.prophet.planner import LimitReached, Limits, Progress
from alica.prophet.search.encoding import CompiledTask
from alica.prophet.search.heuristics import INF, Evaluator

CHECK_EVERY = 16
"""Expansions between two checks of the run's limits (a slow heuristic evaluates some 50 states a second)."""


@dataclass(slots=True)
class Stats:
    """Counters shared by the searches of one planner run, and the run's limits.

    Attributes:
        progress_every: expansions between two ``Progress`` events.
        limits: the run's deadline, checked every :data:`CHECK_EVERY` expansions (``None``: none);
            a search that passes it raises :class:`~alica.prophet.planner.LimitReached`.
        expansions: states expanded so far (all searches together).
        evaluations: heuristic evaluations so far.
        next_progress: the expansion count of the next ``Progress``.
        next_check: the expansion count of the next check of the limits.
        compiled: whether a compiled search ran in this run (the anytime restarts then run compiled too).
    """

    progress_every: int = 1000
    limits: Limits | None = None
    expansions: int = 0
    evaluations: int = 0
    next_progress: int = 0
    next_check: int = 0
    compiled: bool = False

    def __post_init__(self) -> None:
        self.progress_every = max(1, int(self.progress_every))
        self.next_progress = self.progress_every
        self.next_check = CHECK_EVERY

    def progress_due(self) -> bool:
        """Whether a ``Progress`` event is due now; checks the limits on the way.

        Progress events come every ``progress_every`` expansions whatever the clock says (MAGiC
        counts search steps by them); the deadline only ends a run that is past it.

        Raises:
            LimitReached: the deadline has passed.
        """
        n = self.expansions
        if n >= self.next_check:
            self.next_check = n + CHECK_EVERY
            if self.limits is not None:
                try:
                    self.limits.check("searching", done=f"{n} expansions")
                except LimitReached as exc:
                    exc.expansions = n
                    raise
        if n >= self.next_progress:
            self.next_progress += self.progress_every
            return True
        return False


@dataclass(frozen=True, slots=True)
class LoopSetup:
    """What every search loop reads before it starts: the task's hot members (the loop binds them
    to locals), the weighting and the successor shuffle."""

    successor: Callable[[int, int], int]
    applicable: Callable[[int], list[int]]
    op_cost: Sequence[int]
    goal_mask: int
    greedy: bool
    w: float
    shuffle: Callable[[list[int]], None] | None


def loop_setup(ct: CompiledTask, weight: float | None = None, seed: int | None = None) -> LoopSetup:
    """The shared preamble of :func:`lazy_search`, :func:`~alica.prophet.search.lama.lama_search`
    and :func:`~alica.prophet.search.astar.astar`."""
    return LoopSetup(
        ct.successor,
        ct.applicable,
        ct.cost,
        ct.goal_mask,
        weight is None,
        1.0 if weight is None else float(weight),
        random.Random(seed).shuffle if seed is not None else None,
    )


def trace(parent: dict[int, tuple[int, int]], state: int) -> list[int]:
    """The operators leading to ``state`` through the ``parent`` links (op -1 marks the start)."""
    ops: list[int] = []
    while True:
        pstate, op = parent[state]
        if op < 0:
            break
        ops.append(op)
        state = pstate
    ops.reverse()
    return ops


def lazy_search(
    ct: CompiledTask,
    evaluate: Evaluator,
    stats: Stats,
    *,
    weight: float | None = None,
    bound: float = INF,
    boost: int = 1000,
    max_expansions: float = INF,
    seed: int | None = None,
) -> Generator[Progress, None, tuple[list[int] | None, bool]]:
    """Lazy GBFS (``weight=None``) or lazy weighted A* with preferred operators.

    Args:
        ct: the compiled task.
        evaluate: the heuristic (its preferred operators fill the second list).
        stats: shared counters (also sets how often ``Progress`` comes).
        weight: ``None`` for greedy search on h, else the weight w of ``g + w*h``.
        bound: successors with ``g >= bound`` are pruned.
        boost: extra turns for the preferred list after progress.
        max_expansions: give up after this many expansions.
        seed: shuffle each state's successors with this seed before inserting them
            (another tie-breaking); ``None`` keeps the operators' order.

    Returns:
        ``(plan, exhausted)``: the plan as compiled operator ids, or ``None``;
        ``exhausted`` when the search space under the bound ran out (with
        weighted A*, states are reopened on a cheaper path, so this proves
        that no plan cheaper than ``bound`` exists), not when the expansion
        budget did.
    """
    setup = loop_setup(ct, weight, seed)
    successor, applicable, op_cost, gm = setup.successor, setup.applicable, setup.op_cost, setup.goal_mask
    greedy, w, shuffle = setup.greedy, setup.w, setup.shuffle
    parent: dict[int, tuple[int, int]] = {}
    closed_g: dict[int, int] = {}
    cache: dict[int, tuple[float, list[int]]] = {}
    regular: list[tuple[float, int, int, int, int]] = []
    preferred: list[tuple[float, int, int, int, int]] = []
    prio = [0, 0]
    count = 0
    expanded = 0
    best_h = INF
    entry: tuple[float, int, int, int, int] | None = (0.0, 0, -1, -1, 0)
    while True:
        if entry is None:
            if regular and preferred:
                which = 0 if prio[0] <= prio[1] else 1
            elif regular:
                which = 0
            elif preferred:
                which = 1
            else:
                return None, True
            prio[which] += 1
            entry = heappop(preferred if which else regular)
        _key, _n, pstate, op, g = entry
        entry = None
        state = ct.init if op < 0 else successor(pstate, op)
        old = closed_g.get(state)
        if old is not None and (greedy or old <= g):
            continue
        closed_g[state] = g
        parent[state] = (pstate, op)
        if state & gm == gm:
            return trace(parent, state), False
        hp = cache.get(state)
        if hp is None:
            hp = evaluate(state)
            stats.evaluations += 1
            if not greedy:
                cache[state] = hp
        h, pref = hp
        if h == INF:
            continue
        stats.expansions += 1
        expanded += 1
        if expanded > max_expansions:
            return None, False
        if stats.progress_due():
            yield Progress(stats.expansions)
        if h < best_h:
            best_h = h
            if pref:
                prio[1] -= boost
        successors = applicable(state)
        if shuffle is not None:
            successors = list(successors)
            shuffle(successors)
            pref = list(pref)
            shuffle(pref)
        for o in successors:
            g2 = g + op_cost[o]
            if g2 >= bound:
                continue
            count += 1
            heappush(regular, (h if greedy else g2 + w * h, count, state, o, g2))
        for o in pref:
            g2 = g + op_cost[o]
            if g2 >= bound:
                continue
            count += 1
            heappush(preferred, (h if greedy else g2 + w * h, count, state, o, g2))
