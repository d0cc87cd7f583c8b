"""Issue 37, findings 1, 5, 6: rogue frames on loopback are counted and dropped; the agent's transport goes on."""

from __future__ import annotations

import math

import zenoh

from alica.comm import QoS
from alica.comm.codec import encode
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints, zenoh_config
from alica.engine.team import WORLD_TOPIC
from tests.comm.test_zenoh import drain, wait_for
from tests.security.test_frames_checks import deep_frame


def test_rogue_frames_are_rejected_and_counted_and_delivery_goes_on():
    ea, eb = free_endpoints(2)
    a = ZenohTransport("a", listen=[ea], team="unit")
    b = ZenohTransport("b", listen=[eb], connect=[ea], team="unit")
    rogue = zenoh.open(zenoh_config((ea,), (), "peer", 2.0, None))
    try:
        assert wait_for(lambda: a.peers() == {"b"})
        a.subscribe("news")
        a.subscribe(WORLD_TOPIC)
        bad_number = encode(("1", "b", "news", 1, "one", 1, 0.0, encode("x")))  # non-int incarnation and rseq

        def rejected() -> bool:
            rogue.put("unit/m/b/news", bad_number)
            return a.stats.rejected.get("number", 0) > 0

        assert wait_for(rejected)  # the rogue's frames reach a
        rogue.put("unit/m/rogue/x", deep_frame(100_000))  # a topic nested 100,000 deep (before: a segfault)
        rogue.put("unit/m/b/news", encode((1, "zz", "news", 1, 0, 0, 0.0, encode("x"))))  # not its key's sender
        rogue.put("unit/hb/b", encode((math.inf, "b", {"news": 1})))  # an incarnation of inf
        rogue.put("unit/hb/b", encode((1, "b", ["news"])))  # numbers that are no dict
        world = encode((1, "rogue", WORLD_TOPIC, 1, 0, 0, 0.0, encode("found(a)")))  # well-formed: the engine drops it
        rogue.put(f"unit/m/rogue/{WORLD_TOPIC}", world)
        for rseq in range(5, 200):  # a forged sender's reliable frames after a gap: held only up to the cap
            rogue.put("unit/m/ghost/news", encode((1, "ghost", "news", rseq, rseq, rseq, 0.0, encode("x"))))
        b.publish("news", "still here", QoS.RELIABLE)
        got = drain(a, 2)
        assert [e.payload for e in got if e.sender == "b"] == ["still here"]
        assert [e.payload for e in got if e.sender == "rogue"] == ["found(a)"]
        assert wait_for(lambda: {"nesting", "sender", "number", "shape"} <= set(a.stats.rejected))
        assert not a.closed
    finally:
        rogue.close()
        b.close()
        a.close()
