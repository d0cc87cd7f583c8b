"""MaximalDist, MinimalDist and dist take points as well as objects placed by Pos."""

from __future__ import annotations

import pytest

from alica.errors import EvaluationError
from alica.lang import FactBase, evaluate, holds


def test_points_are_their_own_positions():
    fb = FactBase(values={("Pos", "f1"): (3.0, 4.0)})
    env = {"p": (0.0, 0.0), "q": {"x": 6.0, "y": 8.0}}
    assert evaluate("dist(p, f1)", fb, env) == 5.0
    assert evaluate("dist(f1, q)", fb, env) == 5.0
    assert evaluate("dist(p, q)", fb, env) == 10.0
    assert holds("MaximalDist(p, f1, 4.9) and not MaximalDist(p, f1, 5)", fb, env)
    assert holds("MinimalDist(q, f1, 5.1) and not MinimalDist(q, f1, 5)", fb, env)


def test_an_object_without_a_position_is_an_error_for_dist_and_false_for_the_predicates():
    fb = FactBase(values={("Pos", "f1"): (3.0, 4.0)})
    assert not holds("MaximalDist(f1, nowhere, 0)", fb)
    with pytest.raises(EvaluationError, match="nowhere"):
        evaluate("dist(f1, nowhere)", fb)
