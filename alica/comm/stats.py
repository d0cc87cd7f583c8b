"""Counters of the simulated network, and the snapshot users read."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class NetStats:
    """A snapshot of what the simulated network did so far.

    ``sent`` counts publish calls that went out; the other message counts are
    per receiver (one publish to five subscribers can give five deliveries).

    Attributes:
        sent: publish calls by live agents.
        delivered: messages handed to receivers by ``poll()``.
        dropped_loss: best-effort copies lost on a lossy link.
        dropped_partition: best-effort copies that met a partition.
        dropped_crash: copies dropped because the receiver was crashed or
            crashed while they were in flight or unpolled (reliable ones too).
        dropped_closed: copies for a receiver whose transport was closed.
        superseded: best-effort copies discarded for a newer value from the
            same sender and topic.
        retransmitted: retransmissions of reliable copies lost on a lossy link.
        buffered: reliable copies held now on links cut by a partition.
        sent_by: publish calls per agent, in attach order.
    """

    sent: int
    delivered: int
    dropped_loss: int
    dropped_partition: int
    dropped_crash: int
    dropped_closed: int
    superseded: int
    retransmitted: int
    buffered: int
    sent_by: dict[str, int] = field(default_factory=dict, hash=False)


class Counters:
    """The mutable counters behind :class:`NetStats` (internal to the network)."""

    __slots__ = (
        "delivered",
        "dropped_closed",
        "dropped_crash",
        "dropped_loss",
        "dropped_partition",
        "retransmitted",
        "sent",
        "superseded",
    )

    def __init__(self) -> None:
        self.sent = 0
        self.delivered = 0
        self.dropped_loss = 0
        self.dropped_partition = 0
        self.dropped_crash = 0
        self.dropped_closed = 0
        self.superseded = 0
        self.retransmitted = 0

    def snapshot(self, buffered: int, sent_by: dict[str, int]) -> NetStats:
        """Freeze the counters.

        Args:
            buffered: reliable copies held by partitions now.
            sent_by: publish calls per agent.

        Returns:
            The snapshot.
        """
        return NetStats(
            sent=self.sent,
            delivered=self.delivered,
            dropped_loss=self.dropped_loss,
            dropped_partition=self.dropped_partition,
            dropped_crash=self.dropped_crash,
            dropped_closed=self.dropped_closed,
            superseded=self.superseded,
            retransmitted=self.retransmitted,
            buffered=buffered,
            sent_by=dict(sent_by),
        )
