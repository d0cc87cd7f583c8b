"""Issue 37, findings 2, 4 and 7 on loopback without credentials.

2. Frames from a name outside the roster are dropped and counted, never delivered (so never merged).
4. A forged incarnation cannot silence an agent for good: one from beyond the hosts' clocks is refused,
   one just ahead silences the real sender only until the forgery has been quiet for the inbox's quiet time.
7. A second session with a live agent's name refuses to start (or is told to stop, when it started in a
   partition), and the teammates keep hearing the first one.
"""

from __future__ import annotations

import time

import pytest
import zenoh

from alica.comm import QoS
from alica.comm.codec import encode
from alica.comm.relay import LinkRelay
from alica.comm.zenoh_transport import NameTaken, ZenohTransport, free_endpoints, zenoh_config
from alica.engine.team import WORLD_TOPIC
from tests.comm.test_zenoh import drain, wait_for


def _frame(sender: str, topic: str, payload: object, *, incarnation: int = 1, rseq: int = 0) -> bytes:
    return encode((incarnation, sender, topic, 1, rseq, rseq, 0.0, encode(payload)))


def test_frames_and_tokens_from_outside_the_roster_are_dropped_and_counted():
    ea, eb = free_endpoints(2)
    a = ZenohTransport("a", listen=[ea], team="unit", roster=["a", "b"])
    b = ZenohTransport("b", listen=[eb], connect=[ea], team="unit", roster=["a", "b"])
    stranger = ZenohTransport("stranger", connect=[ea], team="unit")
    rogue = zenoh.open(zenoh_config((ea,), (), "peer", 2.0, None))
    try:
        a.subscribe(WORLD_TOPIC)
        assert wait_for(lambda: a.peers() == {"b"} and a.stats.rejected.get("roster", 0) >= 1)  # stranger's token
        rogue.put(f"unit/m/rogue/{WORLD_TOPIC}", _frame("rogue", WORLD_TOPIC, "found(a)"))
        rogue.put("unit/hb/rogue", encode((1, "rogue", {WORLD_TOPIC: 3})))
        stranger.publish(WORLD_TOPIC, "found(b)", QoS.RELIABLE)
        assert wait_for(lambda: a.stats.rejected.get("roster", 0) >= 4)
        b.publish(WORLD_TOPIC, "from b", QoS.RELIABLE)
        got = drain(a, 1)
        assert [(e.sender, e.payload) for e in got] == [("b", "from b")]
        assert a.peers() == {"b"}
    finally:
        rogue.close()
        stranger.close()
        b.close()
        a.close()


def test_an_incarnation_beyond_the_hosts_clocks_is_refused():
    ea, eb = free_endpoints(2)
    a = ZenohTransport("a", listen=[ea], team="unit")
    b = ZenohTransport("b", listen=[eb], connect=[ea], team="unit")
    rogue = zenoh.open(zenoh_config((ea,), (), "peer", 2.0, None))
    try:
        a.subscribe("news")
        assert wait_for(lambda: a.peers() == {"b"})
        rogue.put("unit/hb/b", encode((2**63 - 1, "b", {"news": 1})))  # before: b was silenced for good
        assert wait_for(lambda: a.stats.rejected.get("number", 0) >= 1)
        b.publish("news", "heard", QoS.RELIABLE)
        assert [e.payload for e in drain(a, 1)] == ["heard"]
    finally:
        rogue.close()
        b.close()
        a.close()


def test_a_forged_incarnation_silences_a_sender_only_while_the_forger_speaks():
    ea, eb = free_endpoints(2)
    a = ZenohTransport("a", listen=[ea], team="unit", lease=0.2)  # quiet after 2 s
    b = ZenohTransport("b", listen=[eb], connect=[ea], team="unit")
    rogue = zenoh.open(zenoh_config((ea,), (), "peer", 2.0, None))
    try:
        a.subscribe("news")
        assert wait_for(lambda: a.peers() == {"b"})
        ahead = time.time_ns() + 60 * 10**9  # within the clocks' skew: taken
        rogue.put("unit/m/b/news", _frame("b", "news", "forged", incarnation=ahead))
        assert [e.payload for e in drain(a, 1)] == ["forged"]
        b.publish("news", "real", QoS.RELIABLE)  # b's incarnation looks old now
        assert drain(a, 1, timeout=0.5) == []
        # before the fix b stayed silenced for good, also when restarted; now it speaks again once the forgery is quiet
        got = drain(a, 1, timeout=15.0)
        assert [e.payload for e in got] == ["real"]
    finally:
        rogue.close()
        b.close()
        a.close()


def test_a_second_agent_with_a_live_name_refuses_to_start_and_the_teammate_keeps_the_first():
    ea, eb, ec = free_endpoints(3)
    a = ZenohTransport("a", listen=[ea], team="unit")
    b = ZenohTransport("b", listen=[eb], connect=[ea], team="unit")
    try:
        a.subscribe("news")
        assert wait_for(lambda: a.peers() == {"b"})
        with pytest.raises(NameTaken, match="another agent named 'b'"):
            ZenohTransport("b", listen=[ec], connect=[ea, eb], team="unit")
        b.publish("news", "still b", QoS.RELIABLE)
        # before the fix the duplicate started, and its newer incarnation silenced the real b for good
        assert [e.payload for e in drain(a, 1)] == ["still b"]
        assert a.peers() == {"b"}
    finally:
        b.close()
        a.close()


def test_a_duplicate_started_in_a_partition_is_told_to_stop_when_it_heals():
    ea, ef, es = free_endpoints(3)
    a = ZenohTransport("a", listen=[ea], team="unit")
    first = ZenohTransport("b", listen=[ef], connect=[ea], team="unit")
    relay = LinkRelay(ef)
    relay.cut()
    taken: list[str] = []
    # zenoh peers do not forward between peers: through a, the second does not see the first's token
    second = ZenohTransport("b", listen=[es], connect=[ea, relay.endpoint], team="unit", on_name_taken=taken.append)
    try:
        a.subscribe("news")
        assert wait_for(lambda: a.peers() == {"b"})
        second.publish("news", "second b", QoS.RELIABLE)  # a takes the newer incarnation's frames meanwhile
        assert [e.payload for e in drain(a, 1)] == ["second b"]
        relay.heal()
        assert wait_for(lambda: bool(taken), timeout=10.0)
        assert second.name_taken == taken[0] and "another agent named 'b'" in taken[0]
        assert first.name_taken is None  # the older one is not told to stop
        second.close()  # the agent stops, as told
        assert wait_for(lambda: a.peers() == {"b"})
        first.publish("news", "first b", QoS.RELIABLE)
        assert [e.payload for e in drain(a, 1)] == ["first b"]  # the teammate hears the first b again at once
    finally:
        second.close()
        relay.close()
        first.close()
        a.close()
