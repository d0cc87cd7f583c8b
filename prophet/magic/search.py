"""One share's search, stepped: read the task, then a few planner events per call.

:class:`ShareSearch` is what the leader and each worker run for a share: the
builtin planner with the share's first search (:class:`FirstSearch`), not
anytime (the first plan ends it), on a clock the caller injects. Each
:meth:`ShareSearch.step` reads the task (the first call) or handles at most
``budget`` planner events, so a caller interleaves its messages with the
search.
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterator

from alica.errors import PlannerError
from alica.prophet.planner import Done, Improved, LimitReached, Limits, Plan, PlanStatus, SearchEvent
from alica.prophet.search.anytime import FirstSearch
from alica.prophet.search.planner import BuiltinPlanner

PROGRESS_EVERY = 50
"""Expansions between two planner events, so one event is a small step of a share's search."""


class ShareSearch:
    """The search of one share until its first plan, in steps.

    Args:
        domain: the PDDL domain text.
        problem: the PDDL problem text.
        search: how the first plan is searched.
        seconds: the time budget on ``clock``, from now; ``None``: none.
        clock: the clock the budget and the duration are measured on.
        memory_mb: the memory bound of the planning (:class:`Limits`); ``None``: none.
        progress_every: expansions between two planner events.

    Attributes:
        plan: the plan found (``None`` until then, or without one).
        status: ``None`` while searching; then ``SOLVED`` or why there is no plan.
        expansions: states expanded so far.
        message: why there is no plan (empty otherwise).
        seconds: how long the search ran on ``clock`` (until it ended, or until now).
    """

    def __init__(
        self,
        domain: str,
        problem: str,
        search: FirstSearch,
        *,
        seconds: float | None = None,
        clock: Callable[[], float],
        memory_mb: float | None = None,
        progress_every: int = PROGRESS_EVERY,
    ) -> None:
        self._texts = (domain, problem)
        self._search = search
        self._clock = clock
        self._limits = Limits(seconds, memory_mb, clock)
        self._progress_every = progress_every
        self._events: Iterator[SearchEvent] | None = None
        self._started = clock()
        self._stopped = False
        self._ended: float | None = None
        self.plan: Plan | None = None
        self.status: PlanStatus | None = None
        self.expansions = 0
        self.message = ""

    @property
    def done(self) -> bool:
        """Whether the search has ended (or was stopped)."""
        return self.status is not None or self._stopped

    def stop(self) -> None:
        """Stop the search for good (its status stays ``None`` if it had not ended)."""
        self._stopped = True
        self._close()

    @property
    def seconds(self) -> float:
        """How long the search ran on its clock."""
        end = self._ended if self._ended is not None else self._clock()
        return end - self._started

    def step(self, budget: int = 1) -> bool:
        """Read the task (on the first call) or handle at most ``budget`` planner events.

        Args:
            budget: planner events to handle, at least 1.

        Returns:
            Whether the search has ended (see :attr:`status`).
        """
        if self.done:
            return True
        if self._events is None:
            self._start()
            return self.done
        for _ in range(max(1, budget)):
            event = next(self._events, None)
            if event is None:  # the events always end with Done; be safe
                self._end(PlanStatus.ERROR, "the search ended without a final event")
                break
            self.expansions = event.expansions
            if isinstance(event, Improved):
                self.plan = event.plan
                self._end(PlanStatus.SOLVED, "")
                break
            if isinstance(event, Done):
                self._end(event.status, event.message)
                break
            if self._limits.expired():
                shown = f"{self._limits.seconds:g} s " if self._limits.seconds is not None else ""
                self._end(PlanStatus.TIMEOUT, f"time limit {shown}reached while searching")
                break
        return self.done

    def _start(self) -> None:
        from alica.prophet.pddl import PddlError, parse_domain, parse_problem  # lazy: the reader only here

        domain_text, problem_text = self._texts
        try:
            domain = parse_domain(domain_text, "<share domain>", self._limits)
            problem = parse_problem(problem_text, "<share problem>", domain, self._limits)
            planner = BuiltinPlanner(progress_every=self._progress_every, first=self._search)
            self._events = planner.search(domain, problem, anytime=False, limits=self._limits)
        except LimitReached as exc:
            self._end(exc.status, str(exc))
        except (PddlError, PlannerError) as exc:
            self._end(PlanStatus.ERROR, str(exc))

    def _end(self, status: PlanStatus, message: str) -> None:
        self.status = status
        self.message = message
        self._ended = self._clock()
        self._close()

    def _close(self) -> None:
        if self._events is not None:
            if isinstance(self._events, Generator):  # a generator holds its grounding until closed
                self._events.close()
            self._events = None

    def __repr__(self) -> str:
        state = "searching" if self.status is None else self.status.value
        return f"<ShareSearch {self._search} {state} {self.expansions} expansions>"
