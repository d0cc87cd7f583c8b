"""One agent's end of the simulated network: its state and its :class:`Transport`."""

from __future__ import annotations

from collections import deque
from typing import Protocol

from alica.comm.transport import Envelope, QoS, Transport


class Reliable:
    """One reliable copy on its way from a sender to a receiver.

    Args:
        nominal: when it arrives if no partition is in the way.
        counter: the network's send counter of its publish call.
        envelope: the message.
        delay: its drawn one-way delay, counted again from a heal.
        sender: the sending agent.
        receiver: the receiving agent.
    """

    __slots__ = ("counter", "delay", "envelope", "nominal", "receiver", "sender")

    def __init__(
        self,
        nominal: float,
        counter: int,
        envelope: Envelope,
        delay: float,
        sender: AgentState,
        receiver: AgentState,
    ) -> None:
        self.nominal = nominal
        self.counter = counter
        self.envelope = envelope
        self.delay = delay
        self.sender = sender
        self.receiver = receiver


class AgentState:
    """What the network keeps per attached agent.

    Args:
        name: the agent id.
        index: its attach order, from 0.

    Attributes:
        seq: last sequence number per topic it published on.
        inbox: delivered, not yet polled messages; ``None`` marks a
            superseded best-effort slot.
        holes: how many ``None`` slots the inbox has.
        pending: inbox position of the unpolled best-effort message per
            (sender, topic).
        last_best_effort: newest best-effort seq received per (sender, topic).
        heard: last arrival time per sender, for the lease.
        outgoing: reliable copies in flight per receiver id, in send order.
        crash_at: when it crashes or crashed, ``None`` when it is up.
        crash_token: identifies the scheduled crash event.
        closed: its transport was closed.
        sent: its publish calls.
    """

    __slots__ = (
        "closed",
        "crash_at",
        "crash_token",
        "heard",
        "holes",
        "inbox",
        "index",
        "last_best_effort",
        "name",
        "outgoing",
        "pending",
        "sent",
        "seq",
    )

    def __init__(self, name: str, index: int) -> None:
        self.name = name
        self.index = index
        self.seq: dict[str, int] = {}
        self.inbox: list[Envelope | None] = []
        self.holes = 0
        self.pending: dict[tuple[str, str], int] = {}
        self.last_best_effort: dict[tuple[str, str], int] = {}
        self.heard: dict[str, float] = {}
        self.outgoing: dict[str, deque[Reliable]] = {}
        self.crash_at: float | None = None
        self.crash_token: int | None = None
        self.closed = False
        self.sent = 0

    def down_at(self, t: float) -> bool:
        """True when the agent is crashed at time ``t``."""
        return self.crash_at is not None and self.crash_at <= t

    def take_inbox(self) -> list[Envelope]:
        """Empty the inbox and return its messages in delivery order."""
        inbox = self.inbox
        self.inbox = []
        if self.pending:
            self.pending = {}
        if self.holes:
            self.holes = 0
            return [envelope for envelope in inbox if envelope is not None]
        return inbox  # type: ignore[return-value]  # no holes: no None in it

    def forget(self) -> int:
        """Lose everything received (a crash or close); returns how many unpolled messages were lost."""
        lost = len(self.inbox) - self.holes
        self.inbox = []
        self.holes = 0
        self.pending = {}
        self.last_best_effort = {}
        self.heard = {}
        return lost


class _Network(Protocol):
    """What an agent's transport asks of the simulated network (:class:`~alica.comm.simnet.SimNetwork`)."""

    def _publish(self, state: AgentState, topic: str, payload: object, qos: QoS) -> None: ...

    def _subscribe(self, state: AgentState, topic: str) -> None: ...

    def _poll(self, state: AgentState) -> list[Envelope]: ...

    def _peers(self, state: AgentState) -> frozenset[str]: ...

    def _close(self, state: AgentState) -> None: ...


class SimTransport(Transport):
    """The :class:`Transport` of one agent on a :class:`~alica.comm.simnet.SimNetwork`.

    Made by :meth:`SimNetwork.attach`; all the work happens in the network.
    """

    __slots__ = ("_network", "_state")

    def __init__(self, network: _Network, state: AgentState) -> None:
        self._network = network
        self._state = state

    @property
    def agent_id(self) -> str:
        """The id of the agent this transport belongs to."""
        return self._state.name

    def publish(self, topic: str, payload: object, qos: QoS = QoS.BEST_EFFORT) -> None:
        """See :meth:`Transport.publish`; a no-op while the agent is crashed."""
        self._network._publish(self._state, topic, payload, qos)

    def subscribe(self, topic: str) -> None:
        """See :meth:`Transport.subscribe`."""
        self._network._subscribe(self._state, topic)

    def poll(self) -> list[Envelope]:
        """See :meth:`Transport.poll`; empty while the agent is crashed."""
        return self._network._poll(self._state)

    def peers(self) -> frozenset[str]:
        """See :meth:`Transport.peers`; the lease is the network's ``lease``."""
        return self._network._peers(self._state)

    def close(self) -> None:
        """See :meth:`Transport.close`; messages in flight to this agent are dropped."""
        self._network._close(self._state)

    def __repr__(self) -> str:
        return f"SimTransport({self._state.name!r})"
