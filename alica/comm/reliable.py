"""The sender's side of reliable delivery, pure and synchronous: numbering and the history.

A sender numbers its reliable messages per topic (``rseq``) and across all its
topics (``gseq``), keeps them for receivers that missed some, and answers
their history questions. :class:`History` does this without threads, zenoh or
a clock of its own: time comes in as ``now``. The caller (the zenoh shell,
:mod:`alica.comm.zenoh_transport`) holds its lock around every call.

Bounds: a kept message goes when it is older than ``seconds``, or, while the
kept messages take more than ``max_bytes``, the oldest of the topic being
published goes first; each topic keeps at least its newest message.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping


class History:
    """One sender's reliable numbers and kept messages.

    Args:
        incarnation: this sender's incarnation (a restarted process has a new one).
        seconds: how long a message is kept.
        max_bytes: the most the kept messages may take.
    """

    def __init__(self, incarnation: int, *, seconds: float, max_bytes: float) -> None:
        self.incarnation = incarnation
        self._seconds = seconds
        self._max_bytes = max_bytes
        self._rseq: dict[str, int] = {}
        self._put_rseq: dict[str, int] = {}
        self._gseq = 0
        self._kept: dict[str, deque[tuple[int, float, bytes]]] = {}
        self.kept_bytes = 0
        """What the kept messages take, in bytes."""

    def next_numbers(self, topic: str) -> tuple[int, int]:
        """The numbers of the next reliable message on ``topic``: (per topic, across topics)."""
        rseq = self._rseq[topic] = self._rseq.get(topic, 0) + 1
        self._gseq += 1
        return rseq, self._gseq

    def keep(self, topic: str, rseq: int, now: float, data: bytes) -> None:
        """Keep the encoded message ``rseq`` of ``topic``, then trim the topic to the bounds."""
        kept = self._kept.get(topic)
        if kept is None:
            kept = self._kept[topic] = deque()
        kept.append((rseq, now, data))
        self.kept_bytes += len(data)
        while len(kept) > 1 and (self.kept_bytes > self._max_bytes or kept[0][1] < now - self._seconds):
            self.kept_bytes -= len(kept.popleft()[2])  # too old, or the flooding topic gives way first

    def put(self, topic: str, rseq: int) -> None:
        """Message ``rseq`` of ``topic`` is on the wire: heartbeats may announce it."""
        self._put_rseq[topic] = rseq

    def trim(self, now: float) -> None:
        """Drop every kept message older than the history's seconds."""
        horizon = now - self._seconds
        for kept in self._kept.values():
            while kept and kept[0][1] < horizon:
                self.kept_bytes -= len(kept.popleft()[2])

    def announced(self) -> dict[str, int]:
        """Per topic, the last reliable number on the wire (also of topics whose history is trimmed)."""
        return dict(self._put_rseq)

    def kept(self, topic: str) -> list[int]:
        """The numbers of the kept messages of ``topic``, oldest first."""
        return [number for number, _, _ in self._kept.get(topic, ())]

    def answer(
        self, incarnation: int, wanted: Mapping[str, tuple[int | None, float]]
    ) -> tuple[tuple[bytes, ...], dict[str, int], dict[str, int]]:
        """The answer to a receiver's question: the kept messages it lacks, where each topic starts, the oldest kept.

        Args:
            incarnation: the incarnation of this sender the receiver knows.
            wanted: per topic, (the next number the receiver lacks, ``None`` on its first question;
                when it subscribed).

        Returns:
            The encoded messages in send order per topic, and per topic the next number and the oldest kept number.
        """
        frames: list[bytes] = []
        start: dict[str, int] = {}
        oldest: dict[str, int] = {}
        for topic, (first, since) in wanted.items():
            kept = self._kept.get(topic, deque())
            last = self._rseq.get(topic, 0)
            if first is None or incarnation != self.incarnation:
                # its first question (or about an earlier life of this agent): all since it subscribed
                frames += [data for _, at, data in kept if at >= since]
            else:
                frames += [data for number, _, data in kept if number >= first]
            start[topic] = last + 1
            oldest[topic] = kept[0][0] if kept else last + 1
        return tuple(frames), start, oldest
