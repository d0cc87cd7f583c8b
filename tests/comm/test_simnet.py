"""What only the simulated network promises: seeded loss, delay bounds, timed faults, statistics."""

from __future__ import annotations

import json
import statistics

import pytest

from alica.clock import ManualClock
from alica.comm import Delay, Envelope, NetStats, PartitionHandle, QoS, SimNetwork, SimTransport


def make(
    n: int = 2, topics: tuple[str, ...] = ("t",), **options: object
) -> tuple[ManualClock, SimNetwork, list[SimTransport]]:
    clock = ManualClock()
    network = SimNetwork(clock, **options)  # type: ignore[arg-type]
    transports = [network.attach(name) for name in "abcdefghij"[:n]]
    for transport in transports:
        for topic in topics:
            transport.subscribe(topic)
    return clock, network, transports


def traced(n: int = 2, **options: object) -> tuple[ManualClock, SimNetwork, list[SimTransport], list[dict]]:
    events: list[dict] = []
    clock, network, transports = make(n, observer=events.append, trace_messages=True, **options)
    return clock, network, transports, events


def deliveries(events: list[dict]) -> list[dict]:
    return [e for e in events if e["event"] == "deliver"]


# ---------------------------------------------------------------------- loss


def test_loss_rate_is_as_configured_and_exact_for_a_seed() -> None:
    counts = []
    for _ in range(2):
        clock, network, (a, b) = make(loss=0.25, seed=3)
        got = 0
        for i in range(8000):
            a.publish("t", i)
            clock.advance(0.01)
            got += len(b.poll())
        counts.append(got)
        stats = network.stats
        assert stats.delivered == got
        assert stats.dropped_loss + stats.delivered == 8000
        assert stats.superseded == 0
    assert counts[0] == counts[1]  # same seed, same losses
    assert abs(counts[0] / 8000 - 0.75) < 0.015  # about 4 standard deviations


def test_reliable_messages_are_retransmitted_not_lost() -> None:
    clock, network, (a, b), events = traced(loss=0.5, seed=5, retransmit=0.2)
    for i in range(200):
        a.publish("t", i, QoS.RELIABLE)
    clock.advance(30.0)
    assert [e.payload for e in b.poll()] == list(range(200))
    stats = network.stats
    assert stats.retransmitted > 100
    assert stats.dropped_loss == 0
    assert max(e["t"] for e in deliveries(events)) >= 0.2  # some needed a retransmission


def test_loss_per_link() -> None:
    clock, network, (a, b, c) = make(3)
    network.set_link("a", "b", loss=0.9)
    assert network.link("a", "b").loss == 0.9
    assert network.link("b", "a").loss == 0.0
    for i in range(500):
        a.publish("t", i)
        clock.advance(0.01)
        b.poll()
        c.poll()
    stats = network.stats
    assert 20 < stats.delivered - 500 < 90  # c got all 500, b about a tenth


# ---------------------------------------------------------------------- delay


@pytest.mark.parametrize("base, jitter", [(0.0, 0.0), (0.02, 0.0), (0.01, 0.05)])
def test_uniform_delay_stays_in_bounds(base: float, jitter: float) -> None:
    clock, _network, (a, b, _c), events = traced(3, delay=Delay(base, jitter), seed=1)
    for i in range(300):
        a.publish("t", i, QoS.RELIABLE if i % 2 else QoS.BEST_EFFORT)
        clock.advance(0.007)
    clock.advance(1.0)
    b.poll()
    delays = [e["t"] - 0.007 * (e["seq"] - 1) for e in deliveries(events)]
    assert len(delays) >= 300
    assert min(delays) >= base - 1e-9
    assert max(delays) <= base + jitter + 1e-9
    if jitter:
        assert max(delays) - min(delays) > jitter / 2


def test_exponential_delay_has_the_configured_mean() -> None:
    clock, _network, (a, b), events = traced(delay=Delay(0.01, 0.03, "exponential"), seed=2)
    for i in range(2000):
        a.publish("t", i, QoS.RELIABLE)
        clock.advance(0.5)
    clock.advance(5.0)
    b.poll()
    delays = [e["t"] - 0.5 * (e["seq"] - 1) for e in deliveries(events)]
    assert min(delays) >= 0.01
    assert statistics.mean(delays) == pytest.approx(0.04, rel=0.1)


def test_link_delay_override_is_directed_unless_symmetric() -> None:
    clock, network, (a, b, c) = make(3)
    network.set_link("a", "b", delay=Delay(1.0))
    network.set_link("a", "c", delay=Delay(0.5), symmetric=True)
    assert network.link("b", "a").delay == Delay(0.0)
    assert network.link("c", "a").delay == Delay(0.5)
    a.publish("t", 1)
    c.publish("t", 2)
    clock.advance(0.6)
    assert [e.payload for e in b.poll()] == [2]
    assert [e.payload for e in c.poll()] == [1]
    assert [e.payload for e in a.poll()] == [2]
    clock.advance(0.5)
    assert [e.payload for e in b.poll()] == [1]


def test_reliable_order_survives_jitter_and_retransmission() -> None:
    clock, _network, (a, b) = make(delay=Delay(0.0, 0.5), loss=0.4, seed=9)
    for i in range(100):
        a.publish("t", i, QoS.RELIABLE)
    got: list[int] = []
    for _ in range(300):
        clock.advance(0.05)
        got += [e.payload for e in b.poll()]
    assert got == list(range(100))


def test_poll_orders_by_delivery_time_then_send_order() -> None:
    clock, _network, (a, b, c), events = traced(3, delay=Delay(0.0, 0.1), seed=4)
    for i in range(50):
        a.publish("t", ("a", i), QoS.RELIABLE)
        c.publish("t", ("c", i))
    clock.advance(1.0)
    polled = [(e.sender, e.seq) for e in b.poll()]
    delivered = [(e["sender"], e["seq"]) for e in deliveries(events) if e["receiver"] == "b"]
    superseded = {(e["sender"], e["seq"]) for e in events if e.get("reason") == "superseded"}
    assert polled == [d for d in delivered if d not in superseded]
    times = [e["t"] for e in deliveries(events) if e["receiver"] == "b"]
    assert times == sorted(times)


# ---------------------------------------------------------------------- partitions


def test_timed_partition_starts_and_ends_by_itself() -> None:
    clock, network, (a, b), events = traced(delay=Delay(0.01))
    handle = network.partition([["a"], ["b"]], start=1.0, end=2.0)
    assert isinstance(handle, PartitionHandle)
    sent_during = []
    for step in range(300):
        a.publish("t", step, QoS.RELIABLE)
        a.publish("t", -step)
        if 1.0 <= clock.now() < 2.0:
            sent_during.append(step)
        clock.advance(0.01)
        b.poll()
    faults = [(e["event"], e["t"]) for e in events if e["event"] in ("partition", "heal")]
    assert faults == [("partition", 1.0), ("heal", pytest.approx(2.0))]
    reliable = [e for e in deliveries(events) if e["seq"] % 2 == 1]
    assert [e["seq"] for e in reliable] == [2 * i + 1 for i in range(300)]
    # best-effort copies sent while the cut held never arrive
    best_effort = {e["seq"] for e in deliveries(events) if e["seq"] % 2 == 0}
    assert not best_effort & {2 * s + 2 for s in sent_during[2:-2]}
    assert network.stats.dropped_partition >= len(sent_during) - 2


def test_held_reliable_messages_arrive_after_the_heal_plus_their_delay() -> None:
    clock, network, (a, b), events = traced(delay=Delay(0.25))
    network.partition([["a"], ["b"]])
    for i in range(5):
        a.publish("t", i, QoS.RELIABLE)
        clock.advance(0.1)
    assert network.stats.buffered == 5
    clock.set(3.0)
    network.heal()
    assert network.stats.buffered == 0
    clock.advance(0.24)
    assert b.poll() == []
    clock.advance(0.02)
    assert [e.payload for e in b.poll()] == [0, 1, 2, 3, 4]
    assert {e["t"] for e in deliveries(events)} == {3.25}


def test_heal_one_partition_or_all() -> None:
    clock, network, (a, b, c) = make(3)
    first = network.partition([["a"], ["b", "c"]])
    network.partition([["c"]])
    network.heal(first)
    a.publish("t", 1)
    clock.advance(0.1)
    assert [e.payload for e in b.poll()] == [1]
    assert c.poll() == []
    network.heal(first)  # already healed: nothing happens
    network.heal()
    a.publish("t", 2)
    clock.advance(0.1)
    assert [e.payload for e in c.poll()] == [2]


def test_heal_cancels_a_partition_that_has_not_begun() -> None:
    clock, network, (a, b), events = traced()
    handle = network.partition([["a"]], start=5.0)
    network.heal(handle)
    clock.set(6.0)
    a.publish("t", 1)
    clock.advance(0.1)
    assert [e.payload for e in b.poll()] == [1]
    assert not [e for e in events if e["event"] in ("partition", "heal")]


def test_partition_events_are_json() -> None:
    events: list[dict] = []
    clock, network, _ = make(3, observer=events.append)
    network.partition([{"c", "a"}, ["b"]], start=0.5, end=1.5)  # sets are fine: names are sorted
    clock.advance(2.0)
    network.stats  # noqa: B018  # reading the stats brings the network up to now
    assert json.loads(json.dumps(events)) == [
        {"t": 0.5, "event": "partition", "id": 1, "groups": [["a", "c"], ["b"]], "start": 0.5, "end": 1.5},
        {"t": 1.5, "event": "heal", "id": 1},
    ]


# ---------------------------------------------------------------------- crashes


def test_crash_at_a_future_time_drops_what_is_in_flight() -> None:
    clock, network, (a, b) = make(delay=Delay(1.0))
    network.crash("b", at=0.5)
    assert not network.crashed("b")
    a.publish("t", "lost", QoS.RELIABLE)
    clock.advance(0.5)
    assert network.crashed("b")
    b.publish("t", "nothing")
    clock.advance(2.0)
    assert b.poll() == [] and a.poll() == []
    stats = network.stats
    assert (stats.dropped_crash, stats.sent_by) == (1, {"a": 1, "b": 0})
    network.recover("b")
    assert not network.crashed("b")


def test_crash_drops_reliable_messages_held_by_a_partition_and_the_unpolled_inbox() -> None:
    clock, network, (a, b, c) = make(3)
    network.partition([["a", "c"], ["b"]])
    for i in range(4):
        a.publish("t", i, QoS.RELIABLE)
    clock.advance(0.1)  # c has them in its inbox, b has them held
    network.crash("b")
    network.crash("c")
    assert network.stats.buffered == 0
    network.heal()
    network.recover("b")
    network.recover("c")
    clock.advance(1.0)
    assert b.poll() == [] and c.poll() == []
    assert network.stats.dropped_crash == 8


def test_recover_cancels_a_scheduled_crash() -> None:
    events: list[dict] = []
    clock, network, (a, b) = make(observer=events.append)
    network.crash("b", at=1.0)
    network.recover("b")
    clock.set(2.0)
    a.publish("t", 1)
    assert [e.payload for e in b.poll()] == [1]
    assert [e["event"] for e in events] == ["recover"]
    assert events[0]["cancelled"] is True


def test_messages_from_before_a_crash_still_arrive() -> None:
    clock, network, (a, b) = make(delay=Delay(0.5))
    a.publish("t", "last words", QoS.RELIABLE)
    network.crash("a")
    clock.advance(1.0)
    assert [e.payload for e in b.poll()] == ["last words"]


# ---------------------------------------------------------------------- determinism, stats, tracing


def run_scenario(seed: int) -> list[tuple[str, str, int, float]]:
    clock, network, transports = make(4, seed=seed, loss=0.2, delay=Delay(0.01, 0.05))
    log: list[tuple[str, str, int, float]] = []
    for step in range(400):
        for i, transport in enumerate(transports):
            if (step + i) % 3 == 0:
                transport.publish("t", step, QoS.RELIABLE if i % 2 else QoS.BEST_EFFORT)
        if step == 100:
            network.partition([["a", "b"]], end=2.5)
        if step == 200:
            network.crash("c", at=2.2)
        if step == 250:
            network.recover("c")
        clock.advance(0.01)
        for transport in transports:
            log += [(transport.agent_id, e.sender, e.seq, clock.now()) for e in transport.poll()]
    return log


def test_same_seed_same_deliveries_other_seed_other_deliveries() -> None:
    first = run_scenario(42)
    assert first == run_scenario(42)
    assert first != run_scenario(43)


def test_stats_add_up() -> None:
    clock, network, (a, b, c) = make(3, loss=0.3, seed=8)
    for i in range(100):
        a.publish("t", i)
        a.publish("t", i, QoS.RELIABLE)
    clock.advance(20.0)
    got = len(b.poll()) + len(c.poll())
    stats = network.stats
    assert isinstance(stats, NetStats)
    assert stats.sent == 200 and stats.sent_by == {"a": 200, "b": 0, "c": 0}
    assert stats.delivered == got
    assert stats.delivered + stats.dropped_loss + stats.superseded == 400
    assert stats.retransmitted > 0


def test_without_trace_messages_the_observer_sees_only_faults() -> None:
    events: list[dict] = []
    clock, network, (a, _b) = make(observer=events.append)
    a.publish("t", 1)
    network.crash("b")
    network.recover("b")
    clock.advance(1.0)
    assert [e["event"] for e in events] == ["crash", "recover"]


def test_message_events_are_json() -> None:
    clock, network, (a, b, _c), events = traced(3, loss=0.5, seed=1)
    network.partition([["c"]], start=0.5)
    for i in range(10):
        a.publish("t", (i, "x"))
        a.publish("t", i, QoS.RELIABLE)
        clock.advance(0.1)
        b.poll()
    assert json.loads(json.dumps(events)) == events
    kinds = {(e["event"], e.get("reason")) for e in events}
    assert {("send", None), ("deliver", None), ("drop", "loss"), ("drop", "partition")} <= kinds


def test_superseded_values_are_counted_and_traced() -> None:
    clock, network, (a, b), events = traced()
    for i in range(3):
        a.publish("t", i)
    clock.advance(0.1)
    assert [e.payload for e in b.poll()] == [2]
    assert network.stats.superseded == 2
    assert [e["seq"] for e in events if e.get("reason") == "superseded"] == [1, 2]


def test_envelope_is_a_frozen_value() -> None:
    envelope = Envelope("t", "a", 1, (1, 2), 0.0, QoS.RELIABLE)
    with pytest.raises(AttributeError):
        envelope.seq = 2  # type: ignore[misc]
    assert envelope == Envelope("t", "a", 1, (1, 2), 0.0, QoS.RELIABLE)
