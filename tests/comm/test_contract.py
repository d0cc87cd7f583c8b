"""The transport contract: what every transport must do, whatever carries the messages.

Parametrised over ``tests.comm.harness.FACTORIES``; the tests use only the
:class:`~alica.comm.Transport` interface and the harness's fault injection.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from alica.comm import Envelope, QoS, Transport
from tests.comm.harness import FACTORIES, Harness


def _made(name: str) -> Iterator[Harness]:
    """A fresh harness of the set-up ``name``, closed after the test."""
    made = FACTORIES[name]()
    try:
        yield made
    finally:
        made.close()


@pytest.fixture(params=sorted(FACTORIES))
def harness(request: pytest.FixtureRequest) -> Iterator[Harness]:
    yield from _made(request.param)


def team(harness: Harness, *names: str, topics: tuple[str, ...] = ("state",)) -> list[Transport]:
    transports = [harness.attach(name) for name in names]
    for transport in transports:
        for topic in topics:
            transport.subscribe(topic)
    return transports


def settle(harness: Harness, *transports: Transport) -> list[list[Envelope]]:
    harness.wait(harness.settle_time)
    return [transport.poll() for transport in transports]


#: Set-ups whose links lose nothing: only there is best-effort delivery certain.
LOSSLESS = sorted(name for name, make in FACTORIES.items() if make().lossless)


@pytest.fixture(params=LOSSLESS)
def lossless_harness(request: pytest.FixtureRequest) -> Iterator[Harness]:
    yield from _made(request.param)


#: Set-ups whose peers are the agents heard within the lease, and those whose peers follow liveliness tokens.
HEARD = sorted(name for name, make in FACTORIES.items() if make().liveness == "heard")
TOKENS = sorted(name for name, make in FACTORIES.items() if make().liveness == "token")


@pytest.fixture(params=HEARD)
def heard_harness(request: pytest.FixtureRequest) -> Iterator[Harness]:
    yield from _made(request.param)


@pytest.fixture(params=TOKENS)
def token_harness(request: pytest.FixtureRequest) -> Iterator[Harness]:
    yield from _made(request.param)


# ---------------------------------------------------------------------- delivery


def _one_envelope(harness: Harness, qos: QoS) -> None:
    a, b = team(harness, "a", "b")
    payload = ("pose", 1.0, 2.0)
    harness.wait(1.0)
    sent = harness.now()
    a.publish("state", payload, qos)
    [got] = settle(harness, b)
    assert len(got) == 1
    envelope = got[0]
    assert (envelope.topic, envelope.sender, envelope.seq, envelope.qos) == ("state", "a", 1, qos)
    if harness.by_reference:
        assert envelope.payload is payload  # passed by reference, never copied
    else:
        assert envelope.payload == payload
    assert envelope.sent_at == pytest.approx(sent, abs=0.5)


def test_a_subscriber_gets_the_reliable_envelope(harness: Harness) -> None:
    _one_envelope(harness, QoS.RELIABLE)


def test_a_subscriber_gets_the_best_effort_envelope(lossless_harness: Harness) -> None:
    _one_envelope(lossless_harness, QoS.BEST_EFFORT)


def test_publishers_never_receive_their_own_messages(harness: Harness) -> None:
    a, b = team(harness, "a", "b")
    a.publish("state", 1, QoS.RELIABLE)
    a.publish("state", 2)
    got_a, got_b = settle(harness, a, b)
    assert got_a == []
    assert [e.payload for e in got_b if e.qos is QoS.RELIABLE] == [1]


def test_only_subscribed_topics_are_delivered(harness: Harness) -> None:
    a, b, c = team(harness, "a", "b", "c", topics=())
    b.subscribe("x")
    b.subscribe("x")  # twice is harmless
    for topic in ("x", "y"):
        a.publish(topic, topic, QoS.RELIABLE)
    got_b, got_c = settle(harness, b, c)
    assert [(e.topic, e.payload) for e in got_b] == [("x", "x")]
    assert got_c == []


def test_messages_published_before_subscribing_are_not_delivered(harness: Harness) -> None:
    a, b = team(harness, "a", "b", topics=())
    a.publish("late", "early", QoS.RELIABLE)
    harness.wait(harness.settle_time)
    b.subscribe("late")
    a.publish("late", "after", QoS.RELIABLE)
    [got] = settle(harness, b)
    assert [e.payload for e in got] == ["after"]


def test_sequence_numbers_count_per_sender_and_topic(harness: Harness) -> None:
    a, b, c = team(harness, "a", "b", "c", topics=("x", "y"))
    for topic in ("x", "x", "y", "x"):
        a.publish(topic, None, QoS.RELIABLE)
    b.publish("x", None, QoS.RELIABLE)
    [got] = settle(harness, c)
    assert sorted((e.sender, e.topic, e.seq) for e in got) == [
        ("a", "x", 1),
        ("a", "x", 2),
        ("a", "x", 3),
        ("a", "y", 1),
        ("b", "x", 1),
    ]


def test_poll_drains(harness: Harness) -> None:
    a, b = team(harness, "a", "b")
    a.publish("state", 1, QoS.RELIABLE)
    settle(harness, b)
    assert b.poll() == []


# ---------------------------------------------------------------------- quality of service


def test_reliable_is_in_order_without_duplicates(harness: Harness) -> None:
    a, b, c = team(harness, "a", "b", "c", topics=("x", "y"))
    received: dict[str, list[tuple[str, int]]] = {"b": [], "c": []}
    sent = []
    for i in range(300):
        topic = "x" if i % 3 else "y"
        a.publish(topic, i, QoS.RELIABLE)
        sent.append(i)
        harness.wait(0.001 * (i % 7))
        if i % 10 == 0:
            for transport in (b, c):
                received[transport.agent_id] += [(e.topic, e.payload) for e in transport.poll()]
    for transport, late in zip((b, c), settle(harness, b, c), strict=True):
        received[transport.agent_id] += [(e.topic, e.payload) for e in late]
    for name in ("b", "c"):
        assert [payload for _, payload in received[name]] == sent, name


def test_best_effort_keeps_the_latest_value(lossless_harness: Harness) -> None:
    harness = lossless_harness
    a, b = team(harness, "a", "b")
    for i in range(5):
        a.publish("state", i)
    a.publish("other", "x")  # another topic is not superseded
    [got] = settle(harness, b)
    assert [e.payload for e in got] == [4]
    b.subscribe("other")
    a.publish("other", "y")
    a.publish("state", 5)
    [got] = settle(harness, b)
    assert sorted(str(e.payload) for e in got) == ["5", "y"]


def test_best_effort_never_goes_back_in_time(harness: Harness) -> None:
    a, b = team(harness, "a", "b")
    seen: list[int] = []
    for i in range(400):
        a.publish("state", i)
        harness.wait(0.003)
        seen += [e.seq for e in b.poll()]
    seen += [e.seq for e in settle(harness, b)[0]]
    assert seen == sorted(set(seen))
    assert seen
    if harness.lossless:
        assert seen[-1] == 400


# ---------------------------------------------------------------------- faults


def test_partition_drops_best_effort_and_holds_reliable(harness: Harness) -> None:
    a, b, c = team(harness, "a", "b", "c")
    harness.partition([["a", "c"], ["b"]])
    for i in range(20):
        a.publish("state", i, QoS.RELIABLE)
        a.publish("state", -i)
        harness.wait(0.01)
    got_b, got_c = settle(harness, b, c)
    assert got_b == []
    assert [e.payload for e in got_c if e.qos is QoS.RELIABLE] == list(range(20))
    harness.heal()
    [got_b] = settle(harness, b)
    assert [e.payload for e in got_b] == list(range(20))  # all reliable, in order; no best-effort


def test_unlisted_agents_form_one_group(lossless_harness: Harness) -> None:
    harness = lossless_harness
    a, b, c = team(harness, "a", "b", "c")
    harness.partition([["a"]])
    b.publish("state", "from b")
    a.publish("state", "from a")
    got_a, got_b, got_c = settle(harness, a, b, c)
    assert (got_a, got_b) == ([], [])
    assert [e.payload for e in got_c] == ["from b"]


def test_crashed_agent_neither_sends_nor_receives(harness: Harness) -> None:
    a, b = team(harness, "a", "b", topics=("state", "news"))
    a.publish("state", "in flight", QoS.RELIABLE)
    a.publish("news", "in flight too")
    harness.crash("b")
    b.publish("state", "from the dead", QoS.RELIABLE)
    a.publish("state", "to the dead", QoS.RELIABLE)
    got_a, got_b = settle(harness, a, b)
    assert got_a == []
    assert got_b == []
    harness.recover("b")
    assert b.poll() == []  # back with an empty inbox: what was in flight is gone
    a.publish("state", "welcome back", QoS.RELIABLE)
    b.publish("state", "hello", QoS.RELIABLE)
    got_a, got_b = settle(harness, a, b)
    assert [e.payload for e in got_b] == ["welcome back"]
    assert [e.payload for e in got_a] == ["hello"]


def test_peers_are_the_agents_heard_within_the_lease(heard_harness: Harness) -> None:
    harness = heard_harness
    a, b, c = team(harness, "a", "b", "c")
    assert a.peers() == frozenset()
    for _ in range(20):
        for transport in (a, b, c):
            transport.publish("state", transport.agent_id, QoS.RELIABLE)
        harness.wait(0.1)
        for transport in (a, b, c):
            transport.poll()
    assert a.peers() == {"b", "c"}
    harness.crash("c")
    for _ in range(int(harness.lease / 0.1) + 10):  # lease plus a margin
        for transport in (a, b):
            transport.publish("state", transport.agent_id, QoS.RELIABLE)
        harness.wait(0.1)
    assert a.peers() == {"b"}
    assert b.peers() == {"a"}
    assert c.peers() == frozenset()
    harness.wait(harness.lease + 1.0)
    assert a.peers() == frozenset()


def test_peers_follow_liveliness_tokens(token_harness: Harness) -> None:
    harness = token_harness
    a, b, c = team(harness, "a", "b", "c")
    harness.wait(0.2)
    assert (a.peers(), b.peers(), c.peers()) == ({"b", "c"}, {"a", "c"}, {"a", "b"})
    harness.crash("c")
    harness.wait(0.5)  # a closed session takes its token along at once
    assert (a.peers(), b.peers(), c.peers()) == ({"b"}, {"a"}, frozenset())
    harness.partition([["a"], ["b"]])
    harness.wait(harness.lease + 1.0)  # cut off: gone after the lease at the latest
    assert (a.peers(), b.peers()) == (frozenset(), frozenset())
    harness.heal()
    harness.recover("c")
    harness.wait(harness.lease + 1.0)
    assert (a.peers(), b.peers(), c.peers()) == ({"b", "c"}, {"a", "c"}, {"a", "b"})


# ---------------------------------------------------------------------- life cycle and errors


def test_closed_transport_refuses_work(harness: Harness) -> None:
    a, b = team(harness, "a", "b")
    with b:
        assert b.agent_id == "b"
    b.close()  # twice is harmless
    a.publish("state", 1, QoS.RELIABLE)
    for call in (lambda: b.publish("state", 1), lambda: b.subscribe("x"), b.poll):
        with pytest.raises(ValueError, match="closed"):
            call()
    settle(harness, a)


@pytest.mark.parametrize("topic", ["", None, 3])
def test_bad_topics_are_refused(harness: Harness, topic: object) -> None:
    [a] = team(harness, "a")
    with pytest.raises(ValueError, match="topic must be a non-empty string"):
        a.publish(topic, 1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="topic must be a non-empty string"):
        a.subscribe(topic)  # type: ignore[arg-type]


def test_bad_qos_is_refused(harness: Harness) -> None:
    [a] = team(harness, "a")
    with pytest.raises(ValueError, match="qos must be"):
        a.publish("state", 1, "reliable")  # type: ignore[arg-type]
