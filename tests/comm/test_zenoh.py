"""What the zenoh transport does beyond the shared contract: restarts, trimmed histories, names, the codec."""

from __future__ import annotations

import os
import pickle
import time
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from alica.clock import ManualClock
from alica.comm import QoS
from alica.comm.codec import CodecError, allow_module, decode, encode
from alica.comm.relay import LinkRelay
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints
from alica.engine.team import Claim, TeamMessage
from alica.worldmodel import WorldModel


def wait_for(condition, timeout: float = 5.0) -> bool:
    """Real time passes here (real sessions): poll ``condition`` until it holds, at most ``timeout`` seconds."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return condition()


@pytest.fixture
def endpoints() -> Iterator[list[str]]:
    yield free_endpoints(2)


def pair(endpoints: list[str], **options) -> tuple[ZenohTransport, ZenohTransport]:
    a = ZenohTransport("a", listen=[endpoints[0]], team="unit", **options)
    b = ZenohTransport("b", listen=[endpoints[1]], connect=[endpoints[0]], team="unit", **options)
    assert wait_for(lambda: a.peers() == {"b"} and b.peers() == {"a"})
    return a, b


def drain(transport: ZenohTransport, count: int, timeout: float = 5.0) -> list:
    """Poll until ``count`` envelopes came, at most ``timeout`` seconds."""
    got: list = []

    def enough() -> bool:
        got.extend(transport.poll())
        return len(got) >= count

    wait_for(enough, timeout)
    return got


def test_a_restarted_agent_is_a_new_incarnation_whose_numbers_go_on(endpoints):
    a, b = pair(endpoints)
    try:
        b.subscribe("news")
        for i in range(3):
            a.publish("news", i, QoS.RELIABLE)
        first = drain(b, 3)
        assert [(e.payload, e.seq) for e in first] == [(0, 1), (1, 2), (2, 3)]
        a.close()
        assert wait_for(lambda: b.peers() == frozenset())
        a = ZenohTransport("a", listen=[endpoints[0]], team="unit")
        assert wait_for(lambda: b.peers() == {"a"})
        a.publish("news", "again", QoS.RELIABLE)
        [again] = drain(b, 1)
        assert (again.payload, again.seq) == ("again", 4)  # its own count starts at 1; the receiver's goes on
    finally:
        a.close()
        b.close()


def test_what_a_sender_no_longer_keeps_is_counted_lost():
    ea, eb = free_endpoints(2)
    relay = LinkRelay(ea)
    clock = ManualClock(time.time())  # the history's age is on the agents' clock, moved by hand here
    a = ZenohTransport("a", listen=[ea], team="unit", history=0.3, clock=clock)
    b = ZenohTransport("b", listen=[eb], connect=[relay.endpoint], team="unit", clock=clock)
    try:
        b.subscribe("news")
        assert wait_for(lambda: b.peers() == {"a"})
        a.publish("news", "seen", QoS.RELIABLE)
        assert [e.payload for e in drain(b, 1)] == ["seen"]
        relay.cut()
        a.publish("news", "missed", QoS.RELIABLE)
        clock.advance(0.6)  # longer than a's history: publishing "after" drops "missed"
        a.publish("news", "after", QoS.RELIABLE)
        relay.heal()
        assert wait_for(lambda: b.peers() == {"a"})
        assert [e.payload for e in drain(b, 1)] == ["after"]
        assert b.stats.lost == 1
    finally:
        a.close()
        b.close()
        relay.close()


def test_the_history_is_bounded_in_bytes_and_what_it_drops_is_counted_lost():
    ea, eb = free_endpoints(2)
    relay = LinkRelay(ea)
    a = ZenohTransport("a", listen=[ea], team="unit", history_mb=0.002)  # about 2 KB: a dozen of these messages
    b = ZenohTransport("b", listen=[eb], connect=[relay.endpoint], team="unit")
    try:
        b.subscribe("news")
        assert wait_for(lambda: b.peers() == {"a"})
        a.publish("news", -1, QoS.RELIABLE)
        assert [e.payload for e in drain(b, 1)] == [-1]
        relay.cut()
        assert wait_for(lambda: b.peers() == frozenset())
        for i in range(50):
            a.publish("news", (i, "x" * 100), QoS.RELIABLE)
        relay.heal()
        assert wait_for(lambda: b.stats.lost > 0)
        got = [e.payload[0] for e in drain(b, 50 - b.stats.lost)]
        assert got == list(range(b.stats.lost, 50))  # the newest ones, in order; the oldest were dropped
        assert 5 < len(got) < 30
    finally:
        a.close()
        b.close()
        relay.close()


def test_a_partition_shorter_than_the_history_loses_nothing():
    ea, eb = free_endpoints(2)
    relay = LinkRelay(ea)
    a = ZenohTransport("a", listen=[ea], team="unit")
    b = ZenohTransport("b", listen=[eb], connect=[relay.endpoint], team="unit")
    try:
        b.subscribe("news")
        assert wait_for(lambda: b.peers() == {"a"})
        a.publish("news", "before", QoS.RELIABLE)
        assert [e.payload for e in drain(b, 1)] == ["before"]
        relay.cut()
        assert wait_for(lambda: b.peers() == frozenset())
        for i in range(50):
            a.publish("news", i, QoS.RELIABLE)
        relay.heal()
        assert [e.payload for e in drain(b, 50)] == list(range(50))
        assert b.stats.recovered == 50 and b.stats.lost == 0
    finally:
        a.close()
        b.close()
        relay.close()


def test_payloads_cross_processes_as_plain_data(endpoints):
    a, b = pair(endpoints)
    try:
        b.subscribe("alica/team")
        world = WorldModel("a")
        world.assert_fact("found", "s1")
        message = TeamMessage("a", 1.0, "Scout", (Claim(("Root",), "Root", "ep", "S"),))
        a.publish("alica/team", message, QoS.RELIABLE)
        a.publish("alica/team", world.snapshot(), QoS.RELIABLE)
        got = drain(b, 2)
        assert got[0].payload == message
        merged = WorldModel("b")
        merged.merge(got[1].payload)
        assert merged.holds("found", "s1")
    finally:
        a.close()
        b.close()


@pytest.mark.parametrize("topic", ["a*b", "x/$y", "bad topic", "/lead", "trail/", "a//b"])
def test_topics_must_be_zenoh_key_names(endpoints, topic):
    with ZenohTransport("a", listen=[endpoints[0]], team="unit") as a:
        with pytest.raises(ValueError, match="topic must be"):
            a.subscribe(topic)
        with pytest.raises(ValueError, match="topic must be"):
            a.publish(topic, 1)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"agent_id": "a/b"}, "agent id must be"),
        ({"agent_id": "a", "team": ""}, "team must be"),
        ({"agent_id": "a", "mode": "router"}, "mode must be"),
        ({"agent_id": "a", "lease": 0}, "lease must be"),
        ({"agent_id": "a", "connect": ["localhost"]}, "a zenoh endpoint looks like"),
        ({"agent_id": "a", "config": {"no/such/key": 1}}, "is not accepted"),
    ],
)
def test_bad_settings_are_refused_with_a_reason(options, message):
    with pytest.raises(ValueError, match=message):
        ZenohTransport(**options)


# ---------------------------------------------------------------------- the codec


class _Evil:
    def __reduce__(self):
        return (os.system, ("echo owned",))


def test_the_codec_refuses_functions_and_foreign_classes():
    with pytest.raises(CodecError, match="module 'posix' is not allowed|module 'os' is not allowed"):
        decode(pickle.dumps(_Evil()))
    with pytest.raises(CodecError, match="not allowed"):
        decode(pickle.dumps(pytest.approx(1.0)))
    with pytest.raises(CodecError, match="damaged payload"):
        decode(b"\x80\x05not a pickle")
    with pytest.raises(CodecError, match="plain data"):
        encode(lambda: None)


def test_the_codec_takes_a_users_module_once_allowed():
    with pytest.raises(CodecError, match="not allowed"):
        decode(pickle.dumps(_Plain(1)))
    allow_module(__name__)
    assert decode(pickle.dumps(_Plain(1))) == _Plain(1)
    with pytest.raises(ValueError, match="module name"):
        allow_module("")


from dataclasses import dataclass  # noqa: E402 (the user's message type of the test above)


@dataclass(frozen=True)
class _Plain:
    value: int


plain = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(),
    lambda inner: st.tuples(inner, inner) | st.frozensets(st.integers()).map(tuple),
    max_leaves=20,
)


@given(plain)
def test_plain_data_survives_the_codec(value):
    assert decode(encode(value)) == value


def test_a_payload_the_receiver_cannot_decode_is_skipped_and_the_stream_goes_on(endpoints):
    from fractions import Fraction

    a, b = pair(endpoints)
    try:
        b.subscribe("news")
        a.publish("news", "first", QoS.RELIABLE)
        a.publish("news", Fraction(1, 3), QoS.RELIABLE)  # pickles, but no receiver may build it
        a.publish("news", "third", QoS.RELIABLE)
        assert [e.payload for e in drain(b, 2)] == ["first", "third"]
        assert b.stats.undecodable == 1
        [(why, count)] = b.errors.items()
        assert count == 1 and why.startswith("a on news:") and "fractions" in why
    finally:
        a.close()
        b.close()


def test_every_payload_of_a_planning_team_crosses_the_codec(monkeypatch, tmp_path):
    """What the engine, the world model and pRoPhEt MAS (MAGiC included) publish, encoded and decoded."""
    from alica.app.cli import main
    from alica.comm import simnet
    from tests.conftest import blocks_mission_with_builtin

    publish = simnet.SimNetwork._publish
    kinds: set[str] = set()

    def checked(self, state, topic, payload, qos):
        assert decode(encode(payload)) == payload
        kinds.add(type(payload).__name__)
        return publish(self, state, topic, payload, qos)

    monkeypatch.setattr(simnet.SimNetwork, "_publish", checked)
    facts = "ontable(a) and on(c, a) and clear(c) and ontable(b) and clear(b) and handempty(r1) and handempty(r2)@0"
    argv = ["--agents", "r1:Manipulator,r2:Manipulator", "--stand-ins", "--fact", facts, "--parallel-planning"]
    assert main(["run", str(blocks_mission_with_builtin(tmp_path)), *argv]) == 0  # MAGiC: the builtin planner
    assert {"TeamMessage", "Delta", "PlanShare", "Share", "Final"} <= kinds


def test_a_busy_port_is_a_clear_error(endpoints):
    with ZenohTransport("a", listen=[endpoints[0]], team="unit"):
        with pytest.raises(ValueError, match="could not open a session listening on .* already in use"):
            ZenohTransport("b", listen=[endpoints[0]], team="unit")


def test_a_publishers_matching_status_is_an_object_whose_matching_says_it(endpoints):
    """zenoh's stubs call ``Publisher.matching_status`` a bool; CenterFeed reads ``.matching``, as the runtime has it."""
    import zenoh

    with ZenohTransport("a", listen=[endpoints[0]], team="unit") as a:
        publisher = a.session.declare_publisher("unit/nobody/listens")
        status = publisher.matching_status
        assert isinstance(status, zenoh.MatchingStatus) and status.matching is False
        publisher.undeclare()
