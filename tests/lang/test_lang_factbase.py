"""The in-memory FactBase."""

from __future__ import annotations

from alica.lang import BeliefBase, FactBase


def test_is_a_belief_base() -> None:
    assert isinstance(FactBase(), BeliefBase)


def test_facts_and_closed_world() -> None:
    fb = FactBase()
    assert fb.lookup("On", ("a", "b")) is None  # nothing known about On/2
    fb.add("On", "a", "b")
    assert fb.lookup("On", ("a", "b")) is True
    assert fb.lookup("On", ("b", "a")) is False
    assert fb.lookup("On", ("a",)) is None  # a different arity
    assert fb.remove("On", "a", "b")
    assert not fb.remove("On", "a", "b")
    assert fb.lookup("On", ("a", "b")) is False
    fb.declare("Clear", 1)
    assert fb.lookup("Clear", ("a",)) is False


def test_values() -> None:
    fb = FactBase(values={("Pos", "f1"): (1, 2), "eps": 0.5})
    assert fb.lookup("Pos", ("f1",)) == (1, 2)
    assert fb.lookup("Pos", ("f2",)) is None
    assert fb.lookup("eps", ()) == 0.5
    fb.set("Pos", "f1", value=(3, 4))
    assert fb.value("Pos", "f1") == (3, 4)
    fb.unset("Pos", "f1")
    assert fb.lookup("Pos", ("f1",)) is None
    fb.set("eps", value=None)
    assert fb.lookup("eps", ()) is None


def test_objects() -> None:
    fb = FactBase(objects={"Block": ["a", "b"]})
    fb.add_object("c", "Block")
    fb.add_object("a", "Block")
    fb.add_object((1, 2), "Cell")
    assert fb.objects("Block") == ("a", "b", "c")
    assert fb.objects("Cell") == ((1, 2),)
    assert fb.objects("None") == ()
    fb.remove_object("b", "Block")
    assert fb.objects("Block") == ("a", "c")
    assert fb.types() == ["Block", "Cell"]


def test_constructor_facts_and_membership() -> None:
    fb = FactBase(facts=[("On", "a", "g"), "explored", ("At", 1, 2)])
    assert ("On", "a", "g") in fb
    assert "explored" in fb
    assert ("At", 1, 2) in fb
    assert ("On", "g", "a") not in fb
    assert 3 not in fb
    assert fb.holds("At", 1, 2)
    assert sorted(fb.facts(), key=repr) == sorted([("On", "a", "g"), ("explored",), ("At", 1, 2)], key=repr)


def test_unhashable_arguments_look_up_as_unknown() -> None:
    fb = FactBase(facts=[("On", "a", "g")])
    assert fb.lookup("On", ([1], "g")) is None


def test_copy_is_independent() -> None:
    fb = FactBase(facts=["x"], objects={"T": ["a"]}, values={"v": 1})
    other = fb.copy()
    other.add("y")
    other.add_object("b", "T")
    other.set("v", value=2)
    assert "y" not in fb
    assert fb.objects("T") == ("a",)
    assert fb.lookup("v", ()) == 1
