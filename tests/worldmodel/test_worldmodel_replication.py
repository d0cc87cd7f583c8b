"""Replication: deltas, merge, the Lamport rule, snapshots, digests, on_change, ttl."""

from __future__ import annotations

import dataclasses

import pytest

from alica.clock import ManualClock
from alica.worldmodel import Add, Delta, Digest, Key, Stamp, WorldModel, Write


def pair() -> tuple[WorldModel, WorldModel]:
    return WorldModel("a"), WorldModel("b")


# -- take_delta ------------------------------------------------------------------


def test_take_delta_hands_out_local_writes_once() -> None:
    a = WorldModel("a")
    assert a.take_delta() is None
    a.set("pos", "a", value=(0, 0))
    a.set("pos", "a", value=(1, 1))
    a.assert_fact("found", "s1")
    a.add_to_set("invalid", "c1")
    a.add_object("s1", "Sample")
    delta = a.take_delta()
    assert delta is not None
    assert len(delta) == 4  # only the latest write to pos(a)
    assert [w.value for w in delta.writes if w.name == "pos"] == [(1, 1)]
    assert a.take_delta() is None


def test_take_delta_relays_entries_merged_as_new() -> None:
    a, b = pair()
    c = WorldModel("c", relay=False)
    a.assert_fact("found", "s1")
    delta = a.take_delta()
    assert delta is not None
    b.merge(delta)
    c.merge(delta)
    relayed = b.take_delta()
    assert relayed is not None and relayed.sorted_keys() == [Key("register", "found", ("s1",))]
    assert c.take_delta() is None
    b.merge(delta)
    assert b.take_delta() is None  # nothing new the second time


def test_deltas_are_immutable_plain_data() -> None:
    a = WorldModel("a")
    a.set("pos", "a", value=(1.0, 2.0))
    delta = a.take_delta()
    assert delta is not None
    with pytest.raises(dataclasses.FrozenInstanceError):
        delta.writes = ()  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        delta.writes[0].value = 3  # type: ignore[misc]
    assert isinstance(delta.writes, tuple)
    listed = Delta([delta.writes[0]])  # type: ignore[arg-type]
    assert isinstance(listed.writes, tuple)
    with pytest.raises(TypeError, match="Write entries only"):
        Delta(writes=("x",))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="Add entries only"):
        Delta(adds=(delta.writes[0],))  # type: ignore[arg-type]


def test_entries_validate_their_fields() -> None:
    with pytest.raises(TypeError, match="Stamp"):
        Write("pos", ("a",), 1, (1, "a"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="tuple"):
        Write("pos", ["a"], 1, Stamp(1, "a"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="expires"):
        Write("pos", ("a",), 1, Stamp(1, "a"), expires="soon")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="'set' or an 'object'"):
        Add("bag", "s", 1, Stamp(1, "a"))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="Stamp"):
        Add("set", "s", 1, None)  # type: ignore[arg-type]


# -- merge -----------------------------------------------------------------------


def test_merge_returns_changed_keys_and_is_idempotent() -> None:
    a, b = pair()
    a.set("pos", "a", value=(1, 2))
    a.add_to_set("invalid", "c1")
    delta = a.take_delta()
    assert delta is not None
    assert b.merge(delta) == {Key("register", "pos", ("a",)), Key("set", "invalid", ("c1",))}
    assert b.merge(delta) == frozenset()
    assert b.get("pos", "a") == (1, 2)
    assert b.dumps() == a.dumps()


def test_merge_rejects_other_things() -> None:
    with pytest.raises(TypeError, match="merge takes a Delta"):
        WorldModel("a").merge({"pos": 1})  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="Digest"):
        WorldModel("a").missing_for("digest")  # type: ignore[arg-type]


def test_older_writes_lose() -> None:
    a, b = pair()
    a.set("pos", "x", value=1)
    old = a.take_delta()
    a.set("pos", "x", value=2)
    new = a.take_delta()
    assert old is not None and new is not None
    b.merge(new)
    assert b.merge(old) == frozenset()
    assert b.get("pos", "x") == 2


def test_lamport_rule_a_write_after_a_merge_wins() -> None:
    a, b = pair()
    for step in range(10):
        a.set("pos", "x", value=step)
    delta = a.take_delta()
    assert delta is not None
    assert b.counter == 0
    b.merge(delta)
    assert b.counter == 10
    stamp = b.set("pos", "x", value="mine")
    assert stamp == Stamp(11, "b")
    assert stamp > delta.writes[0].stamp
    a.merge(b.snapshot())
    assert a.get("pos", "x") == "mine"


def test_concurrent_writes_resolve_by_writer_id() -> None:
    a, b = pair()
    a.set("pos", "x", value="from a")
    b.set("pos", "x", value="from b")  # same counter 1: writer "b" > "a"
    da, db = a.take_delta(), b.take_delta()
    assert da is not None and db is not None
    a.merge(db)
    b.merge(da)
    assert a.get("pos", "x") == b.get("pos", "x") == "from b"
    assert a.dumps() == b.dumps()


def test_tombstones_converge() -> None:
    a, b = pair()
    a.set("pos", "x", value=1)
    b.merge(a.snapshot())
    b.unset("pos", "x")
    a.merge(b.snapshot())
    assert a.get("pos", "x") is None and b.get("pos", "x") is None
    assert a.dumps() == b.dumps()
    late = WorldModel("c")
    late.merge(b.snapshot())
    late.merge(a.snapshot())
    assert late.get("pos", "x") is None


def test_a_retracted_fact_converges_and_stays_known() -> None:
    a, b = pair()
    a.assert_fact("found", "s1")
    b.merge(a.snapshot())
    b.retract_fact("found", "s1")
    a.merge(b.snapshot())
    assert a.lookup("found", ("s1",)) is False
    assert a.lookup("found", ("s2",)) is False


def test_equal_stamps_with_different_content_still_converge() -> None:
    # Two agents misconfigured with the same id: equal stamps, different writes.
    one, two = WorldModel("dup"), WorldModel("dup")
    one.set("pos", "x", value=1)
    two.set("pos", "x", value=2)
    d1, d2 = one.snapshot(), two.snapshot()
    one.merge(d2)
    two.merge(d1)
    assert one.dumps() == two.dumps()


def test_equal_keys_of_different_types_converge_to_one_spelling() -> None:
    # 1 and 1.0 are the same key in Python; every replica must spell it the same way.
    a, b = pair()
    a.set("p", 1, value="int")
    a.add_to_set("s", 1)
    b.set("p", 1.0, value="float")
    b.add_to_set("s", 1.0)
    da, db = a.snapshot(), b.snapshot()
    x, y = WorldModel("x"), WorldModel("y")
    x.merge(da)
    x.merge(db)
    y.merge(db)
    y.merge(da)
    assert x.dumps() == y.dumps()
    assert x.get("p", 1) == "float"  # (1, "b") > (1, "a")
    assert x.members("s") == {1}


# -- snapshot and digests ----------------------------------------------------------


def test_snapshot_lets_a_peer_rejoin() -> None:
    a = WorldModel("a")
    a.set("pos", "a", value=(1, 2))
    a.assert_fact("found", "s1")
    a.add_object("s1", "Sample")
    snap = a.snapshot()
    assert a.snapshot() is snap  # cached while unchanged
    late = WorldModel("late")
    late.merge(snap)
    assert late.dumps() == a.dumps()
    a.add_object("s2", "Sample")
    assert a.snapshot() is not snap


def test_digest_tells_whether_states_differ() -> None:
    a, b = pair()
    assert a.digest().same_state(b.digest())
    a.assert_fact("found", "s1")
    assert not a.digest().same_state(b.digest())
    b.merge(a.snapshot())
    assert a.digest().same_state(b.digest())
    assert a.digest() == b.digest()
    assert a.digest().clock == (("a", 1),)
    assert isinstance(a.digest(), Digest)


def test_missing_for_equal_states_is_empty() -> None:
    a, b = pair()
    a.set("pos", "a", value=1)
    b.merge(a.snapshot())
    assert len(a.missing_for(b.digest())) == 0


def test_missing_for_sends_what_the_peer_lacks() -> None:
    a, b = pair()
    for index in range(20):
        a.set("pos", f"r{index}", value=index)
    b.merge(a.snapshot())
    a.add_to_set("invalid", "c1")
    missing = a.missing_for(b.digest())
    assert Key("set", "invalid", ("c1",)) in missing.sorted_keys()
    assert len(missing) < len(a.snapshot())  # only the differing buckets
    b.merge(missing)
    assert b.dumps() == a.dumps()


def test_missing_for_does_not_trust_counters_after_a_lost_delta() -> None:
    # b sees a's write 2 but its write 1 was dropped: b's clock says a:2, yet b lacks write 1.
    a, b = pair()
    a.assert_fact("found", "s1")
    lost = a.take_delta()
    a.assert_fact("found", "s2")
    delivered = a.take_delta()
    assert lost is not None and delivered is not None
    b.merge(delivered)
    assert b.digest().clock == (("a", 2),)
    b.merge(a.missing_for(b.digest()))
    assert b.holds("found", "s1")
    assert b.dumps() == a.dumps()


def test_missing_for_with_other_bucket_counts_sends_everything() -> None:
    a, b = WorldModel("a", buckets=8), WorldModel("b", buckets=16)
    a.set("pos", "a", value=1)
    a.add_object("s", "Sample")
    assert a.missing_for(b.digest()) == a.snapshot()


# -- on_change -----------------------------------------------------------------------


def test_on_change_after_local_writes_and_merges() -> None:
    a, b = pair()
    seen: list[frozenset[Key]] = []
    unsubscribe = b.on_change(seen.append)
    b.set("pos", "b", value=1)
    assert seen == [{Key("register", "pos", ("b",))}]
    a.assert_fact("found", "s1")
    a.add_object("s1", "Sample")
    b.merge(a.snapshot())
    assert seen[-1] == {Key("register", "found", ("s1",)), Key("object", "Sample", ("s1",))}
    count = len(seen)
    b.merge(a.snapshot())  # nothing new: no call
    b.add_object("s1", "Sample")  # present: no call
    assert len(seen) == count
    unsubscribe()
    unsubscribe()
    b.set("pos", "b", value=2)
    assert len(seen) == count


def test_listeners_see_the_updated_state() -> None:
    wm = WorldModel("a")
    observed: list[object] = []
    wm.on_change(lambda keys: observed.append(wm.lookup("found", ("s1",))))
    wm.assert_fact("found", "s1")
    assert observed == [True]


# -- ttl -------------------------------------------------------------------------------


def test_ttl_needs_a_clock_and_a_positive_duration() -> None:
    with pytest.raises(ValueError, match="needs a clock"):
        WorldModel("a").set("pos", "a", value=1, ttl=1.0)
    wm = WorldModel("a", clock=ManualClock())
    for bad in (0, -1, float("inf"), True, "1"):
        with pytest.raises(ValueError, match="positive number"):
            wm.set("pos", "a", value=1, ttl=bad)  # type: ignore[arg-type]


def test_values_with_ttl_go_stale_on_every_replica() -> None:
    clock = ManualClock()
    a, b = WorldModel("a", clock=clock), WorldModel("b", clock=clock)
    a.set("seen", "rock", value=(3, 4), ttl=2.0)
    a.set("pos", "a", value=(0, 0))
    b.merge(a.snapshot())
    changes: list[frozenset[Key]] = []
    b.on_change(changes.append)
    clock.advance(1.0)
    assert b.refresh() == frozenset()
    assert b.get("seen", "rock") == (3, 4)
    clock.advance(1.5)
    assert b.refresh() == {Key("register", "seen", ("rock",))}
    assert changes == [{Key("register", "seen", ("rock",))}]
    assert b.get("seen", "rock") is None
    assert b.lookup("seen", ("rock",)) is None
    assert b.get("pos", "a") == (0, 0)
    a.refresh()
    assert a.dumps() == b.dumps()  # the stored state still converges


def test_an_expired_write_arriving_late_is_stale_at_once() -> None:
    clock = ManualClock()
    a, b = WorldModel("a", clock=clock), WorldModel("b", clock=clock)
    a.set("seen", "rock", value=1, ttl=1.0)
    delta = a.take_delta()
    assert delta is not None
    clock.advance(5)
    b.merge(delta)
    assert b.get("seen", "rock") is None
    assert b.stamp_of("seen", "rock") == delta.writes[0].stamp


def test_a_fresh_write_replaces_an_expiring_one() -> None:
    clock = ManualClock()
    wm = WorldModel("a", clock=clock)
    wm.set("seen", "rock", value=1, ttl=1.0)
    wm.set("seen", "rock", value=2)
    clock.advance(3)
    assert wm.refresh() == frozenset()
    assert wm.get("seen", "rock") == 2


def test_expiry_happens_at_the_next_write_too() -> None:
    clock = ManualClock()
    wm = WorldModel("a", clock=clock)
    wm.set("seen", "rock", value=1, ttl=1.0)
    clock.advance(2)
    seen: list[frozenset[Key]] = []
    wm.on_change(seen.append)
    wm.set("pos", "a", value=0)
    assert seen == [{Key("register", "seen", ("rock",)), Key("register", "pos", ("a",))}]
    assert wm.get("seen", "rock") is None
