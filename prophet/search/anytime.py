"""The builtin planner's run on a grounded task: a first plan, then cheaper ones.

1. LAMA's lazy greedy search (:mod:`alica.prophet.search.lama`: FF and the
   landmark count, four open lists, preferred operators) finds a first plan
   (or exhausts the reachable states: ``UNSOLVABLE``). A :class:`FirstSearch`
   chooses another heuristic (lazy GBFS with one FF variant and its preferred
   operators), a weight or a tie-breaking seed for this search (MAGiC gives
   each agent its own); the default is the search just described.
2. Quick window sweeps on it (:mod:`alica.prophet.search.windows`: stretches of the
   plan replanned among their own objects).
3. Restarts: unbounded lazy searches with other heuristics and weights, each
   plan then cleaned up and window-swept (it may start worse than the best
   and end better); full window sweeps on the best; the plan neighbourhood
   graph search (:mod:`alica.prophet.search.neighbourhood`). When the first
   search ran compiled (a large task), the full sweeps and the neighbourhood
   search come first and the restarts are LAMA's search again, compiled, with
   weights 5, 3, 2 and 1, pruned by the best plan's cost.
4. Rounds over a portfolio of bounded passes, each pruning ``g >= best cost``
   and stopped after an expansion budget that doubles every round: lazy GBFS
   with FF on h_add supporters, lazy weighted A* with decreasing weights
   (FF with h_max and with h_add supporters, preferred operators), and
   eager A* with h_max (admissible). Different heuristics and weights lead
   to different plans; the bound makes every plan found cheaper.
5. A pass that exhausts its space under the bound (rather than its budget)
   proves the best plan optimal: ``Done(OPTIMAL)`` (not the greedy pass,
   which does not reopen states); so does a neighbourhood search that covers
   the whole reachable state space.

Every plan goes through loop removal and action elimination; ``Improved``
comes only for a plan cheaper than every one before.
"""

from __future__ import annotations

from collections.abc import Generator, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from alica.prophet.planner import Done, Improved, Limits, Plan, PlanStatus, PlanStep, SearchEvent
from alica.prophet.search.astar import astar
from alica.prophet.search.compiled_lama import compiled_lama_search, first_plan
from alica.prophet.search.encoding import CompiledTask, compile_task
from alica.prophet.search.gbfs import Stats, lazy_search
from alica.prophet.search.heuristics import INF, Evaluator, Relaxed
from alica.prophet.search.jit import SwitchingFF
from alica.prophet.search.landmarks import LandmarkCount
from alica.prophet.search.neighbourhood import neighbourhood
from alica.prophet.search.postprocess import improve
from alica.prophet.search.windows import QUICK_WINDOW_STATES, WINDOW_STATES, Windows

if TYPE_CHECKING:
    from alica.prophet.ground import GroundTask

DEFAULT_WEIGHTS: tuple[float, ...] = (5, 3, 2, 1.5, 1)
NEIGHBOURHOOD_LIMITS: tuple[int, int] = (500, 4000)
"""The first and the largest state limit of the neighbourhood rounds after each plan."""
RESTART_BUDGET = 20
"""The expansion budget of each restart, in multiples of the first search's expansions."""
COMPILED_RESTART_WEIGHTS: tuple[float, ...] = (5, 3, 2, 1)
"""The weights of the compiled restarts (LAMA's search, FF and the landmark count)."""
FIRST_HEURISTICS: tuple[str, ...] = ("lama", "ff", "ff_add_unit", "ff_cost")
"""The heuristics the first search may use (methods of :class:`~alica.prophet.search.heuristics.Relaxed`)."""


@dataclass(frozen=True, slots=True)
class FirstSearch:
    """How the search for the first plan runs: lazy GBFS or lazy weighted A*.

    ``FirstSearch()`` is the builtin planner's own first search (LAMA's: greedy,
    four open lists with FF and the landmark count, :mod:`alica.prophet.search.lama`;
    the operators' order); other values lead to other first plans, which is what
    MAGiC's shares differ in.

    Attributes:
        heuristic: ``"lama"`` (FF with unit-cost h_add supporters and the landmark
            count, four open lists), or one heuristic with two open lists:
            ``"ff"`` (h_max supporters, plan length; the default before
            ``"lama"``), ``"ff_add_unit"`` (h_add supporters, plan length) or
            ``"ff_cost"`` (h_add supporters, plan cost).
        weight: ``None`` for greedy search, else the weight w of ``g + w*h``.
        seed: a tie-breaking seed (successors inserted in a shuffled order);
            ``None``: the operators' order.

    Raises:
        ValueError: an unknown heuristic, or a weight that is not a finite number > 0.
    """

    heuristic: str = "lama"
    weight: float | None = None
    seed: int | None = None

    def __post_init__(self) -> None:
        if self.heuristic not in FIRST_HEURISTICS:
            raise ValueError(
                f"unknown first-search heuristic {self.heuristic!r}; choose one of {', '.join(FIRST_HEURISTICS)}"
            )
        if self.weight is not None and (
            isinstance(self.weight, bool) or not isinstance(self.weight, int | float) or not 0 < self.weight < INF
        ):
            raise ValueError(f"the first search's weight must be a finite number > 0 or None, got {self.weight!r}")
        if self.seed is not None and (isinstance(self.seed, bool) or not isinstance(self.seed, int)):
            raise ValueError(f"the first search's seed must be an int or None, got {self.seed!r}")

    def __str__(self) -> str:
        weight = "greedy" if self.weight is None else f"w={self.weight:g}"
        seed = "" if self.seed is None else f" seed={self.seed}"
        return f"{self.heuristic} {weight}{seed}"


def to_plan(ct: CompiledTask, ops: Sequence[int]) -> Plan:
    """The :class:`Plan` of a sequence of compiled operators (cost from the task's operators)."""
    operators = ct.task.operators
    steps = tuple(PlanStep(operators[ct.source[o]].action, tuple(operators[ct.source[o]].args)) for o in ops)
    return Plan(steps, sum(operators[ct.source[o]].cost for o in ops))


def _portfolio(ct: CompiledTask, relaxed: Relaxed, weights: Sequence[float]) -> list[tuple[Evaluator, float | None]]:
    """The bounded passes of one improvement round: (heuristic, weight or None for greedy)."""
    passes: list[tuple[Evaluator, float | None]] = [(relaxed.ff_add_unit, None)]
    for w in weights:
        if ct.unit_cost:
            passes += [(relaxed.ff, w), (relaxed.ff_add_unit, w)]
        else:
            passes.append((relaxed.ff_cost, w))
    return passes


def search_task(
    task: GroundTask,
    *,
    anytime: bool = True,
    weights: Sequence[float] = DEFAULT_WEIGHTS,
    progress_every: int = 1000,
    optimal_pass: bool = True,
    first: FirstSearch | None = None,
    limits: Limits | None = None,
    stats: Stats | None = None,
) -> Iterator[SearchEvent]:
    """Search a grounded task (``GroundTask`` shape), yielding planner events.

    Args:
        task: the grounded task.
        anytime: go on after the first plan (see the module docstring).
        weights: the weights of the weighted A* passes, in order.
        progress_every: expansions between two ``Progress`` events.
        optimal_pass: include the A* pass with h_max in the rounds; without it
            (and with inadmissible passes only) the run ends with
            ``Done(SOLVED)`` after one round.
        first: how the first plan is searched; ``None`` is ``FirstSearch()``.
        limits: the run's deadline, checked while searching (every few expansions).
        stats: the run's counters (expansions, evaluations), to read them
            afterwards; ``None``: fresh ones (``progress_every`` and ``limits`` apply then).

    Yields:
        ``Progress``, ``Improved`` for each cheaper plan, one final ``Done``.

    Raises:
        LimitReached: the deadline of ``limits`` passed (``Planner.search`` turns it into ``Done(TIMEOUT)``).
    """
    stats = Stats(progress_every, limits) if stats is None else stats
    reason = task.unsolvable_reason
    if reason:
        yield Done(PlanStatus.UNSOLVABLE, 0, str(reason))
        return
    ct = compile_task(task)
    if not ct.solvable_relaxed:
        yield Done(PlanStatus.UNSOLVABLE, 0, "the goal is unreachable even ignoring deletes")
        return
    relaxed = Relaxed(ct)
    first = FirstSearch() if first is None else first
    lmcount: LandmarkCount | None = None
    if first.heuristic == "lama":
        lmcount = LandmarkCount(ct, relaxed)
        ff: Evaluator
        if relaxed.has_rules:
            # h_add sums a derived fact's rule bodies again for every use: with rules, h_max supporters guide
            # far better (optical-telegraphs p02: 522 expansions against 5,176; the other derived domains alike)
            ff = relaxed.ff
        else:
            ff = SwitchingFF(relaxed, relaxed.ff_unit, relaxed.r_unit, limits=stats.limits)  # every operator 1
        ops, _exhausted = yield from first_plan(ct, relaxed, ff, lmcount, stats, weight=first.weight, seed=first.seed)
    else:
        evaluate: Evaluator = {"ff": relaxed.ff, "ff_add_unit": relaxed.ff_add_unit, "ff_cost": relaxed.ff_cost}[
            first.heuristic
        ]
        ops, _exhausted = yield from lazy_search(ct, evaluate, stats, weight=first.weight, seed=first.seed)
    if ops is None:
        yield Done(PlanStatus.UNSOLVABLE, stats.expansions, "every reachable state was expanded")
        return
    first_expansions = stats.expansions
    best = improve(ct, ops)
    yield Improved(to_plan(ct, best), stats.expansions)
    if not anytime:
        yield Done(PlanStatus.SOLVED, stats.expansions)
        return
    windows = Windows(ct)
    best = yield from _windows(ct, windows, best, ct.plan_cost(best), stats, QUICK_WINDOW_STATES)
    best_cost = ct.plan_cost(best)
    polished: list[int] | None = None
    if stats.compiled:  # a large task: full sweeps and the neighbourhood come before the restarts, long there
        best = yield from _windows(ct, windows, best, best_cost, stats)
        best, proven = yield from _polish(ct, best, stats)
        if proven:
            yield Done(PlanStatus.OPTIMAL, stats.expansions, "every reachable state was explored")
            return
        best_cost = ct.plan_cost(best)
        polished = best
    restart_budget = RESTART_BUDGET * max(100, first_expansions)
    for restart, weight in _restarts(ct, relaxed, lmcount if stats.compiled else None):
        if isinstance(restart, str):  # "lama": the first search ran compiled, so do the restarts
            assert lmcount is not None
            ops, _exhausted = yield from compiled_lama_search(
                ct, relaxed, lmcount, stats, weight=weight, max_expansions=restart_budget, bound=best_cost
            )
        else:
            ops, _exhausted = yield from lazy_search(ct, restart, stats, weight=weight, max_expansions=restart_budget)
        if ops is not None:
            found = yield from _windows(ct, windows, improve(ct, ops), best_cost, stats, QUICK_WINDOW_STATES)
            found = yield from _windows(ct, windows, found, min(best_cost, ct.plan_cost(found)), stats)
            if ct.plan_cost(found) < best_cost:
                best, best_cost = found, ct.plan_cost(found)
    proven = False
    if best is not polished:
        best = yield from _windows(ct, windows, best, best_cost, stats)
        best, proven = yield from _polish(ct, best, stats)
    best_cost = ct.plan_cost(best)
    if proven or best_cost == 0:
        yield Done(PlanStatus.OPTIMAL, stats.expansions, "every reachable state was explored")
        return
    passes = _portfolio(ct, relaxed, weights)
    budget = max(500, 2 * first_expansions)
    while True:
        for evaluate, weight in passes:
            ops, exhausted = yield from lazy_search(
                ct, evaluate, stats, weight=weight, bound=best_cost, max_expansions=budget
            )
            if exhausted and weight is not None:  # greedy passes do not reopen: no proof
                yield Done(PlanStatus.OPTIMAL, stats.expansions, "a bounded pass found no cheaper plan")
                return
            if ops is not None:
                found = yield from _windows(ct, windows, improve(ct, ops), best_cost, stats)
                best, proven = yield from _polish(ct, found, stats)
                best_cost = ct.plan_cost(best)
                if proven:
                    yield Done(PlanStatus.OPTIMAL, stats.expansions, "every reachable state was explored")
                    return
        if not optimal_pass:
            yield Done(PlanStatus.SOLVED, stats.expansions)
            return
        ops, exhausted = yield from astar(ct, relaxed.h_max, stats, bound=best_cost, max_expansions=budget)
        if ops is not None:
            yield Improved(to_plan(ct, ops), stats.expansions)
        if ops is not None or exhausted:
            yield Done(PlanStatus.OPTIMAL, stats.expansions, "A* with h_max")
            return
        budget *= 2


def _restarts(
    ct: CompiledTask, relaxed: Relaxed, lmcount: LandmarkCount | None
) -> list[tuple[Evaluator | str, float | None]]:
    """The unbounded searches after the first plan: other heuristics and weights give other plans.

    With ``lmcount`` (the first search ran compiled, on a large task), LAMA's search again, compiled,
    with the weights of LAMA's own restarts and pruned by the best plan's cost: pure-Python ones
    would not end within a few seconds there.
    """
    if lmcount is not None:
        return [("lama", w) for w in COMPILED_RESTART_WEIGHTS]
    if ct.unit_cost:
        return [(relaxed.ff_add_unit, None), (relaxed.ff, 3), (relaxed.ff_add_unit, 3)]
    return [(relaxed.ff_cost, None), (relaxed.ff_cost, 3)]


def _windows(
    ct: CompiledTask,
    windows: Windows,
    plan: list[int],
    report_below: float,
    stats: Stats,
    limit: int = WINDOW_STATES,
) -> Generator[SearchEvent, None, list[int]]:
    """Window replanning on ``plan`` until a sweep finds nothing cheaper.

    Yields ``Improved`` for each plan (``plan`` itself included) cheaper than
    ``report_below`` (the best so far) and returns the last plan. ``limit``
    caps the states of each window search.
    """
    if ct.plan_cost(plan) < report_below:
        report_below = ct.plan_cost(plan)
        yield Improved(to_plan(ct, plan), stats.expansions)
    while True:
        found = yield from windows.improve_once(plan, stats, limit=limit)
        if found is None:
            return plan
        plan = improve(ct, found)
        cost = ct.plan_cost(plan)
        if cost < report_below:
            report_below = cost
            yield Improved(to_plan(ct, plan), stats.expansions)


def _polish(ct: CompiledTask, plan: list[int], stats: Stats) -> Generator[SearchEvent, None, tuple[list[int], bool]]:
    """Neighbourhood rounds around ``plan`` (the limit doubles after a round without gain).

    Yields ``Improved`` for each cheaper plan; returns the best plan and whether
    it is proven optimal (a round explored the whole reachable state space).
    """
    limit, cap = NEIGHBOURHOOD_LIMITS
    cost = ct.plan_cost(plan)
    while limit <= cap:
        ops, exhausted = yield from neighbourhood(ct, plan, limit, stats)
        ops = improve(ct, ops)
        new_cost = ct.plan_cost(ops)
        if new_cost < cost:
            plan, cost = ops, new_cost
            yield Improved(to_plan(ct, plan), stats.expansions)
        elif not exhausted:
            limit *= 2
        if exhausted:
            return plan, True
    return plan, False


__all__ = ["DEFAULT_WEIGHTS", "FIRST_HEURISTICS", "INF", "FirstSearch", "search_task", "to_plan"]
