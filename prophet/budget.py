"""The leader's search and its budget per tick.

The leader runs the planner as an anytime search (an iterator of events,
:func:`alica.prophet.pipeline.plan_problem`) and advances it a budget per tick:
a number of expansions in simulation (deterministic: the same run plans the
same way), or wall-clock seconds on real robots (:class:`SearchBudget`).
:class:`LeaderSearch` is what the leader keeps of a running search, and
:func:`advance` spends one tick's budget on it.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from alica.prophet.pipeline import Found, ProblemEvent, ProblemPlanning, Rejected, ValidPlan
from alica.prophet.planner import Done, PlanStatus
from alica.prophet.tasks import Literal
from alica.prophet.world import PlanningWorld


@dataclass(frozen=True, slots=True)
class SearchBudget:
    """How much the leader searches per tick.

    Attributes:
        expansions: the search budget per tick, in expansions (deterministic: the same run plans the same way).
        seconds: a wall-time budget per tick instead (for real robots); ``None`` uses ``expansions``.
    """

    expansions: int = 1000
    seconds: float | None = None

    def __post_init__(self) -> None:
        if self.expansions < 1 or (self.seconds is not None and self.seconds <= 0):
            raise ValueError("the planner's budget needs expansions >= 1 and seconds > 0 (or None)")

    def deadline(self) -> float | None:
        """The wall-clock time (``time.perf_counter``) this tick's search ends at; ``None``: count expansions."""
        return time.perf_counter() + self.seconds if self.seconds is not None else None

    def spent(self, expansions: int, deadline: float | None) -> bool:
        """Whether this tick's budget is spent, after ``expansions`` this tick (or at ``deadline``)."""
        if deadline is not None:
            return time.perf_counter() >= deadline
        return expansions >= self.expansions


@dataclass
class LeaderSearch:
    """The leader's running search."""

    generation: int
    world: PlanningWorld
    events: Iterator[ProblemEvent]
    started: float
    expansions: int = 0
    best: ValidPlan | None = None
    shared_cost: float | None = None
    version: int = 0
    goal: tuple[Literal, ...] = ()
    planning: ProblemPlanning | None = None
    """What the search plans (its PDDL): an operator's change of the plan is validated against it."""


def advance(search: LeaderSearch, budget: SearchBudget, warn: Callable[[str], None]) -> Done | None:
    """Advance the search within one tick's budget.

    The search stops early at its first plan (the leader shares it at once). A plan
    the validator rejects is not shared: ``warn`` reports it.

    Args:
        search: the running search (its ``expansions`` and ``best`` are updated).
        budget: the budget per tick.
        warn: reports a message to the operator.

    Returns:
        The Done event when the search ended (a search whose events run out ends
        solved with its best plan, or unsolvable), else ``None``.
    """
    start = search.expansions
    deadline = budget.deadline()
    finished: Done | None = None
    for event in search.events:
        search.expansions = event.expansions
        if isinstance(event, Found):
            search.best = event.plan
            if search.shared_cost is None:
                break  # share the first plan at once
        elif isinstance(event, Rejected):
            warn(f"the planner's plan is invalid and not shared: {event.reason}")
        elif isinstance(event, Done):
            finished = event
            break
        if budget.spent(search.expansions - start, deadline):
            break
    else:
        finished = Done(PlanStatus.SOLVED if search.best is not None else PlanStatus.UNSOLVABLE, search.expansions)
    return finished
