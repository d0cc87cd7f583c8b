"""MAGiC's leader: split the task into one share per agent, search its own, take the first valid plan.

A round (:meth:`MagicLeader.start`) gives each of the n agents one share of
the same task, each with its own first search (:func:`share_searches`):
share 0, the builtin planner's default search, is the leader's own; the
others go to the teammates, one :class:`Share` each. :meth:`MagicLeader.step`
handles what arrived and steps the leader's own search. The first valid
plan, the leader's or a teammate's (checked with
:func:`~alica.prophet.validate.validate_plan`), ends the round: every
teammate that got a share gets a :class:`Final`, which stops its search. A
round thus takes at most n-1 shares, n-1 results and n-1 finals.

A teammate that is no longer reachable (:meth:`MagicLink.reachable`) before
it answered is not waited for: the leader **takes its share over**, searching
it itself once its own search has ended without a plan, which costs no
message. A teammate unreachable when the round starts gets no share; the
leader takes that share over the same way. A late answer of such a teammate
still counts (a valid plan ends the round; a failure spares the leader the
share). A share proven unsolvable ends the round (every share searches the
same task); when every share has failed otherwise, the round ends with the
failure: ``TIMEOUT`` before ``MEMORY`` before ``ERROR``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from alica.prophet.magic.messages import Final, MagicLink, MessageCounts, Result, Share, share_searches
from alica.prophet.magic.search import PROGRESS_EVERY, ShareSearch
from alica.prophet.planner import Plan, PlanStatus, PlanStep
from alica.prophet.search.anytime import FirstSearch

FAILURE_ORDER = (PlanStatus.TIMEOUT, PlanStatus.MEMORY, PlanStatus.ERROR)
"""The status of a round whose every share failed, in this order of precedence (``UNSOLVABLE`` ends it at once)."""


@dataclass(frozen=True, slots=True)
class RoundOutcome:
    """How a MAGiC round ended, as the leader saw it.

    Attributes:
        round_id: the round.
        status: ``SOLVED`` with a plan; else ``UNSOLVABLE``, ``TIMEOUT``, ``MEMORY`` or ``ERROR``.
        plan: the validated plan (its cost from the validation), or ``None``.
        solver: the agent that found the plan (the leader for a share it took over).
        index: the share that found the plan.
        search: that share's first search.
        agents: the agents of the round, the leader first (share ``i`` went to ``agents[i]``).
        shared: the teammates that got a share.
        informed: the teammates that got a final.
        lost: teammates not waited for (unreachable before they answered).
        taken_over: the shares the leader searched after its own.
        sent: MAGiC messages the leader sent in the round (shares and finals).
        received: results of the round the leader received until it ended.
        started: the leader's clock at the start.
        ended: the leader's clock at the end (when the plan was taken, for a solved round).
        expansions: states the leader's own searches expanded.
        message: why there is no plan (empty otherwise).
    """

    round_id: int
    status: PlanStatus
    plan: Plan | None
    solver: str | None
    index: int | None
    search: FirstSearch | None
    agents: tuple[str, ...]
    shared: tuple[str, ...]
    informed: tuple[str, ...]
    lost: tuple[str, ...]
    taken_over: tuple[int, ...]
    sent: int
    received: int
    started: float
    ended: float
    expansions: int
    message: str = ""

    @property
    def cost(self) -> float | None:
        """The plan's cost, if any."""
        return None if self.plan is None else self.plan.cost

    @property
    def messages(self) -> int:
        """The round's messages seen by the leader: every one is to or from it."""
        return self.sent + self.received

    @property
    def seconds(self) -> float:
        """From the start to the end, on the leader's clock."""
        return self.ended - self.started


class MagicLeader:
    """The leader's side of MAGiC (see the module docstring).

    Args:
        link: how the leader reaches the team.
        domain: the PDDL domain as text.
        problem: the PDDL problem as text.
        seed: the seed of the shares' tie-breaking (:func:`share_searches`).
        seconds: each share's time budget on its searcher's clock; ``None``: none.
        clock: the leader's clock (the budget of its own searches, the outcome's times).
        memory_mb: the memory bound of the leader's own searches; ``None``: none.
        progress_every: expansions between two planner events (one search step).
        first_round: the number of the first round; a leader that is made anew for each
            planning run (the planning runtime, one per generation) gives numbers that keep
            growing, so its teammates take each new round's share as newer.

    Raises:
        PddlError: the domain or the problem is not valid PDDL.
    """

    def __init__(
        self,
        link: MagicLink,
        domain: str,
        problem: str,
        *,
        seed: int = 0,
        seconds: float | None = None,
        clock: Callable[[], float] = time.monotonic,
        memory_mb: float | None = None,
        progress_every: int = PROGRESS_EVERY,
        first_round: int = 1,
    ) -> None:
        from alica.prophet.pddl import parse_domain, parse_problem  # lazy: the reader only here

        parsed_domain = parse_domain(domain, "<magic domain>")
        self._task = (parsed_domain, parse_problem(problem, "<magic problem>", parsed_domain))
        self._link = link
        self._texts = (domain, problem)
        self._seed = seed
        self._seconds = seconds
        self._clock = clock
        self._memory_mb = memory_mb
        self._progress_every = progress_every
        if first_round < 1:
            raise ValueError(f"MAGiC rounds count from 1, got first_round={first_round}")
        self._round = first_round - 1
        self._first = first_round
        self._agents: tuple[str, ...] = ()
        self._shares: tuple[FirstSearch, ...] = ()
        self._pending: dict[int, str] = {}
        self._failed: dict[int, tuple[PlanStatus, str]] = {}
        self._queue: list[int] = []
        self._lost: list[str] = []
        self._taken_over: list[int] = []
        self._sent_to: set[str] = set()
        self._own: ShareSearch | None = None
        self._own_index = 0
        self._expansions = 0
        self._started = 0.0
        self.counts = MessageCounts()
        """The MAGiC messages of the current round."""
        self.outcome: RoundOutcome | None = None
        """The current round's outcome once it has ended."""

    @property
    def name(self) -> str:
        """The leader's agent id."""
        return self._link.name

    @property
    def round_id(self) -> int:
        """The current round (0 before the first)."""
        return self._round

    @property
    def running(self) -> bool:
        """Whether a round is on and has not ended."""
        return self._round >= self._first and self.outcome is None

    @property
    def idle(self) -> bool:
        """Whether the leader has nothing of its own to search now (it waits for its teammates' results)."""
        return self._own is None and not self._queue

    def start(self, agents: Sequence[str]) -> int:
        """Start a round over ``agents`` (the leader among them): one share each.

        A round still running is abandoned (its teammates stop on the new round's shares;
        those unreachable now get none and stay on the old one until they hear of a newer round).

        Args:
            agents: the team's agent ids, each once, the leader included; the
                teammates get shares 1, 2, ... in this order.

        Returns:
            The new round's number.

        Raises:
            ValueError: ``agents`` repeats an id or lacks the leader.
        """
        agents = tuple(agents)
        if len(set(agents)) != len(agents):
            raise ValueError(f"MAGiC agents must be distinct, got {list(agents)}")
        if self.name not in agents:
            raise ValueError(f"the leader {self.name!r} must be one of the agents {list(agents)}")
        if self._own is not None:
            self._own.stop()
        self._round += 1
        self._agents = (self.name, *(a for a in agents if a != self.name))
        self._shares = share_searches(len(self._agents), self._seed)
        self._pending, self._failed, self._queue = {}, {}, []
        self._lost, self._taken_over = [], []
        self._sent_to = set()
        self._expansions = 0
        self.counts = MessageCounts()
        self.outcome = None
        self._started = self._clock()
        reachable = self._link.reachable()
        for index, worker in enumerate(self._agents[1:], 1):
            if worker in reachable:
                self._link.send(self._share(index))
                self.counts.shares_sent += 1
                self._pending[index] = worker
                self._sent_to.add(worker)
            else:
                self._lost.append(worker)
                self._queue.append(index)
        self._begin(0)
        return self._round

    def step(self, budget: int = 1) -> RoundOutcome | None:
        """Handle what arrived, then search at most ``budget`` planner events of the leader's share.

        Args:
            budget: planner events of the leader's own search, at least 1.

        Returns:
            The round's outcome once it has ended, else ``None``.
        """
        for payload in self._link.receive():
            self._receive(payload)
        if not self.running:
            return self.outcome
        reachable = self._link.reachable()
        for index, worker in list(self._pending.items()):
            if worker not in reachable:
                del self._pending[index]
                self._lost.append(worker)
                self._queue.append(index)
        if self._own is None and self._queue:
            self._begin(self._queue.pop(0))
        own = self._own
        if own is not None:
            before = own.expansions
            own.step(budget)
            self._expansions += own.expansions - before
            if own.done:
                self._own = None
                if own.plan is not None:
                    self._take(own.plan.steps, self.name, self._own_index)
                else:
                    self._fail(self._own_index, own.status or PlanStatus.ERROR, own.message)
        if self.running and self._own is None and not self._queue and not self._pending:
            self._end_failed()
        return self.outcome

    # ------------------------------------------------------------------ internals

    def _share(self, index: int) -> Share:
        domain, problem = self._texts
        worker = self._agents[index]
        return Share(self._round, self.name, worker, index, domain, problem, self._shares[index], self._seconds)

    def _begin(self, index: int) -> None:
        if index:
            self._taken_over.append(index)
        self._own_index = index
        domain, problem = self._texts
        self._own = ShareSearch(
            domain,
            problem,
            self._shares[index],
            seconds=self._seconds,
            clock=self._clock,
            memory_mb=self._memory_mb,
            progress_every=self._progress_every,
        )

    def _receive(self, payload: object) -> None:
        if (
            not isinstance(payload, Result)
            or payload.to != self.name
            or payload.round_id != self._round
            or not 0 < payload.index < len(self._agents)
            or self._agents[payload.index] != payload.worker
        ):
            self.counts.ignored += 1
            return
        self.counts.results_received += 1
        if not self.running:
            return
        self._pending.pop(payload.index, None)
        if payload.index in self._queue:
            self._queue.remove(payload.index)
        if payload.steps is not None:
            self._take(payload.steps, payload.worker, payload.index)
        else:
            self._fail(payload.index, payload.status, payload.message)

    def _take(self, steps: tuple[PlanStep, ...], solver: str, index: int) -> None:
        """End the round with this plan if it is valid; else count the share as failed."""
        from alica.prophet.validate import validate_plan  # lazy: the validator only here

        check = validate_plan(self._task, steps)
        if not check.valid:
            self._fail(index, PlanStatus.ERROR, f"{solver}'s plan is not valid: {check.reason}")
            return
        self._finish(PlanStatus.SOLVED, Plan(steps, check.cost), solver, index, "")

    def _fail(self, index: int, status: PlanStatus, message: str) -> None:
        self._failed[index] = (status, message)
        if status is PlanStatus.UNSOLVABLE:
            self._finish(status, None, None, None, message)

    def _end_failed(self) -> None:
        statuses = [status for status, _ in self._failed.values()]
        status = next((s for s in FAILURE_ORDER if s in statuses), PlanStatus.ERROR)
        message = next((m for s, m in self._failed.values() if s is status and m), "every share failed")
        self._finish(status, None, None, None, message)

    def _finish(
        self, status: PlanStatus, plan: Plan | None, solver: str | None, index: int | None, message: str
    ) -> None:
        if self._own is not None:
            self._own.stop()
        self._own = None
        self._queue = []
        self._pending = {}
        reachable = self._link.reachable()
        steps = None if plan is None else plan.steps
        cost = None if plan is None else plan.cost
        informed = []
        for worker in self._agents[1:]:
            if worker in self._sent_to and (worker not in self._lost or worker in reachable):
                self._link.send(Final(self._round, self.name, worker, steps, status, cost, solver))
                self.counts.finals_sent += 1
                informed.append(worker)
        self.outcome = RoundOutcome(
            self._round,
            status,
            plan,
            solver,
            index,
            None if index is None else self._shares[index],
            self._agents,
            tuple(w for w in self._agents if w in self._sent_to),
            tuple(informed),
            tuple(self._lost),
            tuple(self._taken_over),
            self.counts.sent,
            self.counts.received,
            self._started,
            self._clock(),
            self._expansions,
            message,
        )

    def __repr__(self) -> str:
        state = "idle" if self._round < self._first else ("running" if self.running else "ended")
        return f"<MagicLeader {self.name} round {self._round} {state}>"
