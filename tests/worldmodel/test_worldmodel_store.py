"""Local operations of the WorldModel: registers, facts, sets, objects, lookup, listings."""

from __future__ import annotations

import json
from enum import IntEnum

import numpy as np
import pytest

from alica.lang import BeliefBase
from alica.lang.fact import Fact
from alica.worldmodel import Key, LamportClock, Stamp, WorldModel, order_key


def test_is_a_belief_base() -> None:
    assert isinstance(WorldModel("scout"), BeliefBase)


def test_agent_id_must_be_a_non_empty_string() -> None:
    with pytest.raises(ValueError, match="agent id"):
        WorldModel("")
    with pytest.raises(ValueError, match="agent id"):
        WorldModel(7)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="buckets"):
        WorldModel("a", buckets=0)


# -- registers -------------------------------------------------------------


def test_set_get_and_overwrite() -> None:
    wm = WorldModel("scout")
    first = wm.set("pos", "scout", value=(1.0, 2.0))
    assert wm.get("pos", "scout") == (1.0, 2.0)
    second = wm.set("pos", "scout", value=(3.0, 4.0))
    assert wm.get("pos", "scout") == (3.0, 4.0)
    assert second > first
    assert wm.stamp_of("pos", "scout") == second
    assert wm.lookup("pos", ("scout",)) == (3.0, 4.0)


def test_zero_ary_register() -> None:
    wm = WorldModel("scout")
    wm.set("battery", value=0.5)
    assert wm.get("battery") == 0.5
    assert wm.lookup("battery", ()) == 0.5


def test_get_default_for_missing_and_unhashable() -> None:
    wm = WorldModel("scout")
    assert wm.get("pos", "x") is None
    assert wm.get("pos", "x", default=(0, 0)) == (0, 0)
    assert wm.get("pos", ["x"], default=1) == 1


def test_unset_writes_a_tombstone() -> None:
    wm = WorldModel("scout")
    wm.set("pos", "a", value=(1, 1))
    tombstone = wm.unset("pos", "a")
    assert wm.get("pos", "a") is None
    assert wm.lookup("pos", ("a",)) is None  # a function, not a predicate: unknown, not False
    assert wm.stamp_of("pos", "a") == tombstone  # the tombstone is stored
    assert wm.to_json()["registers"][0]["value"] is None


def test_set_none_is_unset() -> None:
    wm = WorldModel("scout")
    wm.set("pos", "a", value=(1, 1))
    wm.set("pos", "a", value=None)
    assert wm.get("pos", "a") is None
    assert wm.stamp_of("pos", "a") is not None


def test_values_must_be_plain_data() -> None:
    wm = WorldModel("scout")
    with pytest.raises(ValueError, match="tuple instead"):
        wm.set("pos", "a", value=[1, 2])
    with pytest.raises(ValueError, match="dict"):
        wm.set("pos", "a", value={"x": 1})
    with pytest.raises(ValueError, match="argument of pos"):
        wm.set("pos", object(), value=1)
    with pytest.raises(ValueError, match="NaN"):
        wm.set("pos", float("nan"), value=1)
    with pytest.raises(ValueError, match="register name"):
        wm.set("", value=1)
    with pytest.raises(ValueError, match="item of s"):
        wm.add_to_set("s", [1])
    with pytest.raises(ValueError, match="type name"):
        wm.add_object("a", "")
    assert wm.counter == 0  # refused writes use no stamp
    assert wm.take_delta() is None


def test_nan_is_allowed_as_a_value() -> None:
    wm = WorldModel("scout")
    wm.set("reading", value=float("nan"))
    assert wm.get("reading") != wm.get("reading")


def test_numeric_subclasses_are_stored_as_plain_types() -> None:
    class Level(IntEnum):
        LOW = 1

    wm = WorldModel("scout")
    wm.set("pos", "a", value=(np.float64(1.5), np.int64(2)))
    wm.set("level", Level.LOW, value=Level.LOW)
    value = wm.get("pos", "a")
    assert value == (1.5, 2)
    assert [type(item) for item in value] == [float, int]  # type: ignore[union-attr]
    assert type(wm.get("level", 1)) is int
    assert json.loads(wm.dumps())


# -- facts and the closed world --------------------------------------------


def test_assert_retract_holds() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "a")
    assert wm.holds("found", "a")
    assert wm.lookup("found", ("a",)) is True
    wm.retract_fact("found", "a")
    assert not wm.holds("found", "a")
    assert wm.lookup("found", ("a",)) is False


def test_closed_world_for_known_predicates_only() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "a")
    assert wm.lookup("found", ("b",)) is False  # known predicate, same arity
    assert wm.lookup("found", ("a", "b")) is None  # other arity: unknown
    assert wm.lookup("explored", ()) is None  # never written
    wm.retract_fact("explored")
    assert wm.lookup("explored", ()) is False


def test_retract_keeps_the_predicate_known_unset_does_not() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "a")
    wm.retract_fact("found", "a")
    assert wm.lookup("found", ("z",)) is False
    wm.unset("found", "a")
    assert wm.lookup("found", ("z",)) is None


def test_boolean_function_values_make_a_predicate() -> None:
    wm = WorldModel("scout")
    wm.set("charged", "r1", value=True)
    assert wm.holds("charged", "r1")
    assert wm.lookup("charged", ("r2",)) is False
    wm.set("charged", "r1", value=0.7)  # no longer a truth value: predicate unknown again
    assert wm.lookup("charged", ("r2",)) is None


def test_unhashable_lookup_is_unknown() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "a")
    assert wm.lookup("found", (["a"],)) is None
    wm.add_to_set("s", "x")
    assert wm.lookup("s", (["x"],)) is None


# -- sets and objects --------------------------------------------------------


def test_grow_only_sets() -> None:
    wm = WorldModel("scout")
    assert wm.add_to_set("invalid_candidates", "c1")
    assert not wm.add_to_set("invalid_candidates", "c1")  # present: no write
    assert wm.add_to_set("invalid_candidates", ("cell", 3, 4))
    assert wm.members("invalid_candidates") == frozenset({"c1", ("cell", 3, 4)})
    assert wm.members("nothing") == frozenset()
    assert wm.set_names() == ["invalid_candidates"]
    assert wm.counter == 2


def test_set_membership_is_visible_to_lookup() -> None:
    wm = WorldModel("scout")
    assert wm.lookup("invalid_candidates", ("c1",)) is None  # unknown set
    wm.add_to_set("invalid_candidates", "c1")
    assert wm.lookup("invalid_candidates", ("c1",)) is True
    assert wm.lookup("invalid_candidates", ("c2",)) is False
    assert wm.lookup("invalid_candidates", ("c1", "c2")) is None
    assert wm.holds("invalid_candidates", "c1")


def test_registers_are_looked_up_before_sets() -> None:
    wm = WorldModel("scout")
    wm.add_to_set("mark", "a")
    wm.set("mark", "a", value=5)
    assert wm.lookup("mark", ("a",)) == 5
    assert wm.lookup("mark", ("b",)) is False


def test_members_cache_follows_changes() -> None:
    wm = WorldModel("scout")
    wm.add_to_set("s", "a")
    first = wm.members("s")
    assert wm.members("s") is first
    wm.add_to_set("s", "b")
    assert wm.members("s") == frozenset({"a", "b"})


def test_objects_in_a_stable_sorted_order() -> None:
    wm = WorldModel("scout")
    for obj in ["s10", "b", "s2", "a"]:
        wm.add_object(obj, "Sample")
    assert wm.objects("Sample") == ("a", "b", "s10", "s2")
    assert wm.objects("Sample") is wm.objects("Sample")  # cached
    assert not wm.add_object("a", "Sample")
    wm.add_object("0", "Sample")
    assert wm.objects("Sample") == ("0", "a", "b", "s10", "s2")
    assert wm.objects("Robot") == ()
    assert wm.types() == ["Sample"]


def test_objects_of_mixed_kinds_sort_without_errors() -> None:
    wm = WorldModel("scout")
    for obj in ["x", 3, (1, "a"), 1.5, None, True]:
        wm.add_object(obj, "Thing")
    assert wm.objects("Thing") == (None, True, 1.5, 3, "x", (1, "a"))


def test_order_key_is_total_over_plain_data() -> None:
    items = [(2, "a"), "b", 1, None, False, 0.5, ("a",), ()]
    ordered = sorted(items, key=order_key)
    assert ordered == [None, False, 0.5, 1, "b", (), (2, "a"), ("a",)]


# -- listings ------------------------------------------------------------------


def test_facts_and_values_listings() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "b")
    wm.assert_fact("found", "a")
    wm.retract_fact("found", "c")
    wm.set("pos", "scout", value=(1.0, 2.0))
    wm.add_to_set("invalid", "c9")
    assert wm.facts() == [Fact("found", ("a",)), Fact("found", ("b",)), Fact("invalid", ("c9",))]
    assert wm.values() == [("pos", ("scout",), (1.0, 2.0))]


def test_to_json_is_json_and_sorted() -> None:
    wm = WorldModel("scout")
    wm.set("pos", "b", value=(1, 2))
    wm.set("pos", "a", value=(3, 4))
    wm.add_object("s1", "Sample")
    wm.add_to_set("invalid", ("cell", 1))
    data = json.loads(wm.dumps())
    assert [row["args"] for row in data["registers"]] == [["a"], ["b"]]
    assert data["sets"] == [{"name": "invalid", "item": ["cell", 1], "stamp": [4, "scout"]}]
    assert data["objects"] == [{"type": "Sample", "object": "s1", "stamp": [3, "scout"]}]
    assert wm.to_json() == data


def test_repr_mentions_the_agent() -> None:
    wm = WorldModel("scout")
    wm.assert_fact("found", "a")
    assert "scout" in repr(wm) and "counter 1" in repr(wm)


# -- stamps and keys -------------------------------------------------------------


def test_stamps_order_by_counter_then_writer() -> None:
    assert Stamp(2, "a") > Stamp(1, "z")
    assert Stamp(2, "b") > Stamp(2, "a")
    assert Stamp(2, "b") == Stamp(2, "b")
    assert str(Stamp(3, "scout")) == "3@scout"
    with pytest.raises(ValueError, match="counter"):
        Stamp(0, "a")
    with pytest.raises(ValueError, match="writer"):
        Stamp(1, "")


def test_lamport_clock() -> None:
    clock = LamportClock("a")
    assert clock.peek() == Stamp(1, "a")
    assert clock.tick() == Stamp(1, "a")
    clock.observe(10)
    clock.observe(4)
    assert clock.counter == 10
    assert clock.tick() == Stamp(11, "a")


def test_keys_sort_deterministically() -> None:
    keys = {Key("set", "s", ("x",)), Key("register", "pos", (2,)), Key("register", "pos", ("a",))}
    assert sorted(keys) == [Key("register", "pos", (2,)), Key("register", "pos", ("a",)), Key("set", "s", ("x",))]
    assert str(Key("register", "pos", ("a",))) == "register:pos('a')"


def test_the_world_model_offers_its_protocol() -> None:
    from alica.worldmodel import WorldModelLike

    wm: WorldModelLike = WorldModel("scout")
    wm.assert_fact("found", "a")
    assert isinstance(wm, WorldModelLike) and wm.facts() == [Fact("found", ("a",))]
    assert not isinstance(object(), WorldModelLike)
