"""Synchronised transitions: the agents involved fire together or not at all.

Each agent whose synchronised transition's condition holds sends a
:class:`SyncTalk` with its row: the transition, whether the condition holds,
and the agents whose holding rows it has seen (its acknowledgements). The
synchronisation is complete, in an agent's view, when every transition of
the synchronisation has a holding row and every holder has acknowledged
every other holder (an agent's own acknowledgements count once it has sent
them). Then each holder fires on its own next tick, so with the
same messages all fire in the same tick. A synchronisation that is not
complete ``sync_timeout`` seconds after the agent's condition began to hold
fails the plan (``fail_on_timeout``) or starts over.

:class:`SyncTable` keeps an agent's processes, one per plan instance and
synchronisation, while the agent is in the state that holds them.
"""

from __future__ import annotations

from dataclasses import dataclass

from alica.engine.team import PlanKey
from alica.model import Plan, Synchronisation


@dataclass(frozen=True, slots=True)
class SyncTalk:
    """One agent's row of a synchronisation."""

    sender: str
    key: PlanKey
    sync: str
    transition: str
    holds: bool
    acks: tuple[str, ...]
    sent_at: float


@dataclass(slots=True)
class _Row:
    transition: str
    holds: bool
    acks: frozenset[str]
    heard: float


class SyncProcess:
    """One agent's view of one synchronisation in one plan instance.

    Args:
        me: the agent.
        key: the plan instance.
        sync: the synchronisation of the model.
        expiry: seconds after which a teammate's row without news is dropped.
    """

    def __init__(self, me: str, key: PlanKey, sync: Synchronisation, expiry: float) -> None:
        self.me = me
        self.key = key
        self.sync = sync
        self.expiry = expiry
        self.rows: dict[str, _Row] = {}
        self.holding_since: float | None = None
        self.last_talk = -1e18
        self.last_sent: SyncTalk | None = None

    def update_mine(self, transition: str, holds: bool, now: float) -> None:
        """Record my own row."""
        if holds and self.holding_since is None:
            self.holding_since = now
        if not holds:
            self.holding_since = None
        acks = frozenset(a for a, r in self.rows.items() if a != self.me and r.holds)
        self.rows[self.me] = _Row(transition, holds, acks, now)

    def receive(self, talk: SyncTalk, now: float) -> None:
        """Take in a teammate's row."""
        self.rows[talk.sender] = _Row(talk.transition, talk.holds, frozenset(talk.acks), now)
        mine = self.rows.get(self.me)
        if mine is not None and talk.holds and talk.sender not in mine.acks:
            mine.acks = mine.acks | {talk.sender}

    def expire(self, now: float) -> None:
        """Drop teammates' rows that have not been refreshed."""
        for agent in [a for a, r in self.rows.items() if a != self.me and now - r.heard > self.expiry]:
            del self.rows[agent]
        mine = self.rows.get(self.me)
        if mine is not None:
            mine.acks = frozenset(a for a in mine.acks if a in self.rows)

    def complete(self) -> bool:
        """Whether every synchronised transition has a holder and all holders acknowledged each other."""
        holders = {a for a, r in self.rows.items() if r.holds}
        if self.me not in holders:
            return False
        covered = {self.rows[a].transition for a in holders}
        if not all(t in covered for t in self.sync.transitions):
            return False
        sent = self.last_sent
        if sent is None or not sent.holds:
            return False
        # My own acknowledgements count only once sent: the others must see them too.
        mine = frozenset(sent.acks)
        return all(holders <= ((mine if a == self.me else self.rows[a].acks) | {a}) for a in holders)

    def timed_out(self, now: float) -> bool:
        """Whether my condition has held for longer than the synchronisation's timeout."""
        return self.holding_since is not None and now - self.holding_since > self.sync.sync_timeout

    def talk(self, now: float) -> SyncTalk | None:
        """The row to send now, or None when nothing changed and the talk timeout has not passed."""
        mine = self.rows.get(self.me)
        if mine is None:
            return None
        talk = SyncTalk(self.me, self.key, self.sync.name, mine.transition, mine.holds, tuple(sorted(mine.acks)), now)
        previous = self.last_sent
        same = previous is not None and (previous.transition, previous.holds, previous.acks) == (
            talk.transition,
            talk.holds,
            talk.acks,
        )
        if same and now - self.last_talk < self.sync.talk_timeout:
            return None
        self.last_talk = now
        self.last_sent = talk
        return talk

    def reset(self) -> None:
        """Start over (after a timeout without failure)."""
        self.rows.clear()
        self.holding_since = None
        self.last_sent = None


class SyncTable:
    """One agent's synchronisation processes, by plan instance and synchronisation name.

    Args:
        me: the agent.
        period: seconds between two engine ticks (a process forgets silent rows after at least four).
    """

    def __init__(self, me: str, period: float) -> None:
        self.me = me
        self.period = period
        self.processes: dict[tuple[PlanKey, str], SyncProcess] = {}

    def process(self, key: PlanKey, plan: Plan, name: str) -> SyncProcess:
        """This agent's process of synchronisation ``name`` of ``plan`` in the plan instance ``key``."""
        process = self.processes.get((key, name))
        if process is None:
            sync = next(s for s in plan.synchronisations if s.name == name)
            expiry = max(4 * sync.talk_timeout, 4 * self.period)
            process = self.processes[(key, name)] = SyncProcess(self.me, key, sync, expiry)
        return process

    def drop(self, key: PlanKey) -> None:
        """The agent left the state of plan instance ``key``: forget its synchronisations."""
        for found in [k for k in self.processes if k[0] == key]:
            del self.processes[found]

    def receive(self, talk: SyncTalk, plan: Plan, now: float) -> None:
        """A teammate's row for the instance of ``plan`` that this agent runs (ignored for no such synchronisation)."""
        if any(s.name == talk.sync for s in plan.synchronisations):
            self.process(talk.key, plan, talk.sync).receive(talk, now)

    def talk(self, now: float) -> list[SyncTalk]:
        """The rows to send now (teammates' stale rows dropped first)."""
        out = []
        for process in list(self.processes.values()):
            process.expire(now)
            talk = process.talk(now)
            if talk is not None:
                out.append(talk)
        return out
