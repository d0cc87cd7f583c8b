"""Reliable delivery, pure and synchronous: the sender's history and the receiver's inbox.

A sender numbers its reliable messages per topic (``rseq``) and across all its
topics (``gseq``), keeps them for receivers that missed some, and answers
their history questions: :class:`History`. A receiver delivers each sender's
reliable messages once and in the sender's order, holds back those that came
after a gap, asks the sender's history for what it lacks, and keeps the
latest best-effort value per sender and topic: :class:`Inbox`. Neither has
threads, zenoh or a clock of its own: time comes in as ``now``, and what to
send (a history question) comes back as a value. The caller (the zenoh shell,
:mod:`alica.comm.zenoh_transport`) holds its lock around every call.

Bounds: a kept message goes when it is older than ``seconds``, or, while the
kept messages take more than ``max_bytes``, the oldest of the topic being
published goes first; each topic keeps at least its newest message. The
inbox holds at most ``max_held`` messages and ``max_held_bytes`` payload
bytes per sender, and ``max_held_total`` messages and ``max_held_bytes_total``
bytes in all (one more is not held: the sender's history gives it again once
the gap is filled); a sender unheard for ``quiet`` seconds loses what is held of
it and is no longer asked; at most ``max_senders`` senders are remembered
(then the one heard longest ago goes, never-answered ones first).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from alica.comm.codec import CodecError, decode
from alica.comm.transport import Envelope, QoS

# A frame: (incarnation, sender, topic, seq, rseq, gseq, sent_at, payload bytes). ``seq`` counts the
# sender's messages on the topic, ``rseq`` its reliable ones on the topic (0 for best-effort) and
# ``gseq`` its reliable ones on every topic (0 for best-effort): receivers find gaps by ``rseq``
# and deliver a sender's reliable messages in ``gseq`` order, whatever their topic. The payload
# is encoded on its own: one a receiver cannot decode is counted and skipped, and its stream goes on.
Frame = tuple[int, str, str, int, int, int, float, object]
Question = tuple[int, dict[str, tuple[int | None, float]]]
"""A history question to one sender: (the incarnation of it the receiver knows; per subscribed topic,
(the next number the receiver lacks, ``None`` before the first answer; when it subscribed))."""
_UNDECODABLE = object()


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


@dataclass(slots=True)
class _Stream:
    """What a receiver knows of one sender's reliable messages on one topic."""

    next: int | None = None
    """The next reliable number to deliver; ``None`` until the sender's history said where to start."""
    held: dict[int, tuple[int, Envelope | None, int]] = field(default_factory=dict)
    """Reliable messages not delivered yet, by number: (gseq, envelope (``None`` when it cannot be decoded), bytes)."""
    last_gseq: int = 0
    """The sender-wide number of the last message delivered from this stream."""

    def gapped(self) -> bool:
        """Whether a message is known to be missing before the held ones (or where to start is unknown)."""
        return self.next is None or (bool(self.held) and self.next not in self.held)


@dataclass(slots=True)
class _Sender:
    """What a receiver knows of one sender (one incarnation of it)."""

    incarnation: int
    streams: dict[str, _Stream] = field(default_factory=dict)
    offset: dict[str, int] = field(default_factory=dict)
    """Per topic: added to the incarnation's numbers, so that numbers grow across restarts."""
    last_seq: dict[str, int] = field(default_factory=dict)
    """Per topic: the last number delivered from this sender (offset included)."""
    asked_at: float | None = None
    """When a history question to this sender went out (``None``: none outstanding)."""
    heard_at: float = 0.0
    """When a frame, heartbeat or answer of this sender came last."""
    answered: bool = False
    """Whether its history ever answered (senders that never did are forgotten first)."""
    retired: bool = False
    """Whether this incarnation's session is gone while an older one of the same id lives (a duplicate stopped)."""

    def stream(self, topic: str) -> _Stream:
        found = self.streams.get(topic)
        if found is None:
            found = self.streams[topic] = _Stream()
        return found


class Inbox:
    """One receiver's side: what came from every sender, in the order to deliver it.

    A reliable message is delivered once, in its sender's order across all
    the sender's topics; one that comes after a gap is held until the gap is
    filled from the sender's history (or the history says it no longer has
    the missing ones). A best-effort message replaces the one of the same
    sender and topic not taken yet, and one older than a delivered one is
    dropped. A sender's new incarnation (a restart) starts over, with its
    envelope numbers going on from the old ones; frames of an older
    incarnation are ignored, until the newer one's session is gone
    (:meth:`retire`: it was a duplicate of the name) or it has been quiet for
    ``quiet`` seconds (a forged incarnation cannot silence a sender for good).

    Methods that may need a history question return the sender to ask; the
    caller then asks :meth:`question` and hands the answer to :meth:`answered`.

    Args:
        agent_id: the receiver's own id (its own frames are ignored).
        quiet: seconds after which a sender not heard is no longer asked and what is held of it is dropped.
        max_held: the most messages held for one sender.
        max_held_total: the most messages held for all senders.
        max_senders: the most senders remembered.
        max_held_bytes: the most payload bytes held for one sender.
        max_held_bytes_total: the most payload bytes held for all senders.
    """

    def __init__(
        self,
        agent_id: str,
        *,
        quiet: float = 20.0,
        max_held: int = 10_000,
        max_held_total: int = 100_000,
        max_senders: int = 1024,
        max_held_bytes: int = 16 * 1024 * 1024,
        max_held_bytes_total: int = 64 * 1024 * 1024,
    ) -> None:
        self._id = agent_id
        self._max_bytes = max_held_bytes
        self._max_bytes_total = max_held_bytes_total
        self._bytes = 0
        self._bytes_by: dict[str, int] = {}
        self._quiet = quiet
        self._max_held = max_held
        self._max_held_total = max_held_total
        self._max_senders = max_senders
        self._held = 0
        self._held_by: dict[str, int] = {}
        self.subscribed: dict[str, float] = {}
        """The topics subscribed to, and when."""
        self._senders: dict[str, _Sender] = {}
        self._out: list[Envelope | None] = []
        self._pending: dict[tuple[str, str], int] = {}
        self.counts = dict.fromkeys(("recovered", "duplicates", "superseded", "lost", "undecodable"), 0)
        self.dropped = dict.fromkeys(("held", "quiet", "senders"), 0)
        """Bounds met: messages not held (a cap), dropped from a quiet sender, and senders forgotten (the cap)."""
        """What happened so far (the counters of the same names of :class:`~alica.comm.zenoh_transport.ZenohStats`)."""
        self.errors: dict[str, int] = {}
        """Why payloads could not be decoded (sender, topic, reason) and how often."""

    @property
    def held(self) -> int:
        """Reliable messages taken in and not delivered yet (waiting for a gap to be filled, or for where to start)."""
        return self._held

    def subscribe(self, topic: str, now: float) -> None:
        """Take in ``topic`` from now on (a second call keeps the first time)."""
        self.subscribed.setdefault(topic, now)

    def take(self) -> list[Envelope]:
        """The envelopes to deliver, in order, and forget them."""
        out = self._out
        if not out:
            return []
        self._out = []
        self._pending.clear()
        return [envelope for envelope in out if envelope is not None]

    def receive(self, frame: Frame, now: float) -> str | None:
        """Take in one frame; returns its sender when that sender's history must be asked now."""
        incarnation, sender, topic, seq, rseq, gseq, sent_at, data = frame
        if topic not in self.subscribed or sender == self._id:
            return None
        state = self._sender(sender, incarnation, now)
        if state is None:
            return None
        shown = state.offset.get(topic, 0) + seq
        if rseq == 0:
            payload = self._payload(data, sender, topic)
            if payload is _UNDECODABLE:
                return None
            if shown <= state.last_seq.get(topic, 0):
                self.counts["superseded"] += 1
                return None
            state.last_seq[topic] = shown
            key = (sender, topic)
            old = self._pending.get(key)
            if old is not None:
                self._out[old] = None
                self.counts["superseded"] += 1
            self._pending[key] = len(self._out)
            self._out.append(Envelope(topic, sender, shown, payload, sent_at, QoS.BEST_EFFORT))
            return None
        stream = state.stream(topic)
        if (stream.next is not None and rseq < stream.next) or rseq in stream.held:
            self.counts["duplicates"] += 1  # before decoding: a duplicate is neither decoded nor counted twice
            return None
        payload = self._payload(data, sender, topic)
        size = _size(data)
        if stream.next is None or rseq != stream.next:
            if not self._room(sender, size):
                self.dropped["held"] += 1  # its history gives it again once the gap is filled
                return self._want(sender, state, now)
        stream.held[rseq] = (gseq, _envelope(topic, sender, shown, payload, sent_at), size)
        self._count_held(sender, 1, size)
        self._release(sender, state)
        return self._want(sender, state, now) if stream.gapped() else None

    def heard(self, sender: str, incarnation: int, last: Mapping[str, int], now: float) -> str | None:
        """Take in a heartbeat (per topic, the last reliable number sent); returns the sender when it must be asked."""
        if sender == self._id:
            return None
        state = self._sender(sender, incarnation, now)
        if state is None:
            return None
        behind = False
        for topic, number in last.items():
            if topic in self.subscribed:
                stream = state.stream(topic)
                behind = behind or stream.next is None or stream.next <= number
        return self._want(sender, state, now) if behind else None

    def overdue(self, now: float, timeout: float) -> list[str]:
        """The senders asked more than ``timeout`` seconds ago and not answered: they count as asked again now.

        A sender not heard for ``quiet`` seconds is not asked again, and what is held of it is dropped.
        """
        retry = []
        for sender, state in self._senders.items():
            if now - state.heard_at > self._quiet:
                state.asked_at = None
                dropped = self._held_by.get(sender, 0)
                if dropped:
                    for stream in state.streams.values():
                        stream.held.clear()
                    self._drop_held(sender)
                    self.dropped["quiet"] += dropped
                continue
            if state.asked_at is not None and now - state.asked_at > timeout:
                state.asked_at = now
                retry.append(sender)
        return retry

    def question(self, sender: str) -> Question | None:
        """What to ask ``sender``'s history (``None``: nothing heard of it)."""
        state = self._senders.get(sender)
        if state is None:
            return None
        return state.incarnation, {topic: (state.stream(topic).next, since) for topic, since in self.subscribed.items()}

    def answered(
        self,
        incarnation: int,
        sender: str,
        frames: Iterable[Frame],
        start: Mapping[str, int],
        oldest: Mapping[str, int],
    ) -> None:
        """Take in a history answer (see :meth:`History.answer`).

        Args:
            incarnation: the answering sender's incarnation.
            sender: the answering sender.
            frames: the frames of the answer (read only when the answer is about the current incarnation).
            start: per topic, the number of the sender's next reliable message.
            oldest: per topic, the oldest number the sender still keeps.
        """
        state = self._sender(sender, incarnation, None)
        if state is None:
            return
        state.asked_at = None
        state.answered = True
        decoded = list(frames)
        first_answer = {topic for topic in start if topic in self.subscribed and state.stream(topic).next is None}
        for topic in first_answer:
            stream = state.stream(topic)
            numbers = [f[4] for f in decoded if f[2] == topic]
            stream.next = min(numbers) if numbers else int(start[topic])
            for number in [n for n in stream.held if n < stream.next]:
                size = stream.held.pop(number)[2]  # sent before this agent subscribed
                self._count_held(sender, -1, -size)
        for topic, first in oldest.items():
            known = state.streams.get(topic)
            if topic not in first_answer and known is not None and known.next is not None and first > known.next:
                self.counts["lost"] += first - known.next
                known.next = first
        for frame in decoded:
            _, _, topic, seq, rseq, gseq, sent_at, data = frame
            known = state.streams.get(topic)
            if known is None or known.next is None or rseq < known.next or rseq in known.held:
                continue
            size = _size(data)
            if rseq != known.next and not self._room(sender, size):
                self.dropped["held"] += 1
                continue
            shown = state.offset.get(topic, 0) + seq
            payload = self._payload(data, sender, topic)
            known.held[rseq] = (gseq, _envelope(topic, sender, shown, payload, sent_at), size)
            self._count_held(sender, 1, size)
            self.counts["recovered"] += topic not in first_answer
        self._release(sender, state)

    def _payload(self, data: object, sender: str, topic: str) -> object:
        """The decoded payload, or :data:`_UNDECODABLE` (counted, its reason kept)."""
        if not isinstance(data, bytes):
            self.counts["undecodable"] += 1
            return _UNDECODABLE
        try:
            return decode(data)
        except CodecError as exc:
            self.counts["undecodable"] += 1
            self.errors.setdefault(f"{sender} on {topic}: {exc}", 0)
            self.errors[f"{sender} on {topic}: {exc}"] += 1
            return _UNDECODABLE

    def _sender(self, sender: str, incarnation: int, now: float | None) -> _Sender | None:
        """The state of ``sender``, started over for a new incarnation; ``None`` for an old one.

        ``now`` (``None``: an answer, which is no sign of life) marks the sender heard, and a new sender
        may make the inbox forget the one heard longest ago, never-answered ones first.
        """
        state = self._senders.get(sender)
        if state is None:
            if now is None:
                return None
            if len(self._senders) >= self._max_senders:
                self._forget_one()
            state = self._senders[sender] = _Sender(incarnation)
        elif incarnation > state.incarnation:
            state = self._start_over(sender, state, incarnation)
        elif incarnation < state.incarnation:
            if now is None or not (state.retired or now - state.heard_at > self._quiet):
                return None
            # the newer incarnation stopped (a duplicate) or went quiet (a forgery): the older one speaks again
            state = self._start_over(sender, state, incarnation)
        if now is not None:
            state.heard_at = now
        return state

    def _start_over(self, sender: str, state: _Sender, incarnation: int) -> _Sender:
        """A new state of ``sender`` for ``incarnation``, its envelope numbers going on from ``state``'s."""
        numbers = dict(state.last_seq)
        self._drop_held(sender)
        self._senders[sender] = _Sender(incarnation, offset=numbers, last_seq=dict(numbers))
        return self._senders[sender]

    def retire(self, sender: str, incarnation: int) -> None:
        """``sender``'s session ``incarnation`` is gone while an older one lives: take the older one's frames again."""
        state = self._senders.get(sender)
        if state is not None and state.incarnation == incarnation:
            state.retired = True

    def _forget_one(self) -> None:
        """Forget the sender heard longest ago, preferring one whose history never answered."""
        victim = min(self._senders, key=lambda name: (self._senders[name].answered, self._senders[name].heard_at))
        del self._senders[victim]
        self._drop_held(victim)
        self._pending = {key: index for key, index in self._pending.items() if key[0] != victim}
        self.dropped["senders"] += 1

    def _room(self, sender: str, size: int) -> bool:
        """Whether one more message of ``sender``, of ``size`` payload bytes, may be held."""
        return (
            self._held < self._max_held_total
            and self._held_by.get(sender, 0) < self._max_held
            and self._bytes + size <= self._max_bytes_total
            and self._bytes_by.get(sender, 0) + size <= self._max_bytes
        )

    def _count_held(self, sender: str, change: int, size: int) -> None:
        """Count ``change`` messages of ``size`` payload bytes (both negative when they go) held for ``sender``."""
        if change:
            self._held += change
            self._bytes += size
            left = self._held_by.get(sender, 0) + change
            if left > 0:
                self._held_by[sender] = left
                self._bytes_by[sender] = self._bytes_by.get(sender, 0) + size
            else:
                self._held_by.pop(sender, None)
                self._bytes_by.pop(sender, None)

    def _drop_held(self, sender: str) -> None:
        """Count everything held for ``sender`` as gone (the caller drops the messages themselves)."""
        self._count_held(sender, -self._held_by.get(sender, 0), -self._bytes_by.get(sender, 0))

    def _release(self, sender: str, state: _Sender) -> None:
        """Deliver the sender's held reliable messages that can go, in its send order.

        A message goes when its topic has no gap before it and no other topic
        of the sender has a gap that may hold an earlier message.
        """
        streams = state.streams
        while True:
            gate = min((s.last_gseq for s in streams.values() if s.gapped()), default=None)
            best: _Stream | None = None
            for stream in streams.values():
                if stream.next is not None and stream.next in stream.held:
                    if best is None or stream.held[stream.next][0] < best.held[best.next][0]:  # type: ignore[index]
                        best = stream
            if best is None or best.next is None:
                return
            gseq, envelope, size = best.held[best.next]
            if gate is not None and gseq > gate:
                return
            del best.held[best.next]
            self._count_held(sender, -1, -size)
            best.next += 1
            best.last_gseq = gseq
            if envelope is None:
                continue  # a payload this process cannot decode: counted, skipped
            if envelope.seq > state.last_seq.get(envelope.topic, 0):
                state.last_seq[envelope.topic] = envelope.seq
            self._out.append(envelope)

    @staticmethod
    def _want(sender: str, state: _Sender, now: float) -> str | None:
        """``sender`` when no history question to it is outstanding (then one counts as asked ``now``)."""
        if state.asked_at is not None:
            return None
        state.asked_at = now
        return sender


def _size(data: object) -> int:
    """The payload bytes a held message counts for."""
    return len(data) if isinstance(data, bytes | bytearray) else 0


def _envelope(topic: str, sender: str, seq: int, payload: object, sent_at: float) -> Envelope | None:
    return None if payload is _UNDECODABLE else Envelope(topic, sender, seq, payload, sent_at, QoS.RELIABLE)
