"""The receiver's side of reliable delivery (:class:`alica.comm.reliable.Inbox`), without zenoh.

Senders are :class:`~alica.comm.reliable.History` objects framing messages as
the zenoh transport does; the "network" between them and the inbox is a list
of frames in flight that the test loses, reorders and duplicates at will, and
history questions and answers that come late, twice, or never.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.comm.codec import decode, encode
from alica.comm.reliable import Frame, History, Inbox
from alica.comm.transport import Envelope, QoS

TOPICS = ("a", "b")
SENDERS = ("s", "t")
TIMEOUT = 1.0
Answer = tuple[int, str, list[Frame], dict[str, int], dict[str, int]]
"""A history answer as the inbox takes it: (incarnation, sender, frames, start, oldest)."""
Message = tuple[str, int, str, int]
"""A reliable message: (sender, incarnation, topic, rseq)."""


@dataclass
class Sender:
    """One sender process: its history and its per-topic message counts (a restart starts both over)."""

    name: str
    incarnation: int = 1
    history: History = field(init=False)
    seq: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.history = History(self.incarnation, seconds=1e9, max_bytes=1e9)

    def send(self, topic: str, now: float, reliable: bool = True) -> Frame:
        """A frame as ZenohTransport.publish makes it; the payload names the message."""
        seq = self.seq[topic] = self.seq.get(topic, 0) + 1
        rseq, gseq = self.history.next_numbers(topic) if reliable else (0, 0)
        payload = encode((self.name, self.incarnation, topic, rseq, seq))
        frame: Frame = (self.incarnation, self.name, topic, seq, rseq, gseq, now, payload)
        if reliable:
            self.history.keep(topic, rseq, now, encode(frame))
            self.history.put(topic, rseq)
        return frame

    def restart(self) -> Sender:
        return Sender(self.name, self.incarnation + 1)

    def answer(self, inbox: Inbox) -> Answer | None:
        """This sender's answer to the question the inbox asks it now (``None``: the inbox asks nothing)."""
        question = inbox.question(self.name)
        if question is None:
            return None
        frames, start, oldest = self.history.answer(*question)
        return self.incarnation, self.name, [decode(f) for f in frames], start, oldest


def receiver() -> Inbox:
    inbox = Inbox("r")
    for topic in TOPICS:
        inbox.subscribe(topic, 0.0)
    return inbox


def settle(inbox: Inbox, senders: dict[str, Sender], now: float) -> float:
    """Heartbeats, time-outs and answers until the inbox asks nothing more (the network healed); the time after."""
    for _ in range(10):
        heard = [inbox.heard(s.name, s.incarnation, s.history.announced(), now) for s in senders.values()]
        now += 2 * TIMEOUT
        asks = {name for name in heard if name is not None} | set(inbox.overdue(now, TIMEOUT))
        if not asks:
            return now
        for name in sorted(asks):
            answer = senders[name].answer(inbox)
            assert answer is not None
            inbox.answered(*answer)
    raise AssertionError("the inbox keeps asking")


def ident(envelope: Envelope) -> Message:
    """(sender, incarnation, topic, rseq) of a delivered message."""
    sender, incarnation, topic, rseq, _ = envelope.payload
    return sender, incarnation, topic, rseq


def check_order(delivered: list[Envelope]) -> None:
    """Exactly once, each topic in its sender's order, best-effort never older than what came before."""
    reliable = [ident(e) for e in delivered if e.qos is QoS.RELIABLE]
    assert len(reliable) == len(set(reliable))
    last_rseq: dict[tuple[str, int, str], int] = {}
    last_shown: dict[tuple[str, str], int] = {}
    last_reliable_shown: dict[tuple[str, str], int] = {}
    for envelope in delivered:
        sender, incarnation, topic, rseq = ident(envelope)
        assert (envelope.sender, envelope.topic) == (sender, topic)
        key = (sender, topic)
        if envelope.qos is QoS.RELIABLE:
            stream = (sender, incarnation, topic)
            assert rseq == last_rseq.get(stream, 0) + 1  # from the first message on, without a gap
            last_rseq[stream] = rseq
            assert envelope.seq > last_reliable_shown.get(key, 0)  # numbers grow, also across restarts
            last_reliable_shown[key] = envelope.seq
        else:
            assert envelope.seq > last_shown.get(key, 0)  # never older than one delivered before it
        last_shown[key] = max(last_shown.get(key, 0), envelope.seq)


SEND = st.tuples(  # mostly reliable, mostly on subscribed topics
    st.just("send"),
    st.sampled_from(SENDERS),
    st.sampled_from((*TOPICS, *TOPICS, "c")),
    st.sampled_from((True, True, False)),
)
ARRIVE = st.tuples(st.just("arrive"), st.integers(0, 3), st.booleans())
EVENTS = [  # sending and arriving three times as often as the others
    *[SEND] * 3,
    *[ARRIVE] * 3,
    st.tuples(st.just("lose"), st.integers(0, 3)),
    st.tuples(st.just("beat"), st.sampled_from(SENDERS)),
    st.tuples(st.just("ask"), st.integers(0, 3), st.booleans()),
    st.tuples(st.just("reply"), st.integers(0, 3), st.booleans()),
    st.tuples(st.just("exchange"), st.integers(0, 3)),
    st.tuples(st.just("tick")),
]
RESTART = st.tuples(st.just("restart"), st.sampled_from(SENDERS))


def play(events: list[tuple]) -> None:
    """Play ``events`` (polling after each), then heal: every message of each sender's last life came once, in order.

    Events: a sender sends (reliable or best-effort, also on a topic the receiver did not subscribe to);
    a frame in flight arrives (and stays in flight, to come again) or is lost; a sender's heartbeat
    arrives; a history question the inbox asked goes out (or is lost); an answer arrives (and may come
    again later); a question is answered at once; time passes beyond the question time-out; a sender restarts.

    Across topics, a sender's order holds for what the inbox knows of: no message goes out while an
    earlier one of the same sender (and life) that the inbox has taken in is still undelivered.
    """
    inbox = receiver()
    senders = {name: Sender(name) for name in SENDERS}
    sent: dict[Message, int] = {}  # reliable message -> its gseq
    received: set[Message] = set()  # reliable messages the inbox was handed (on a subscribed topic)
    wire: list[Frame] = []
    asks: list[str] = []
    replies: list[Answer] = []
    delivered: list[Envelope] = []
    now = 0.0

    def took_in(frames: list[Frame]) -> None:
        received.update((f[1], f[0], f[2], f[4]) for f in frames if f[4] and f[2] in TOPICS)

    for event in events:
        now += 0.01
        kind = event[0]
        if kind == "send":
            _, name, topic, reliable = event
            frame = senders[name].send(topic, now, reliable)
            wire.append(frame)
            if reliable:
                sent[(name, frame[0], topic, frame[4])] = frame[5]
        elif kind == "restart":
            senders[event[1]] = senders[event[1]].restart()
        elif kind == "arrive" and wire:
            index = event[1] % len(wire)
            frame = wire[index] if event[2] else wire.pop(index)
            took_in([frame])
            asks += filter(None, [inbox.receive(frame, now)])
        elif kind == "lose" and wire:
            wire.pop(event[1] % len(wire))
        elif kind == "beat":
            sender = senders[event[1]]
            asks += filter(None, [inbox.heard(sender.name, sender.incarnation, sender.history.announced(), now)])
        elif kind == "ask" and asks:
            answer = senders[asks.pop(event[1] % len(asks))].answer(inbox)
            if answer is not None and event[2]:
                replies.append(answer)
        elif kind == "reply" and replies:
            index = event[1] % len(replies)
            answer = replies[index] if event[2] else replies.pop(index)
            took_in(answer[2])
            inbox.answered(*answer)
        elif kind == "exchange" and asks:  # a question and its answer at once
            answer = senders[asks.pop(event[1] % len(asks))].answer(inbox)
            if answer is not None:
                took_in(answer[2])
                inbox.answered(*answer)
        elif kind == "tick":
            asks += inbox.overdue(now, TIMEOUT)
        for envelope in inbox.take():
            if envelope.qos is QoS.RELIABLE:
                message = ident(envelope)
                done = {ident(e) for e in delivered if e.qos is QoS.RELIABLE}
                earlier = {m for m in received if m[:2] == message[:2] and sent[m] < sent[message]}
                assert earlier <= done, "a message went out before an earlier one of its sender that was in"
            delivered.append(envelope)
        check_order(delivered)
    for late in replies:  # answers still on their way come after the heal
        inbox.answered(*late)
    settle(inbox, senders, now + 1)
    delivered += inbox.take()
    check_order(delivered)
    got = {ident(e) for e in delivered if e.qos is QoS.RELIABLE}
    assert got <= set(sent) and all(topic in TOPICS for _, _, topic, _ in got)
    last_lives = {(s.name, s.incarnation) for s in senders.values()}
    assert {m for m in sent if m[:2] in last_lives and m[2] in TOPICS} <= got
    assert inbox.counts["lost"] == inbox.counts["undecodable"] == 0
    assert inbox.held == 0 and inbox.take() == []


@settings(max_examples=200)
@given(st.lists(st.one_of(*EVENTS), min_size=40, max_size=200))
def test_any_interleaving_delivers_each_senders_messages_once_and_in_order(events):
    play(events)


@given(st.lists(st.one_of(*EVENTS, RESTART), min_size=40, max_size=200))
def test_restarts_deliver_the_last_lives_messages_once_and_in_order(events):
    play(events)


def started(*names: str) -> tuple[Inbox, dict[str, Sender]]:
    """An inbox that heard every sender once (its first question answered) before anything was sent."""
    inbox = receiver()
    senders = {name: Sender(name) for name in names}
    for sender in senders.values():
        assert inbox.heard(sender.name, 1, {"a": 0}, 0.0) == sender.name  # first contact: where to start?
        answer = sender.answer(inbox)
        assert answer is not None
        inbox.answered(*answer)
    return inbox, senders


def payloads(envelopes: list[Envelope]) -> list[tuple[str, int]]:
    return [(e.topic, e.payload[3]) for e in envelopes]


def test_a_gap_holds_what_came_after_it_until_the_history_fills_it():
    inbox, senders = started("s")
    s = senders["s"]
    a1, a2, a3 = (s.send("a", 1.0) for _ in range(3))
    assert inbox.receive(a1, 1.0) is None and payloads(inbox.take()) == [("a", 1)]
    assert inbox.receive(a3, 1.1) == "s"  # a2 is missing: ask the history
    assert inbox.take() == [] and inbox.held == 1
    assert inbox.question("s") == (1, {"a": (2, 0.0), "b": (1, 0.0)})  # per topic, the next number it lacks
    inbox.answered(*s.answer(inbox))
    assert payloads(inbox.take()) == [("a", 2), ("a", 3)] and inbox.held == 0
    assert inbox.counts["recovered"] == 1  # a3 was already held
    inbox.receive(a2, 1.2)  # the lost one comes after all
    assert inbox.take() == [] and inbox.counts["duplicates"] == 1


def test_a_later_message_of_another_topic_waits_for_an_earlier_gap():
    inbox, senders = started("s")
    s = senders["s"]
    a1, b1, a2, a3, b2 = s.send("a", 1.0), s.send("b", 1.0), s.send("a", 1.0), s.send("a", 1.0), s.send("b", 1.0)
    for frame in (a1, b1):
        inbox.receive(frame, 1.0)
    assert payloads(inbox.take()) == [("a", 1), ("b", 1)]
    assert inbox.receive(a3, 1.1) == "s"
    assert inbox.receive(b2, 1.1) is None  # already asked
    assert inbox.take() == []  # b2 was sent after the missing a2: it waits
    inbox.receive(a2, 1.2)
    assert payloads(inbox.take()) == [("a", 2), ("a", 3), ("b", 2)]


def test_one_question_at_a_time_asked_again_once_overdue():
    inbox, senders = started("s")
    s = senders["s"]
    frames = [s.send("a", 1.0) for _ in range(5)]
    assert inbox.receive(frames[1], 1.0) == "s"
    assert inbox.receive(frames[3], 1.1) is None
    assert inbox.heard("s", 1, s.history.announced(), 1.2) is None
    assert inbox.overdue(1.5, TIMEOUT) == []
    assert inbox.overdue(2.5, TIMEOUT) == ["s"]
    assert inbox.overdue(2.6, TIMEOUT) == []  # counts as asked again at 2.5
    inbox.answered(*s.answer(inbox))
    assert [p for _, p in payloads(inbox.take())] == [1, 2, 3, 4, 5]
    assert inbox.overdue(10.0, TIMEOUT) == []


def test_an_answer_that_comes_twice_or_late_delivers_nothing_twice():
    inbox, senders = started("s")
    s = senders["s"]
    a1, a2 = s.send("a", 1.0), s.send("a", 1.0)
    assert inbox.receive(a2, 1.0) == "s"
    answer = s.answer(inbox)
    assert answer is not None
    inbox.answered(*answer)
    inbox.answered(*answer)
    inbox.receive(a1, 1.1)
    assert payloads(inbox.take()) == [("a", 1), ("a", 2)]
    assert inbox.counts["recovered"] == 1 and inbox.counts["duplicates"] == 1


def test_a_heartbeat_ahead_of_what_came_asks():
    inbox, senders = started("s")
    s = senders["s"]
    s.send("a", 1.0)  # lost
    assert inbox.heard("s", 1, {"a": 0, "c": 7}, 1.0) is None  # nothing new (c is not subscribed)
    assert inbox.heard("s", 1, s.history.announced(), 1.0) == "s"
    inbox.answered(*s.answer(inbox))
    assert payloads(inbox.take()) == [("a", 1)]


def test_a_restart_starts_over_its_numbers_go_on_and_its_earlier_life_is_ignored():
    inbox, senders = started("s")
    old = senders["s"]
    for frame in (old.send("a", 1.0), old.send("a", 1.0)):
        inbox.receive(frame, 1.0)
    assert [e.seq for e in inbox.take()] == [1, 2]
    late = old.send("a", 1.5)  # still on its way when the process dies
    old_answer = old.answer(inbox)
    new = old.restart()
    first = new.send("a", 2.0)
    assert inbox.receive(first, 2.0) == "s"  # a new life: where does it start?
    assert inbox.question("s") == (2, {"a": (None, 0.0), "b": (None, 0.0)})
    assert inbox.receive(late, 2.1) is None
    assert old_answer is not None
    inbox.answered(*old_answer)  # an answer of the earlier life, late
    assert inbox.take() == []
    inbox.answered(*new.answer(inbox))
    [again] = inbox.take()
    assert (again.payload[:2], again.seq) == (("s", 2), 3)  # its own count starts at 1; the envelope's goes on
    assert inbox.overdue(100.0, TIMEOUT) == []


def test_what_the_sender_no_longer_keeps_is_counted_lost_and_skipped():
    inbox = receiver()
    s = Sender("s")
    s.history = History(1, seconds=1.0, max_bytes=1e9)
    inbox.receive(s.send("a", 0.0), 0.0)
    inbox.answered(*s.answer(inbox))
    assert payloads(inbox.take()) == [("a", 1)]
    frames = [s.send("a", float(now)) for now in range(1, 5)]  # a2 and a3 are too old when a5 is kept
    assert s.history.kept("a") == [4, 5]
    assert inbox.receive(frames[-1], 4.0) == "s"
    inbox.answered(*s.answer(inbox))
    assert payloads(inbox.take()) == [("a", 4), ("a", 5)]
    assert inbox.counts["lost"] == 2 and inbox.held == 0


def test_the_first_answer_drops_what_was_sent_before_subscribing():
    inbox = Inbox("r")
    s = Sender("s")
    before = s.send("a", 1.0)
    inbox.subscribe("a", 5.0)
    inbox.subscribe("a", 9.0)  # a second subscription keeps the first time
    after = s.send("a", 6.0)
    assert inbox.receive(before, 6.0) == "s"
    inbox.receive(after, 6.0)
    inbox.answered(*s.answer(inbox))
    assert payloads(inbox.take()) == [("a", 2)] and inbox.held == 0


def test_best_effort_keeps_the_latest_value_and_never_an_older_one():
    inbox, senders = started("s")
    s = senders["s"]
    b1, b2, b3 = (s.send("a", 1.0, reliable=False) for _ in range(3))
    inbox.receive(b1, 1.0)
    inbox.receive(b3, 1.0)
    inbox.receive(b2, 1.0)  # older than one taken in
    [latest] = inbox.take()
    assert (latest.qos, latest.seq) == (QoS.BEST_EFFORT, 3) and inbox.counts["superseded"] == 2
    r4 = s.send("a", 1.0)
    inbox.receive(r4, 1.0)
    inbox.receive(s.send("a", 1.0, reliable=False), 1.0)
    assert [(e.qos, e.seq) for e in inbox.take()] == [(QoS.RELIABLE, 4), (QoS.BEST_EFFORT, 5)]


def test_an_undecodable_payload_is_counted_and_skipped_and_its_stream_goes_on():
    inbox, senders = started("s")
    s = senders["s"]
    a1, a2, a3 = (s.send("a", 1.0) for _ in range(3))
    broken = (*a2[:7], b"not a pickle")
    for frame in (a1, broken, a3):
        inbox.receive(frame, 1.0)
    assert payloads(inbox.take()) == [("a", 1), ("a", 3)]
    assert inbox.counts["undecodable"] == 1 and inbox.held == 0
    [(why, count)] = inbox.errors.items()
    assert why.startswith("s on a:") and count == 1


def test_an_undecodable_payload_that_comes_twice_is_a_duplicate_not_counted_again():
    inbox, senders = started("s")
    s = senders["s"]
    a1, a2 = (s.send("a", 1.0) for _ in range(2))
    broken = (*a1[:7], b"not a pickle")
    for frame in (broken, broken, a2, broken):  # the network repeats it (a history answer raced the stream)
        inbox.receive(frame, 1.0)
    assert payloads(inbox.take()) == [("a", 2)]
    assert inbox.counts["undecodable"] == 1 and inbox.counts["duplicates"] == 2
    assert list(inbox.errors.values()) == [1]


def test_its_own_frames_and_unsubscribed_topics_are_ignored():
    inbox = receiver()
    me, other = Sender("r"), Sender("s")
    assert inbox.receive(me.send("a", 1.0), 1.0) is None
    assert inbox.heard("r", 1, me.history.announced(), 1.0) is None
    assert inbox.receive(other.send("c", 1.0), 1.0) is None
    assert inbox.question("s") is None and inbox.question("r") is None
    assert inbox.take() == [] and inbox.held == 0
