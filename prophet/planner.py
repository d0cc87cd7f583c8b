"""The planner interface: what a planner supports, and the anytime search as an iterator.

A planner yields :class:`SearchEvent` values while it searches: ``Progress``
now and then (so a caller can stop between two of them: per tick in
simulation, by wall time on a robot), ``Improved`` for every better plan,
and one final ``Done``. :meth:`Planner.solve` drives the iterator to the end
or to a time limit and returns a :class:`PlanResult`.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from enum import Enum

from alica.errors import PlannerError


class Feature(Enum):
    """A PDDL requirement a planner may support."""

    STRIPS = "strips"
    """Positive preconditions and goals, add and delete effects."""
    TYPING = "typing"
    """Typed objects and parameters."""
    NEGATIVE_PRECONDITIONS = "negative-preconditions"
    """``(not ...)`` in preconditions and goals."""
    EQUALITY = "equality"
    """``(= ?x ?y)`` in preconditions."""
    CONDITIONAL_EFFECTS = "conditional-effects"
    """``(when ...)`` in effects."""
    ACTION_COSTS = "action-costs"
    """``(increase (total-cost) n)`` effects and a ``minimize (total-cost)`` metric."""


class PlanStatus(Enum):
    """How a planner's search ended."""

    SOLVED = "solved"
    """A plan was found (it may not be optimal)."""
    OPTIMAL = "optimal"
    """A plan was found and proven optimal."""
    UNSOLVABLE = "unsolvable"
    """No plan exists (proven)."""
    TIMEOUT = "timeout"
    """The budget ran out before a plan was found."""
    ERROR = "error"
    """The planner could not run (the message says why)."""


@dataclass(frozen=True, slots=True)
class PlanStep:
    """One ground action: ``PlanStep("pick-up", ("a",))``."""

    action: str
    args: tuple[str, ...] = ()

    def __str__(self) -> str:
        return f"({' '.join((self.action, *self.args))})"


@dataclass(frozen=True, slots=True)
class Plan:
    """A sequence of ground actions and its cost."""

    steps: tuple[PlanStep, ...]
    cost: float

    def __len__(self) -> int:
        return len(self.steps)


@dataclass(frozen=True, slots=True)
class Progress:
    """The search is still running."""

    expansions: int


@dataclass(frozen=True, slots=True)
class Improved:
    """A plan better than every earlier one."""

    plan: Plan
    expansions: int


@dataclass(frozen=True, slots=True)
class Done:
    """The search ended: ``SOLVED``/``OPTIMAL`` (after its last ``Improved``), ``UNSOLVABLE`` or ``ERROR``."""

    status: PlanStatus
    expansions: int
    message: str = ""


SearchEvent = Progress | Improved | Done


@dataclass(frozen=True, slots=True)
class PlanResult:
    """What a planner run gave.

    Attributes:
        status: how it ended.
        plan: the best plan, if any.
        planner: the planner's name.
        time_first_s: seconds until the first plan (None without a plan).
        time_s: seconds in all.
        expansions: states expanded.
        message: what went wrong, or notes.
    """

    status: PlanStatus
    plan: Plan | None
    planner: str
    time_first_s: float | None
    time_s: float
    expansions: int
    message: str = ""

    @property
    def solved(self) -> bool:
        """Whether there is a plan."""
        return self.plan is not None

    @property
    def cost(self) -> float | None:
        """The plan's cost, if any."""
        return self.plan.cost if self.plan is not None else None


class Planner(ABC):
    """A planner: ``name``, the features it supports, and an anytime search.

    Subclasses implement :meth:`_search`; callers use :meth:`search` (which
    checks the features first) or :meth:`solve`.
    """

    name: str = "planner"
    features: frozenset[Feature] = frozenset({Feature.STRIPS})

    def missing(self, needed: Iterable[Feature]) -> frozenset[Feature]:
        """The needed features this planner lacks."""
        return frozenset(needed) - self.features

    def search(self, domain: object, problem: object, *, anytime: bool = True) -> Iterator[SearchEvent]:
        """The search as events, after checking that the planner supports the task.

        Raises:
            PlannerError: the task needs features the planner lacks (named in the message).
        """
        needed = getattr(domain, "requirements", frozenset()) | getattr(problem, "requirements", frozenset())
        lacking = self.missing(needed)
        if lacking:
            names = ", ".join(sorted(f.value for f in lacking))
            raise PlannerError(
                f"planner '{self.name}' does not support :{names}; use another planner (alica plan --planner ...)"
            )
        return self._search(domain, problem, anytime=anytime)

    @abstractmethod
    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        """The planner's own search (see the module docstring for the events)."""

    def solve(self, domain: object, problem: object, *, time_limit: float = 60.0, anytime: bool = False) -> PlanResult:
        """Run the search until it ends or ``time_limit`` wall seconds pass; the best plan wins."""
        start = time.perf_counter()
        best: Plan | None = None
        first: float | None = None
        expansions = 0
        status = PlanStatus.TIMEOUT
        message = ""
        for event in self.search(domain, problem, anytime=anytime):
            expansions = event.expansions
            if isinstance(event, Improved):
                best = event.plan
                if first is None:
                    first = time.perf_counter() - start
                status = PlanStatus.SOLVED
            elif isinstance(event, Done):
                status = (
                    event.status if event.status is not PlanStatus.SOLVED or best is not None else PlanStatus.SOLVED
                )
                message = event.message
                break
            if time.perf_counter() - start > time_limit:
                status = PlanStatus.SOLVED if best is not None else PlanStatus.TIMEOUT
                break
        return PlanResult(status, best, self.name, first, time.perf_counter() - start, expansions, message)
