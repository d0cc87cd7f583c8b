"""The temporal back-end: durative actions planned in sequence by the builtin search, then scheduled.

See :mod:`alica.prophet.temporal`. Each sequential plan the builtin search improves to is
deordered and scheduled; an ``Improved`` event comes for each schedule with a shorter makespan
than every one before, its plan the sequential steps and its cost the makespan
(:meth:`TemporalPlanner.schedule_of` gives the timed plan back).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from alica.prophet.pddl import Domain, Problem
from alica.prophet.planner import Done, Feature, Improved, Limits, Plan, Planner, PlanStatus, SearchEvent
from alica.prophet.search.planner import BuiltinPlanner
from alica.prophet.temporal import Schedule, schedule, sequential_task


class TemporalPlanner(Planner):
    """Durative actions, makespan (see the module docstring); options go to the builtin planner."""

    name = "temporal"
    features = BuiltinPlanner.features | {Feature.DURATIVE_ACTIONS}
    takes_limits = True

    def __init__(self, **options: Any) -> None:
        self.inner = BuiltinPlanner(**options)

    def _search(
        self, domain: object, problem: object, *, anytime: bool, limits: Limits | None = None
    ) -> Iterator[SearchEvent]:
        if not isinstance(domain, Domain) or not isinstance(problem, Problem):
            raise TypeError(f"the temporal planner takes a pddl Domain and Problem, got {type(domain).__name__}")
        best: float | None = None
        for event in self.inner.search(*sequential_task(domain, problem), anytime=anytime, limits=limits):
            if isinstance(event, Improved):
                makespan = schedule(domain, problem, event.plan.steps).plan.makespan
                if best is None or makespan < best:
                    best = makespan
                    yield Improved(Plan(event.plan.steps, makespan), event.expansions)
                continue
            if isinstance(event, Done) and event.status is PlanStatus.OPTIMAL:  # the sum's proof, not the makespan's
                yield Done(
                    PlanStatus.SOLVED, event.expansions, "the summed duration is optimal; the makespan is not proven"
                )
                continue
            yield event

    @staticmethod
    def schedule_of(domain: Domain, problem: Problem, plan: Plan) -> Schedule:
        """The timed plan of a plan this planner found (the schedule is a function of the steps)."""
        return schedule(domain, problem, plan.steps)


__all__ = ["TemporalPlanner"]
