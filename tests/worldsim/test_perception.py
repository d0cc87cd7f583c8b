"""FactPerception: the sensed facts put into each agent's world model, and wrong beliefs put right."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from alica.worldmodel.store import WorldModel
from alica.worldsim.perception import FactPerception


class _Team:
    def __init__(self, agents):
        self.world = SimpleNamespace(facts=set())
        self.engines = [SimpleNamespace(name=a, world_model=WorldModel(a)) for a in agents]
        self.t = 0.0

    def now(self):
        return self.t

    def running(self):
        return self.engines


def test_sensed_facts_are_written_and_stale_ones_retracted():
    team = _Team(["r1", "r2"])
    perception = FactPerception(lambda world: world.facts, every=0.2)
    team.world.facts = {("holding", "r1", "a"), ("clear", "b")}
    perception(team)
    for engine in team.engines:
        assert engine.world_model.holds("holding", "r1", "a") and engine.world_model.holds("clear", "b")
    team.t, team.world.facts = 0.2, {("handempty", "r1"), ("clear", "b"), ("clear", "a")}
    perception(team)
    wm = team.engines[0].world_model
    assert not wm.holds("holding", "r1", "a") and wm.holds("handempty", "r1") and wm.holds("clear", "a")


def test_a_wrong_belief_is_put_right_at_the_next_reading_and_other_facts_are_left_alone():
    team = _Team(["r1"])
    perception = FactPerception(lambda world: world.facts, every=0.2)
    team.world.facts = {("holding", "r1", "a")}
    perception(team)
    wm = team.engines[0].world_model
    # a skill (or a late message) says r1 holds nothing, although the world did not change
    wm.retract_fact("holding", "r1", "a")
    wm.assert_fact("handempty", "r1")
    wm.assert_fact("step_done", "P_s0")  # not a sensed predicate: kept
    team.t = 0.1
    perception(team)  # not due yet
    assert not wm.holds("holding", "r1", "a")
    team.t = 0.2
    perception(team)
    assert wm.holds("holding", "r1", "a") and wm.holds("step_done", "P_s0")
    assert wm.holds("handempty", "r1")  # never sensed: not this reader's predicate


def test_declared_predicates_are_kept_in_line_even_before_they_are_seen():
    team = _Team(["r1"])
    perception = FactPerception(lambda world: world.facts, every=0.2, predicates=["handempty"])
    team.engines[0].world_model.assert_fact("handempty", "r9")
    perception(team)
    assert not team.engines[0].world_model.holds("handempty", "r9")


def test_every_must_be_positive():
    with pytest.raises(ValueError, match="positive number of seconds"):
        FactPerception(lambda world: (), every=0)


def test_places_are_written_when_missing_or_moved_beyond_their_tolerance():
    team = _Team(["r1", "r2"])
    team.world.places = {"b": (1.0, 2.0, 0.05), "r1": (0.0, 0.0, 0.5)}
    perception = FactPerception(lambda world: (), every=0.2, places=lambda world: world.places)
    perception(team)
    for engine in team.engines:
        assert engine.world_model.get("pos", "b") == (1.0, 2.0) and engine.world_model.get("pos", "r1") == (0.0, 0.0)
    wm = team.engines[0].world_model
    # r1 drove 0.3 m (within its 0.5 m), b was moved 0.2 m (beyond its 0.05 m): only b is written again
    team.t, team.world.places = 0.2, {"b": (1.2, 2.0, 0.05), "r1": (0.3, 0.0, 0.5)}
    perception(team)
    assert wm.get("pos", "b") == (1.2, 2.0) and wm.get("pos", "r1") == (0.0, 0.0)
    team.t, team.world.places["r1"] = 0.4, (0.6, 0.0, 0.5)
    perception(team)
    assert wm.get("pos", "r1") == (0.6, 0.0)


def test_the_blocks_world_perception_places_the_blocks_lying_and_the_robots():
    from alica.worldsim.scenarios import blocks_places, blocksworld

    world = blocksworld([["a", "b"], ["c"]], agents=2, seed=0)
    try:
        places = blocks_places(world)
        assert {"a", "b", "c", "r1", "r2"} <= set(places)
        a, c = world.objects["a"].position(), world.objects["c"].position()
        assert places["a"][:2] == pytest.approx((a[0], a[1])) and places["c"][:2] == pytest.approx((c[0], c[1]))
        assert places["r1"][:2] == pytest.approx(world.robots["r1"].pose[:2])
    finally:
        world.close()
