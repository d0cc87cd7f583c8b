"""The transport interface the engine talks to, whatever carries the messages.

The engine sees only a :class:`Transport`: it publishes payloads on topics,
subscribes to topics and drains what arrived once per tick with
:meth:`Transport.poll`. Draining once per tick keeps the engine
single-threaded and deterministic. The simulated network
(:mod:`alica.comm.simnet`) and the eclipse-zenoh transport between processes
(:mod:`alica.comm.zenoh_transport`) implement it with the same meanings, so
nothing here mentions simulated time, seeds or fault injection.

Payloads are plain immutable Python data: tuples, ``str``, ``int``,
``float``, ``bool``, ``None`` and frozen dataclasses, named tuples and enums
made of those. The simulated network passes them **by reference** (it never
copies them, because the engine sends tens of thousands of messages per
simulated second), so a receiver must never mutate a payload it got; a
transport between processes sends a copy (:mod:`alica.comm.codec`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from enum import Enum
from types import TracebackType
from typing import Self


class QoS(Enum):
    """How hard a transport tries to deliver a message."""

    RELIABLE = "reliable"
    """Never lost while sender and receiver live: buffered while the link is down
    and delivered once it returns, in send order per sender -> receiver, without
    duplicates. Dropped only when the receiver crashes."""

    BEST_EFFORT = "best_effort"
    """May be lost, and keeps the latest value only: when a newer best-effort
    message from the same sender on the same topic reaches a receiver before the
    older one was polled, the older one is discarded. A receiver never gets an
    older best-effort message after a newer one from the same sender and topic."""


@dataclass(frozen=True, slots=True)
class Envelope:
    """One message as a receiver gets it.

    Attributes:
        topic: the topic it was published on.
        sender: the agent id of the publisher.
        seq: sequence number per sender and topic, from 1, whatever the QoS;
            receivers use it to drop duplicates and stale values.
        payload: the published data, shared by reference: do not mutate it.
        sent_at: the sender's clock when it published, in seconds.
        qos: the quality of service it was published with.
    """

    topic: str
    sender: str
    seq: int
    payload: object
    sent_at: float
    qos: QoS


class Transport(ABC):
    """One agent's connection to the team: publish, subscribe, poll once per tick.

    A transport is used from one thread (the engine's). It can be used as a
    context manager, which closes it on exit.
    """

    __slots__ = ()

    @property
    @abstractmethod
    def agent_id(self) -> str:
        """The id of the agent this transport belongs to."""

    @abstractmethod
    def publish(self, topic: str, payload: object, qos: QoS = QoS.BEST_EFFORT) -> None:
        """Send ``payload`` to every other agent subscribed to ``topic``.

        The publisher never receives its own message, even when it subscribes
        to the topic. The payload is passed by reference and must be immutable.

        Args:
            topic: a non-empty topic name.
            payload: plain immutable data (see the module docstring).
            qos: :attr:`QoS.BEST_EFFORT` (default) or :attr:`QoS.RELIABLE`.

        Raises:
            ValueError: the topic is empty or not a string, ``qos`` is not a
                :class:`QoS`, or the transport is closed.
        """

    @property
    def tracks_liveliness(self) -> bool:
        """Whether :meth:`peers` says who is alive (middleware liveliness) rather than who was heard lately.

        The engine then takes a teammate out as soon as it leaves :meth:`peers`,
        instead of waiting for the team timeout.
        """
        return False

    @abstractmethod
    def subscribe(self, topic: str) -> None:
        """Receive messages other agents publish on ``topic`` from now on.

        Subscribing to a topic twice is harmless. Messages published before
        the subscription are not delivered (reliable ones are, when sent after
        it, also across processes).

        Args:
            topic: a non-empty topic name.

        Raises:
            ValueError: the topic is empty or not a string, or the transport
                is closed.
        """

    @abstractmethod
    def poll(self) -> list[Envelope]:
        """Drain every message delivered to this agent by now.

        Called once per engine tick. The order is deterministic: by delivery
        time, then by the order in which the messages were sent.

        Returns:
            The delivered messages, oldest delivery first; empty when nothing
            arrived.

        Raises:
            ValueError: the transport is closed.
        """

    @abstractmethod
    def peers(self) -> frozenset[str]:
        """The agents this transport knows to be alive; never this agent itself.

        Returns:
            Ids of the agents whose messages arrived here within the lease
            (a duration the network or session is configured with) before
            now; or, when :attr:`tracks_liveliness`, whose liveliness the
            middleware reports (gone within milliseconds of a crash, after
            the lease in a partition).
        """

    @abstractmethod
    def close(self) -> None:
        """Leave the team: stop sending and receiving. Closing twice is harmless."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
