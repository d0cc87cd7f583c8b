"""The builtin planner's run on a grounded task: a first plan, then cheaper ones.

1. Lazy GBFS with FF (plan length) and preferred operators finds a first plan
   (or exhausts the reachable states: ``UNSOLVABLE``).
2. Restarting lazy weighted A* with decreasing weights, FF on costs and
   preferred operators, each pass pruning ``g >= best cost``; a pass that
   exhausts proves the best plan optimal.
3. Eager A* with h_max (admissible), pruning ``g + h >= best cost``: its
   plan, or its exhaustion, proves optimality.

Every plan goes through loop removal and action elimination before it is
reported.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from prophet.planner import Done, Improved, Plan, PlanStatus, PlanStep, SearchEvent
from prophet.search.astar import astar
from prophet.search.encoding import CompiledTask, compile_task
from prophet.search.gbfs import Stats, lazy_search
from prophet.search.heuristics import Relaxed
from prophet.search.postprocess import improve

DEFAULT_WEIGHTS: tuple[float, ...] = (5, 3, 2, 1.5, 1)


def to_plan(ct: CompiledTask, ops: Sequence[int]) -> Plan:
    """The :class:`Plan` of a sequence of compiled operators (cost from the task's operators)."""
    operators = ct.task.operators
    steps = tuple(PlanStep(operators[ct.source[o]].action, tuple(operators[ct.source[o]].args)) for o in ops)
    return Plan(steps, sum(operators[ct.source[o]].cost for o in ops))


def search_task(
    task: Any,
    *,
    anytime: bool = True,
    weights: Sequence[float] = DEFAULT_WEIGHTS,
    progress_every: int = 1000,
    optimal_pass: bool = True,
) -> Iterator[SearchEvent]:
    """Search a grounded task (``GroundTask`` shape), yielding planner events.

    Args:
        task: the grounded task.
        anytime: go on after the first plan (weighted A* passes, then A*).
        weights: the weights of the weighted A* passes, in order.
        progress_every: expansions between two ``Progress`` events.
        optimal_pass: end with the admissible A* pass (else ``Done(SOLVED)``
            after the last weight).

    Yields:
        ``Progress``, ``Improved`` for each cheaper plan, one final ``Done``.
    """
    stats = Stats(progress_every)
    reason = getattr(task, "unsolvable_reason", None)
    if reason:
        yield Done(PlanStatus.UNSOLVABLE, 0, str(reason))
        return
    ct = compile_task(task)
    if not ct.solvable_relaxed:
        yield Done(PlanStatus.UNSOLVABLE, 0, "the goal is unreachable even ignoring deletes")
        return
    relaxed = Relaxed(ct)
    ops = yield from lazy_search(ct, relaxed.ff, stats)
    if ops is None:
        yield Done(PlanStatus.UNSOLVABLE, stats.expansions, "every reachable state was expanded")
        return
    best = improve(ct, ops)
    best_cost = ct.plan_cost(best)
    yield Improved(to_plan(ct, best), stats.expansions)
    if not anytime:
        yield Done(PlanStatus.SOLVED, stats.expansions)
        return
    if best_cost == 0:
        yield Done(PlanStatus.OPTIMAL, stats.expansions, "a plan of cost 0")
        return
    evaluate = relaxed.ff if ct.unit_cost else relaxed.ff_cost
    for w in weights:
        ops = yield from lazy_search(ct, evaluate, stats, weight=w, bound=best_cost)
        if ops is None:
            yield Done(PlanStatus.OPTIMAL, stats.expansions, f"weighted A* (w={w}) found no cheaper plan")
            return
        ops = improve(ct, ops)
        cost = ct.plan_cost(ops)
        if cost < best_cost:
            best, best_cost = ops, cost
            yield Improved(to_plan(ct, best), stats.expansions)
    if not optimal_pass:
        yield Done(PlanStatus.SOLVED, stats.expansions)
        return
    ops = yield from astar(ct, relaxed.h_max, stats, bound=best_cost)
    if ops is not None:
        best = ops
        yield Improved(to_plan(ct, best), stats.expansions)
    yield Done(PlanStatus.OPTIMAL, stats.expansions, "A* with h_max")
