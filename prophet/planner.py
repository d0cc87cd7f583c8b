"""The planner interface: what a planner supports, and the anytime search as an iterator.

A planner yields :class:`SearchEvent` values while it searches: ``Progress``
now and then (so a caller can stop between two of them: per tick in
simulation, by wall time on a robot), ``Improved`` for every better plan,
and one final ``Done``. :meth:`Planner.solve` drives the iterator to the end
or to a time limit and returns a :class:`PlanResult`.

:class:`Limits` bound a whole planning run, reading and grounding included: a
deadline on a clock and a memory bound. Whoever does work that can grow with
the input (the PDDL reader, the grounding, the search) calls
:meth:`Limits.check` every so many items; past the deadline, or when the
estimated size passes the bound (with ``whole_process``, also when the
process's resident memory does), it raises :class:`LimitReached`, whose
message names the stage. :meth:`Planner.search` turns it into a final
``Done`` (``TIMEOUT`` or ``MEMORY``), so a caller stepping the search never
sees the exception.
"""

from __future__ import annotations

import gc
import os
import sys
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from alica.errors import PlannerError

if TYPE_CHECKING:
    from alica.prophet.ground import GroundTask


@contextmanager
def collector_paused() -> Iterator[None]:
    """The cyclic garbage collector off while reading or grounding.

    Both make many objects and no cycles; the collector's full passes over every
    object of the process would cost a good part of their time on large tasks.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


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
    DERIVED_PREDICATES = "derived-predicates"
    """``(:derived ...)`` rules: predicates that are a function of the others, never in effects or ``:init``."""
    DURATIVE_ACTIONS = "durative-actions"
    """``(:durative-action ...)`` with a fixed or function duration, ``at start``/``over all``/``at end``
    conditions and ``at start``/``at end`` effects; the metric ``(total-time)``, the makespan."""


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
    MEMORY = "memory"
    """The memory bound (:class:`Limits`) was reached before a plan was found."""


DEFAULT_MEMORY_MB = 2048
"""The memory bound of planning when none is given (``alica plan``, the runtime's planning)."""


RESIDENT_EVERY_S = 0.01
"""Seconds between two reads of the process's resident memory by :meth:`Limits.check`."""


def resident_bytes() -> int:
    """This process's resident memory now (Linux: ``/proc/self/statm``); elsewhere its peak so far."""
    try:
        with open("/proc/self/statm", "rb") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        import resource  # POSIX only; Linux reads /proc above

        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return int(peak if sys.platform == "darwin" else peak * 1024)  # bytes on macOS, KiB elsewhere


class LimitReached(PlannerError):
    """A planning limit was reached.

    Attributes:
        stage: what was running (``reading the problem``, ``grounding``, ``searching``).
        kind: ``"time"`` or ``"memory"``.
        expansions: the search's expansions so far, when it was searching (else 0).
    """

    def __init__(self, message: str, stage: str, kind: str, expansions: int = 0) -> None:
        super().__init__(message)
        self.stage = stage
        self.kind = kind
        self.expansions = expansions

    @property
    def status(self) -> PlanStatus:
        """``TIMEOUT`` or ``MEMORY``."""
        return PlanStatus.TIMEOUT if self.kind == "time" else PlanStatus.MEMORY


@dataclass(slots=True)
class Limits:
    """A deadline and a memory bound for one planning run.

    Attributes:
        seconds: the time limit (for messages); ``None``: no deadline.
        memory_mb: the memory bound in MB; ``None``: none.
        clock: the clock the deadline is on (injected in tests).
        deadline: ``clock()`` at the start plus ``seconds``.
        bounds_search: whether the deadline also bounds the search (checked every few expansions); False
            when it bounds reading and grounding only and the caller budgets the search between its
            events (the runtime plans a little every tick, in simulated time).
        whole_process: whether the memory bound holds for the whole process's resident memory
            (measured, at most every :data:`RESIDENT_EVERY_S`), not only for the stages' estimates:
            ``alica plan``, a process that only plans. The runtime plans inside a robot's process
            and bounds the estimates.
    """

    seconds: float | None = None
    memory_mb: float | None = None
    clock: Callable[[], float] = time.monotonic
    deadline: float | None = field(default=None)
    bounds_search: bool = True
    whole_process: bool = False
    _resident: int = field(default=0, repr=False)
    _resident_at: float = field(default=float("-inf"), repr=False)

    def __post_init__(self) -> None:
        if self.deadline is None and self.seconds is not None:
            self.deadline = self.clock() + self.seconds

    @property
    def memory_bytes(self) -> float | None:
        """The memory bound in bytes."""
        return None if self.memory_mb is None else self.memory_mb * 1024 * 1024

    def resident(self) -> int:
        """The process's resident bytes (read at most every :data:`RESIDENT_EVERY_S`); 0 unless ``whole_process``."""
        if not self.whole_process:
            return 0
        now = time.monotonic()
        if now - self._resident_at >= RESIDENT_EVERY_S:
            self._resident, self._resident_at = resident_bytes(), now
        return self._resident

    def room_bytes(self) -> float | None:
        """What a stage may still allocate under the bound (``None`` without one): the bound, less the
        process's resident memory with ``whole_process``."""
        bound = self.memory_bytes
        if bound is None or not self.whole_process:
            return bound
        self._resident_at = float("-inf")
        return max(0.0, bound - self.resident())

    def remaining(self) -> float | None:
        """Seconds left before the deadline (0 when past), ``None`` without one."""
        return None if self.deadline is None else max(0.0, self.deadline - self.clock())

    def expired(self) -> bool:
        """Whether the deadline has passed."""
        return self.deadline is not None and self.clock() >= self.deadline

    def check(self, stage: str, estimate_bytes: float = 0.0, done: str = "", reserve: float = 0.0) -> None:
        """Raise :class:`LimitReached` past the deadline, or when ``estimate_bytes`` passes the bound
        (with ``whole_process``, also when the process's resident memory does).

        Args:
            stage: what is running, for the message (``grounding``).
            estimate_bytes: the memory the stage is estimated to need so far.
            done: how far it got, for the message (``120000 ground actions``).
            reserve: seconds the stage needs to give up (freeing what it built): it stops that much earlier.
        """
        bound = self.memory_bytes
        more = f" ({done})" if done else ""
        if bound is not None and max(estimate_bytes, self.resident()) > bound:
            what = f"the process needs more than {self.memory_mb:g} MB while {stage}{more}"
            if estimate_bytes > bound:
                what = f"{stage} needs more than {self.memory_mb:g} MB{more}"
            raise LimitReached(
                f"{what}; raise --memory-limit or make the problem smaller",
                stage,
                "memory",
            )
        if self.deadline is not None and self.clock() + reserve >= self.deadline:
            shown = f"{self.seconds:g} s " if self.seconds is not None else ""
            raise LimitReached(f"time limit {shown}reached while {stage}{more}", stage, "time")


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


@runtime_checkable
class _Requiring(Protocol):
    """A task half that says which features it needs (a PDDL :class:`~alica.prophet.pddl.Domain` or
    ``Problem``); other planners' tasks (RDDL) need none the planner checks here."""

    @property
    def requirements(self) -> frozenset[Feature]: ...


class Planner(ABC):
    """A planner: ``name``, the features it supports, and an anytime search.

    Subclasses implement :meth:`_search`; callers use :meth:`search` (which
    checks the features first) or :meth:`solve`.
    """

    name: str = "planner"
    features: frozenset[Feature] = frozenset({Feature.STRIPS})
    takes_limits: bool = False
    """Whether :meth:`_search` takes ``limits`` (and checks them while it grounds and searches)."""
    stepwise: bool = False
    """Whether its plan is only the next step of a policy (ProTaP): each step is meant for the robot it
    names, and once the step is over the runtime plans the next one from the world as it is then."""
    reads_positions: bool = False
    """Whether its constructor takes ``positions`` (object -> position in metres, the world model's ``pos``)."""
    first_plan_waits: bool = False
    """Whether a team waits a little for a better first plan (the leader shares it when the search ends or
    after one UpdateTime): its first plan seldom is its best, and execution ends the search."""
    reads_files: bool = False
    """Whether :meth:`solve` takes the PDDL files' paths rather than the parsed domain and problem
    (a back-end that runs an outside planner on the files, such as Fast Downward)."""
    last_ground_task: GroundTask | None = None
    """The ground task of the last search, for a planner that grounds the task itself (``None``
    otherwise): ``alica plan`` checks the plan on it, a cheaper check than the lifted one."""

    @staticmethod
    def unavailable() -> str:
        """Why this back-end cannot run here (beyond its module: e.g. a planner binary that is not
        installed), or ``""`` when it can; a back-end that needs more overrides it."""
        return ""

    def missing(self, needed: Iterable[Feature]) -> frozenset[Feature]:
        """The needed features this planner lacks."""
        return frozenset(needed) - self.features

    def search(
        self, domain: object, problem: object, *, anytime: bool = True, limits: Limits | None = None
    ) -> Iterator[SearchEvent]:
        """The search as events, after checking that the planner supports the task.

        With ``limits``, a limit reached (while grounding, say) ends the events with
        ``Done(TIMEOUT)`` or ``Done(MEMORY)`` whose message names the stage.

        Raises:
            PlannerError: the task needs features the planner lacks (named in the message).
        """
        needed = frozenset[Feature]().union(*(t.requirements for t in (domain, problem) if isinstance(t, _Requiring)))
        lacking = self.missing(needed)
        if lacking:
            names = ", ".join(sorted(f.value for f in lacking))
            raise PlannerError(
                f"planner '{self.name}' does not support :{names}; use another planner (alica plan --planner ...)"
            )
        if self.takes_limits:
            events = self._search(domain, problem, anytime=anytime, limits=limits)  # type: ignore[call-arg]
        else:
            events = self._search(domain, problem, anytime=anytime)
        return _limited(events)

    @abstractmethod
    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        """The planner's own search (see the module docstring for the events)."""

    def solve(
        self,
        domain: object,
        problem: object,
        *,
        time_limit: float = 60.0,
        anytime: bool = False,
        limits: Limits | None = None,
    ) -> PlanResult:
        """Run the search until it ends or ``time_limit`` wall seconds pass; the best plan wins.

        ``limits`` (when given, instead of ``time_limit``) may have started earlier, e.g. before reading.
        """
        if limits is None:
            limits = Limits(time_limit)
        start = time.perf_counter()
        best: Plan | None = None
        first: float | None = None
        expansions = 0
        status = PlanStatus.TIMEOUT
        message = ""
        for event in self.search(domain, problem, anytime=anytime, limits=limits):
            expansions = event.expansions
            if isinstance(event, Improved):
                best = event.plan
                if first is None:
                    first = time.perf_counter() - start
                status = PlanStatus.SOLVED
            elif isinstance(event, Done):
                status = event.status
                if best is not None and status in (PlanStatus.TIMEOUT, PlanStatus.MEMORY):
                    status = PlanStatus.SOLVED  # a limit reached after a plan: that plan stands
                message = event.message
                break
            if limits.expired():
                status = PlanStatus.SOLVED if best is not None else PlanStatus.TIMEOUT
                if best is None:
                    shown = f"{limits.seconds:g} s " if limits.seconds is not None else ""
                    message = f"time limit {shown}reached while searching"
                break
        return PlanResult(status, best, self.name, first, time.perf_counter() - start, expansions, message)


def _limited(events: Iterator[SearchEvent]) -> Iterator[SearchEvent]:
    """``events``, a :class:`LimitReached` turned into the final ``Done``."""
    expansions = 0
    try:
        for event in events:
            expansions = event.expansions
            yield event
    except LimitReached as exc:
        yield Done(exc.status, max(expansions, exc.expansions), str(exc))
