"""The temporal back-end: two searches for a short makespan, taking turns; the shorter plan wins.

1. **Sequential, then scheduled** (:mod:`alica.prophet.temporal`): the builtin search plans the
   sequential task (for the summed duration); each plan it improves to is deordered and scheduled.
2. **Makespan search** (:mod:`alica.prophet.temporal_search`): a forward search over decision
   epochs that starts actions side by side, ordered by an estimate of the makespan, pruned by the
   best makespan either search has found.

The two run in turns, one event of each (a ``Progress`` every so many expansions, an ``Improved``,
the final ``Done``) before the other, so the run is deterministic for the same expansions; both
stop at the run's :class:`~alica.prophet.planner.Limits`. The makespan search grounds nothing of
its own: it takes the ground actions of the sequential task from the builtin planner's grounding.
It refuses what it cannot take (instantaneous actions, conditions that are no conjunctions of
literals): then only the first search runs, and the final ``Done`` says why.

Every plan is checked by :func:`~alica.prophet.validate_temporal.validate_temporal_plan` before its
``Improved`` event, which comes only for a makespan shorter than every one before; its plan's cost
is the makespan. :meth:`TemporalPlanner.schedule_of` gives the timed plan back: a plan of the
makespan search carries its own (:class:`~alica.prophet.temporal.ScheduledPlan`), a sequential
plan's is its schedule.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Generator, Iterator
from typing import Any

from alica.errors import PlannerError
from alica.prophet.pddl import Domain, Problem
from alica.prophet.planner import (
    Done,
    Feature,
    Improved,
    LimitReached,
    Limits,
    Plan,
    Planner,
    PlanStatus,
    PlanStep,
    Progress,
    SearchEvent,
)
from alica.prophet.search.planner import BuiltinPlanner
from alica.prophet.temporal import Schedule, ScheduledPlan, schedule, sequential_task, timed_schedule
from alica.prophet.temporal_ground import TICKS, temporal_task
from alica.prophet.temporal_plan import TemporalPlan
from alica.prophet.temporal_search import MAKESPAN_PASSES, Bound, Pass, TimedResult, makespan_search
from alica.prophet.validate_temporal import validate_temporal_plan

logger = logging.getLogger(__name__)

SEQUENTIAL = "sequential"
MAKESPAN = "makespan"


class TemporalPlanner(Planner):
    """Durative actions, makespan (see the module docstring).

    Args:
        makespan_search: whether the makespan search runs beside the sequential one.
        makespan_passes: the makespan search's passes.
        makespan_only: run the makespan search alone (the builtin planner still grounds the task, but does not search it).
        no_more_steps: a plan of the makespan search counts only when it has no more steps than the
            best plan so far (one found before the sequential search's first plan waits for it), so
            the makespan never shortens by adding steps: a team runs every step, and a shorter
            makespan bought with more steps costs it more driving and waiting than the durations tell.
        options: go to the builtin planner.
    """

    name = "temporal"
    features = BuiltinPlanner.features | {Feature.DURATIVE_ACTIONS}
    takes_limits = True
    first_plan_waits = True  # the sequential search's first plan comes before any of the makespan search's

    def __init__(
        self,
        *,
        makespan_search: bool = True,
        makespan_passes: tuple[Pass, ...] = MAKESPAN_PASSES,
        makespan_only: bool = False,
        no_more_steps: bool = False,
        **options: Any,
    ) -> None:
        self.inner = BuiltinPlanner(**options)
        self.makespan_search = makespan_search or makespan_only
        self.makespan_only = makespan_only
        self.no_more_steps = no_more_steps
        self.makespan_passes = tuple(makespan_passes)
        self.sources: dict[str, int] = {}
        """Per search, how many plans of the last run came from it (``sequential``, ``makespan``)."""
        self.best_source = ""
        """Which search found the last run's best plan (``""`` without one)."""

    def _search(
        self, domain: object, problem: object, *, anytime: bool, limits: Limits | None = None
    ) -> Iterator[SearchEvent]:
        if not isinstance(domain, Domain) or not isinstance(problem, Problem):
            raise TypeError(f"the temporal planner takes a pddl Domain and Problem, got {type(domain).__name__}")
        self.sources = {SEQUENTIAL: 0, MAKESPAN: 0}
        self.best_source = ""
        bound = Bound()
        timed: list[TimedResult] = []
        streams: deque[tuple[str, Generator[SearchEvent, None, None]]] = deque(
            [
                (
                    SEQUENTIAL,
                    _generator(self.inner.search(*sequential_task(domain, problem), anytime=anytime, limits=limits)),
                )
            ]
        )
        expansions = {SEQUENTIAL: 0, MAKESPAN: 0}
        ended: dict[str, Done] = {}
        best: Plan | None = None
        held: list[Plan] = []  # no_more_steps: makespan plans waiting for the sequential search's first plan
        started = not self.makespan_search
        while streams:
            name, events = streams.popleft()
            event = next(events, None)
            if not started:  # the builtin planner has grounded the sequential task (or failed to)
                started = True
                streams.append((MAKESPAN, self._makespan(domain, problem, anytime, limits, bound, timed)))
                if self.makespan_only and event is not None and not isinstance(event, Done):
                    events.close()
                    ended[SEQUENTIAL] = Done(PlanStatus.SOLVED, 0, "not searched (makespan search only)")
                    continue
            if event is None:
                continue
            expansions[name] = event.expansions
            total = sum(expansions.values())
            if isinstance(event, Done):
                ended[name] = event
                continue
            streams.append((name, events))
            if isinstance(event, Progress):
                yield Progress(total)
                continue
            plan = self._checked(domain, problem, name, event.plan, timed)
            if plan is None:
                continue
            source = name
            if self.no_more_steps and name == MAKESPAN:
                if best is None:
                    held.append(plan)
                    continue
                if len(plan.steps) > len(best.steps):
                    continue
            elif self.no_more_steps and held:  # the sequential search's first plan: the held ones no longer compete
                fewer = min((p for p in held if len(p.steps) <= len(plan.steps)), key=lambda p: p.cost, default=None)
                held.clear()
                if fewer is not None and fewer.cost < plan.cost - 1e-9:
                    plan, source = fewer, MAKESPAN
            if best is None or plan.cost < best.cost - 1e-9:
                best = plan
                ticks = round(plan.cost * TICKS)
                bound.ticks = ticks if bound.ticks is None else min(bound.ticks, ticks)
                yield self._improved(plan, source, total)
        if held:  # the sequential search found no plan: the makespan search's best counts
            best = min(held, key=lambda p: p.cost)
            yield self._improved(best, MAKESPAN, sum(expansions.values()))
        yield self._final(ended, best is not None, sum(expansions.values()))

    def _improved(self, plan: Plan, source: str, expansions: int) -> Improved:
        """``plan`` as the best so far, credited to the search it came from (``sources``, ``best_source``)."""
        self.sources[source] += 1
        self.best_source = source
        return Improved(plan, expansions)

    def _makespan(
        self,
        domain: Domain,
        problem: Problem,
        anytime: bool,
        limits: Limits | None,
        bound: Bound,
        timed: list[TimedResult],
    ) -> Generator[SearchEvent, None, None]:
        """The makespan search's events; a limit or a task it cannot take ends them with a ``Done``."""
        ground = self.inner.last_ground_task
        if ground is None:
            yield Done(PlanStatus.ERROR, 0, "the sequential task was not grounded")
            return
        try:
            task = temporal_task(domain, problem, (PlanStep(op.action, op.args) for op in ground.operators))
        except PlannerError as exc:
            yield Done(PlanStatus.ERROR, 0, str(exc))
            return
        bounding = limits if limits is not None and limits.bounds_search else None
        try:
            yield from makespan_search(
                task, anytime=anytime, limits=bounding, bound=bound, passes=self.makespan_passes, on_plan=timed
            )
        except LimitReached as exc:
            yield Done(exc.status, 0, str(exc))

    def _checked(
        self, domain: Domain, problem: Problem, name: str, plan: Plan, timed: list[TimedResult]
    ) -> Plan | None:
        """The plan with its makespan as its cost (and its timing, from the makespan search), when it validates."""
        if name == MAKESPAN:
            done = timed_schedule(domain, problem, timed[-1].plan)
            result: Plan = ScheduledPlan(tuple(t.step for t in done.plan.steps), done.plan.makespan, done)
        else:
            done = schedule(domain, problem, plan.steps)
            result = Plan(plan.steps, done.plan.makespan)
        checked = validate_temporal_plan(domain, problem, done.plan)
        if not checked.valid:  # a bug: never hand it on
            logger.warning("the %s search's plan does not validate: %s", name, checked.reason)
            return None
        return result

    def _final(self, ended: dict[str, Done], solved: bool, expansions: int) -> Done:
        sequential = ended.get(SEQUENTIAL, Done(PlanStatus.ERROR, 0, "no result"))
        makespan = ended.get(MAKESPAN)
        notes = []
        if sequential.status is PlanStatus.OPTIMAL:  # the sum's proof, not the makespan's
            notes.append("the summed duration is optimal; the makespan is not proven")
        elif sequential.message:
            notes.append(f"sequential search: {sequential.message}")
        if makespan is not None and makespan.message:
            notes.append(f"makespan search: {makespan.message}")
        message = "; ".join(notes)
        if solved:
            return Done(PlanStatus.SOLVED, expansions, message)
        status = sequential.status
        if status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL):  # plans that did not validate
            status = PlanStatus.ERROR
        return Done(status, expansions, message)

    @staticmethod
    def schedule_of(domain: Domain, problem: Problem, plan: Plan) -> Schedule:
        """The timed plan of a plan this planner found."""
        if isinstance(plan, ScheduledPlan) and plan.schedule is not None:
            return plan.schedule
        return schedule(domain, problem, plan.steps)

    @staticmethod
    def timed_plan(domain: Domain, problem: Problem, plan: Plan) -> TemporalPlan:
        """The timed steps of a plan this planner found."""
        return TemporalPlanner.schedule_of(domain, problem, plan).plan


def _generator(events: Iterator[SearchEvent]) -> Generator[SearchEvent, None, None]:
    """``events`` as a generator (closing it closes them)."""
    yield from events


__all__ = ["TemporalPlanner"]
