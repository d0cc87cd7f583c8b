"""Queries: the problem of a running plan tree, its bindings unified across levels."""

from __future__ import annotations

import math

import pytest

from alica.lang import FactBase
from alica.solver import Point, solve
from alica.solver.query import Level, QueryError, agents_in, collect
from tests.engine.helpers import library

TWO_LEVELS = """
behaviours:
  - name: Go
    skill: Work
    variables: [target]
    params: {duration: $target}
plans:
  - name: Outer
    variables: ["spot - point[-5, 5]"]
    constraints:
      - name: Apart
        formula: "forall a, b in agents(Work): a == b or dist(spot(a), spot(b)) >= 2.0"
    entry_points:
      - {name: Work, task: Work, state: Busy, min: 1, max: "*"}
    states:
      - name: Busy
        children:
          - {ref: Inner, bind: {where: spot}}
  - name: Inner
    variables: ["where - point[-5, 5]"]
    constraints:
      - name: North
        formula: "forall a in agents(Go): where(a).y >= 3"
      - name: Left
        utility: "0 - (sum a in agents(Go): where(a).x)"
    entry_points:
      - {name: Go, task: Help, state: Going, min: 1, max: "*"}
    states:
      - name: Going
        children:
          - {ref: Go, bind: {target: where}}
"""


def levels(lib, agents=("a", "b")):
    outer, inner = lib.plans["Outer"], lib.plans["Inner"]
    return [
        Level("Outer", outer, dict.fromkeys(agents, ("Work", "Busy"))),
        Level("Outer/Busy/Inner", inner, dict.fromkeys(agents, ("Go", "Going")), {"where": "spot"}),
    ]


def test_constraints_of_both_levels_are_solved_together(tmp_path):
    lib = library(tmp_path, TWO_LEVELS)
    query = collect(levels(lib), FactBase())
    problem = query.problem
    assert {(v.name, v.agent) for v in problem.variables} == {("spot", "a"), ("spot", "b")}
    assert all(isinstance(v.domain, Point) for v in problem.variables)
    assert {t.name for t in problem.constraints} == {"Outer.Apart", "Inner.North"}
    assert query.local(1) == {"spot": "where"}  # the inner plan calls it 'where'
    solution = solve(problem, time_limit=1.0)
    assert solution.status == "solved"
    a, b = solution.of("a")["spot"], solution.of("b")["spot"]
    assert math.dist(a, b) >= 2.0 - 1e-9  # the outer constraint
    assert a[1] >= 3 and b[1] >= 3  # the inner one
    assert min(a[0], b[0]) < -2.5  # the inner utility pulls them left


def test_the_same_view_gives_the_same_seed_and_a_different_view_another(tmp_path):
    lib = library(tmp_path, TWO_LEVELS)
    first, again = collect(levels(lib), FactBase()), collect(levels(lib), FactBase())
    assert first.digest == again.digest and first.problem.seed == again.problem.seed
    assert collect(levels(lib, ("a",)), FactBase()).digest != first.digest


def test_agents_of_an_entry_point_task_or_state(tmp_path):
    lib = library(tmp_path, TWO_LEVELS)
    tree = levels(lib, ("a", "b", "c"))
    assert agents_in(tree, "Go") == ("a", "b", "c")  # the inner level's entry point
    assert agents_in(tree, "Busy") == ("a", "b", "c")  # a state of the outer level
    assert agents_in(tree, "Nowhere") == ()


def test_a_variable_without_a_type_cannot_be_solved(tmp_path):
    lib = library(
        tmp_path, TWO_LEVELS.replace('"where - point[-5, 5]"', "where").replace('"spot - point[-5, 5]"', "spot")
    )
    with pytest.raises(QueryError, match="has no type"):
        collect(levels(lib), FactBase())
