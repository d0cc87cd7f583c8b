"""MAGiC inside a team: the leader's planning split over the teammates in the planning problem's state.

With parallel planning on (``engine_config(parallel_planning=True)``), the
leader of a planning problem (:mod:`alica.prophet.runtime`) does not search
alone: it starts a MAGiC round over the agents in the problem's state (the
teammates that run the WaitPlan meanwhile), each searching one share in its
own engine, in its own process when the team runs as processes. Messages
travel on the planning topic through the engine's child seam
(:meth:`~alica.engine.child.ChildHost.publish`); the agent's
:class:`TeamMagic` sorts them: results to the leader, shares and finals to
the agent's :class:`~alica.prophet.magic.worker.MagicWorker`, which searches
a bounded amount every tick while its agent is in the state.

The first valid plan of the round is the plan the leader shares (no anytime
improvement afterwards: the first result wins, as in IMPERA).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable

from alica.engine.child import ChildHost
from alica.prophet.magic.messages import Final, MagicMessage, Result, Share
from alica.prophet.magic.worker import MagicWorker

STEP_EXPANSIONS = 100
"""Expansions of one MAGiC search step (a planner event); a tick's budget is a number of these."""


class HostLink:
    """A :class:`~alica.prophet.magic.messages.MagicLink` over an agent's child host.

    Args:
        host: the agent's engine, as the child seam shows it.
        inbox: where :class:`TeamMagic` puts the messages for this side.
        members: the agents that can take part now (in the problem's state).
    """

    def __init__(self, host: ChildHost, inbox: list[object], members: Callable[[], Iterable[str]]) -> None:
        self._host = host
        self._inbox = inbox
        self.members = members

    @property
    def name(self) -> str:
        """The agent's id."""
        return self._host.name

    def send(self, payload: MagicMessage) -> None:
        """To the team, on the planning topic (reliable)."""
        self._host.publish(payload)

    def receive(self) -> list[object]:
        """What arrived for this side since the last call."""
        out = list(self._inbox)
        self._inbox.clear()
        return out

    def reachable(self) -> frozenset[str]:
        """The other agents in the problem's state."""
        return frozenset(self.members()) - {self.name}


class TeamMagic:
    """One agent's part in MAGiC rounds: its worker and the leader's inbox.

    Args:
        host: the agent's engine, as the child seam shows it.
        expansions: the worker's search budget per tick, in expansions.
        seconds: a wall-time budget per tick instead (real robots); ``None`` uses ``expansions``.
    """

    def __init__(self, host: ChildHost, expansions: int, seconds: float | None) -> None:
        self.host = host
        self.expansions = expansions
        self.seconds = seconds
        self.leader_inbox: list[object] = []
        self._worker_inbox: list[object] = []
        self._members: Callable[[], Iterable[str]] = tuple
        self.worker = MagicWorker(
            HostLink(host, self._worker_inbox, self._current_members),
            clock=host.now,
            progress_every=STEP_EXPANSIONS,
        )

    def _current_members(self) -> Iterable[str]:
        return self._members()

    def receive(self, payload: object) -> bool:
        """Take a MAGiC message addressed to this agent; whether it was one (of any address)."""
        if isinstance(payload, Result):
            if payload.to == self.host.name:
                self.leader_inbox.append(payload)
            return True
        if isinstance(payload, Share | Final):
            if payload.to == self.host.name:
                self._worker_inbox.append(payload)
            return True
        return False

    def leader_link(self, members: Callable[[], Iterable[str]]) -> HostLink:
        """The link of this agent's leader side, over the agents ``members`` gives."""
        self.leader_inbox.clear()
        return HostLink(self.host, self.leader_inbox, members)

    def tick(self, members: Callable[[], Iterable[str]]) -> None:
        """Search this tick's budget of a teammate's share (if one came), and answer when done."""
        self._members = members
        worker = self.worker
        if not worker.searching and not self._worker_inbox:
            return
        if self.seconds is None:
            worker.step(max(1, self.expansions // STEP_EXPANSIONS))
            return
        deadline = time.perf_counter() + self.seconds
        worker.step(1)
        while worker.searching and time.perf_counter() < deadline:
            worker.step(1)
