"""MAGiC's messages, the link they travel on, and how the shares differ.

A planning round has three kinds of message, all addressed to one agent
(``to``) and sent to the team: the leader's :class:`Share` to each teammate,
each teammate's :class:`Result`, and the leader's :class:`Final` to each
teammate. With n agents that is at most ``3 * (n - 1)`` messages a round
(IMPERA, Section 8.3).

The messages are frozen dataclasses of plain data (``str``, numbers,
``None``, tuples, and the planner's own value types :class:`PlanStep`,
:class:`PlanStatus` and :class:`FirstSearch`), so a transport can pickle
them with an unpickler that accepts classes of ``alica.`` modules only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from alica.prophet.planner import PlanStatus, PlanStep
from alica.prophet.search.anytime import FirstSearch

SHARE_SEARCHES: tuple[FirstSearch, ...] = (
    FirstSearch(),
    FirstSearch("ff_add_unit"),
    FirstSearch("ff", None, 0),
    FirstSearch("ff_add_unit", 3.0),
)
"""The first searches of shares 0-3: the builtin planner's default (share 0, the
leader's), another heuristic, another tie-breaking, a weight. Share 2's seed and
the seeds of every share from 4 on come from the round's seed (:func:`share_searches`)."""


def share_searches(n: int, seed: int = 0) -> tuple[FirstSearch, ...]:
    """The first search of each of ``n`` shares; share 0 is always the default search.

    Shares 0-3 follow :data:`SHARE_SEARCHES`; share ``i >= 4`` repeats share
    ``i % 4``'s heuristic and weight with the tie-breaking seed ``seed + i``
    (share 2 gets ``seed + 2``), so no two shares search alike.

    Args:
        n: the number of shares (agents), at least 1.
        seed: the round's seed.

    Returns:
        ``n`` first-search settings.

    Raises:
        ValueError: ``n < 1``.
    """
    if n < 1:
        raise ValueError(f"MAGiC needs at least one agent, got {n}")
    searches = []
    for i in range(n):
        base = SHARE_SEARCHES[i % len(SHARE_SEARCHES)]
        tie_break = base.seed is not None or i >= len(SHARE_SEARCHES)
        searches.append(FirstSearch(base.heuristic, base.weight, seed + i if tie_break else None))
    return tuple(searches)


@dataclass(frozen=True, slots=True)
class Share:
    """The leader's share of a round for one teammate: the task and how to search it.

    Attributes:
        round_id: the leader's round number (from 1).
        leader: the leader's agent id.
        worker: the teammate the share is for.
        index: the share's number in the round (0 is the leader's own).
        domain: the PDDL domain as text.
        problem: the PDDL problem as text.
        search: how the first plan is searched.
        seconds: the search's time budget on the worker's clock; ``None``: none.
    """

    round_id: int
    leader: str
    worker: str
    index: int
    domain: str
    problem: str
    search: FirstSearch
    seconds: float | None = None

    @property
    def to(self) -> str:
        """The addressee."""
        return self.worker

    def __repr__(self) -> str:
        return f"<Share r{self.round_id} #{self.index} {self.leader}->{self.worker} {self.search}>"


@dataclass(frozen=True, slots=True)
class Result:
    """A teammate's answer to its share: the first plan it found, or why there is none.

    Attributes:
        round_id: the round of the share.
        leader: the leader (the addressee).
        worker: the teammate that searched.
        index: the share's number.
        steps: the plan's steps, ``None`` without a plan.
        status: ``SOLVED`` with a plan; else ``UNSOLVABLE``, ``TIMEOUT``, ``MEMORY`` or ``ERROR``.
        expansions: states the search expanded.
        seconds: the search's duration on the worker's clock.
        message: why there is no plan (empty otherwise).
    """

    round_id: int
    leader: str
    worker: str
    index: int
    steps: tuple[PlanStep, ...] | None
    status: PlanStatus
    expansions: int
    seconds: float
    message: str = ""

    @property
    def to(self) -> str:
        """The addressee."""
        return self.leader

    def __repr__(self) -> str:
        found = "no plan" if self.steps is None else f"{len(self.steps)} steps"
        return f"<Result r{self.round_id} #{self.index} {self.worker}->{self.leader} {self.status.value} {found}>"


@dataclass(frozen=True, slots=True)
class Final:
    """The round's outcome, sent by the leader to a teammate: the plan, or why there is none.

    A teammate still searching the round stops.

    Attributes:
        round_id: the round.
        leader: the leader.
        worker: the addressee.
        steps: the plan's steps, ``None`` without a plan.
        status: ``SOLVED`` with a plan; else why the round failed.
        cost: the plan's cost as validated by the leader (``None`` without a plan).
        solver: the agent whose share found the plan (``None`` without a plan).
    """

    round_id: int
    leader: str
    worker: str
    steps: tuple[PlanStep, ...] | None
    status: PlanStatus
    cost: float | None = None
    solver: str | None = None

    @property
    def to(self) -> str:
        """The addressee."""
        return self.worker

    def __repr__(self) -> str:
        return f"<Final r{self.round_id} {self.leader}->{self.worker} {self.status.value}>"


MagicMessage = Share | Result | Final
"""A message of the protocol."""


@runtime_checkable
class MagicLink(Protocol):
    """How a MAGiC agent reaches its team (an adapter over a transport, or the engine's messaging).

    Attributes:
        name: this agent's id.
    """

    @property
    def name(self) -> str:
        """This agent's id."""
        ...

    def send(self, payload: MagicMessage) -> None:
        """Send a message to the team, reliably and in order per receiver (the addressee is ``payload.to``)."""
        ...

    def receive(self) -> list[object]:
        """The payloads that arrived since the last call, oldest first (anything, not only MAGiC's)."""
        ...

    def reachable(self) -> frozenset[str]:
        """The teammates this agent hears from now (never itself)."""
        ...


@dataclass(slots=True)
class MessageCounts:
    """The MAGiC messages one agent sent and received in its current round.

    Attributes:
        shares_sent: shares sent (the leader).
        results_sent: results sent (a worker).
        finals_sent: finals sent (the leader).
        shares_received: shares received (a worker).
        results_received: results received (the leader).
        finals_received: finals received (a worker).
        ignored: messages of an older round or another addressee's, and payloads that are no MAGiC message.
    """

    shares_sent: int = 0
    results_sent: int = 0
    finals_sent: int = 0
    shares_received: int = 0
    results_received: int = 0
    finals_received: int = 0
    ignored: int = 0

    @property
    def sent(self) -> int:
        """Messages sent in the round."""
        return self.shares_sent + self.results_sent + self.finals_sent

    @property
    def received(self) -> int:
        """Messages of the round received."""
        return self.shares_received + self.results_received + self.finals_received
