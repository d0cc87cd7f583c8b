"""Formulas of the plan language evaluated directly against a WorldModel."""

from __future__ import annotations

import pytest

from alica.errors import EvaluationError
from alica.lang import compile_formula, evaluate, holds
from alica.worldmodel import WorldModel


@pytest.fixture
def wm() -> WorldModel:
    model = WorldModel("scout")
    model.assert_fact("found", "a")
    model.retract_fact("found", "b")
    model.set("pos", "scout", value=(1.0, 2.0))
    model.set("pos", "a", value=(4.0, 6.0))
    model.set("eps", value=0.5)
    model.add_to_set("invalid_candidates", "c1")
    for sample in ("a", "b"):
        model.add_object(sample, "Sample")
    model.add_object("scout", "Robot")
    return model


def test_facts_and_closed_world(wm: WorldModel) -> None:
    assert holds("found(a) and not holds_block(b)", wm)
    assert holds("found(a) and not found(b)", wm)
    assert not holds("found(c)", wm)  # known predicate: missing is false
    assert not holds("explored", wm)  # unknown 0-ary fact: false


def test_set_membership_in_formulas(wm: WorldModel) -> None:
    assert holds("invalid_candidates(c1)", wm)
    assert not holds("invalid_candidates(c2)", wm)
    assert holds("exists s in Sample: found(s) and not invalid_candidates(s)", wm)


def test_quantifiers_range_over_objects(wm: WorldModel) -> None:
    assert holds("exists s in Sample: found(s)", wm)
    assert not holds("forall s in Sample: found(s)", wm)
    assert holds("forall r in Robot: pos(r).x >= 0", wm)
    assert not holds("exists r in Rover: true", wm)


def test_function_values(wm: WorldModel) -> None:
    assert evaluate("pos(scout)", wm) == (1.0, 2.0)
    assert evaluate("pos(a).y - pos(scout).y", wm) == 4.0
    assert holds("pos(scout).x < pos(a).x and eps = 0.5", wm)
    assert holds("pos(self).x = 1.0", wm, env={"self": "scout"})


def test_a_missing_value_is_an_error_not_false(wm: WorldModel) -> None:
    wm.unset("pos", "a")
    with pytest.raises(EvaluationError, match="no value for pos"):
        evaluate("pos(a)", wm)
    assert not holds("pos(a)", wm)


def test_conditions_follow_merges(wm: WorldModel) -> None:
    rover = WorldModel("rover")
    condition = compile_formula("found(b) or invalid_candidates(c2)")
    rover.merge(wm.snapshot())
    assert not condition(rover)
    wm.assert_fact("found", "b")
    delta = wm.take_delta()
    assert delta is not None
    rover.merge(delta)
    assert condition(rover)
