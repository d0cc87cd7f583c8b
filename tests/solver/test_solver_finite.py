"""The finite solver: grounding, tables, and branch and bound against exhaustive enumeration."""

from __future__ import annotations

from itertools import product

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.lang import FactBase, evaluate, holds, parse
from alica.solver import Finite, Integer, Problem, ProblemError, Term, Var, solve
from alica.solver.ground import Reading, Variables, ground
from alica.solver.tables import TableMaker

SPREAD = "forall a, b in agents(Explore): a == b or MaximalDist(frontier(a), frontier(b), eps)"
NEAR = "forall a in agents(Explore): MinimalDist(frontier(a), a, reach)"
DISTINCT = "forall a, b in agents(Explore): a == b or frontier(a) != frontier(b)"
GAIN = "sum a in agents(Explore): gain(frontier(a))"
PAIRS = "sum a, b in agents(Explore): dist(frontier(a), frontier(b)) / 10"


def never() -> float:
    """A clock that never advances: the search always finishes."""
    return 0.0


def term(name: str, text: str) -> Term:
    return Term(name, parse(text), text)


def world(robots, frontiers, gains, eps=4.0, reach=15.0) -> FactBase:
    fb = FactBase(values={"eps": eps, "reach": reach})
    for name, xy in robots.items():
        fb.add_object(name, "agents(Explore)")
        fb.set("Pos", name, value=xy)
    for name, xy in frontiers.items():
        fb.set("Pos", name, value=xy)
        fb.set("gain", name, value=gains[name])
    return fb


def explore(fb: FactBase, frontiers, constraints=(SPREAD, NEAR), utilities=(GAIN,), seed=0) -> Problem:
    agents = list(fb.objects("agents(Explore)"))
    variables = tuple(Var("frontier", str(a), Finite(tuple(frontiers))) for a in agents)
    return Problem(
        variables,
        tuple(term(f"c{i}", t) for i, t in enumerate(constraints)),
        tuple(term(f"u{i}", t) for i, t in enumerate(utilities)),
        fb,
        seed=seed,
    )


def exhaustive(problem: Problem):
    """The best utility by trying every assignment with the plain evaluator (None: infeasible)."""
    best = None
    variables = problem.variables
    for combination in product(*(v.domain.values for v in variables)):
        fb = problem.belief.copy()
        for var, value in zip(variables, combination):
            fb.set(var.name, var.agent, value=value)
        if all(holds(c.node, fb) for c in problem.constraints):
            total = sum(float(evaluate(u.node, fb)) for u in problem.utilities)
            best = total if best is None else max(best, total)
    return best


def test_a_small_exploration_gets_its_optimum():
    frontiers = {"f1": (0, 0), "f2": (1, 0), "f3": (10, 0), "f4": (30, 0)}
    gains = {"f1": 5.0, "f2": 6.0, "f3": 1.0, "f4": 100.0}
    fb = world({"r1": (0, 1), "r2": (2, 1)}, frontiers, gains)
    solution = solve(explore(fb, frontiers), clock=never)
    assert solution.status == "solved" and solution.optimal
    # f4 is out of reach, f1 and f2 are too close together: the best is f2 and f3
    assert sorted(solution.values.values()) == ["f2", "f3"]
    assert solution.utility == 7.0
    assert solution.of("r1")["frontier"] in ("f2", "f3")
    assert solution.satisfied == {"c0": True, "c1": True}


def test_an_impossible_query_is_infeasible_with_a_reason():
    frontiers = {"f1": (0, 0), "f2": (1, 0)}
    fb = world({"r1": (0, 1), "r2": (2, 1)}, frontiers, {"f1": 1.0, "f2": 1.0})
    solution = solve(explore(fb, frontiers), clock=never)
    assert solution.status == "infeasible" and solution.values == {}
    assert solution.reason and np.isnan(solution.utility)
    far = world({"r1": (100, 100)}, frontiers, {"f1": 1.0, "f2": 1.0})
    lonely = solve(explore(far, frontiers), clock=never)
    assert lonely.status == "infeasible" and "frontier(r1)" in lonely.reason


def test_static_integer_variables():
    problem = Problem(
        (Var("n", None, Integer(0, 20)), Var("m", None, Integer(0, 20))),
        (term("c", "n + m <= 17 and n * m >= 30"),),
        (term("u", "2 * n + m"),),
        FactBase(),
    )
    solution = solve(problem, clock=never)
    assert solution.status == "solved" and solution.optimal
    assert solution.static() == {"n": 15, "m": 2}
    assert solution.utility == 32


def test_a_clock_that_runs_out_reports_timeout_or_the_best_so_far():
    ticks = iter(range(10**6))
    frontiers = {f"f{i}": (i * 5.0, 0.0) for i in range(40)}
    fb = world({f"r{i}": (i * 10.0, 0.0) for i in range(4)}, frontiers, dict.fromkeys(frontiers, 1.0), reach=1000)
    problem = explore(fb, frontiers, utilities=(GAIN, PAIRS))
    solution = solve(problem, time_limit=3, clock=lambda: float(next(ticks)))  # the clock ticks on every read
    assert solution.status in ("solved", "timeout")
    assert not solution.optimal


def test_grounding_splits_quantifiers_and_finds_dependencies():
    frontiers = {"f1": (0, 0)}
    fb = world({"r1": (0, 0), "r2": (1, 1), "r3": (2, 2)}, frontiers, {"f1": 1.0})
    problem = explore(fb, frontiers)
    names = Variables(problem)
    pieces = ground("c0", parse(SPREAD), utility=False, names=names, belief=fb, registry=None)
    assert len(pieces) == 9
    by_env = {tuple(v for _, v in p.env): p for p in pieces}
    assert [repr(d) for d in by_env[("r1", "r3")].deps] == ["frontier(r1)", "frontier(r3)"]
    assert [repr(d) for d in by_env[("r2", "r2")].deps] == ["frontier(r2)"]
    sums = ground("u0", parse(GAIN), utility=True, names=names, belief=fb, registry=None)
    assert [[repr(d) for d in p.deps] for p in sums] == [["frontier(r1)"], ["frontier(r2)"], ["frontier(r3)"]]
    nested = ground(
        "n",
        parse("exists a in agents(Explore): frontier(a) == f1"),
        utility=False,
        names=names,
        belief=fb,
        registry=None,
    )
    assert len(nested) == 1 and len(nested[0].deps) == 3


@pytest.mark.parametrize(
    "text",
    [
        SPREAD,
        DISTINCT,
        "forall a, b in agents(Explore): a == b or dist(frontier(a), frontier(b)) >= eps - 1",
        "forall a, b in agents(Explore): not (MinimalDist(frontier(a), frontier(b), 2) and a != b)",
        "forall a, b in agents(Explore): gain(frontier(a)) + gain(frontier(b)) > 3 or a == b",
        "forall a, b in agents(Explore): Pos(frontier(a)).x <= Pos(frontier(b)).x or a == b",
    ],
)
def test_vectorised_tables_equal_the_evaluator_cell_by_cell(text):
    rng = np.random.default_rng(3)
    frontiers = {f"f{i}": tuple(rng.integers(0, 6, 2).tolist()) for i in range(6)}
    fb = world({"r1": (0, 0), "r2": (3, 3)}, frontiers, {f: float(rng.integers(0, 4)) for f in frontiers})
    problem = explore(fb, frontiers, constraints=(text,))
    names = Variables(problem)
    domains = {v: np.array(v.domain.values, dtype=object) for v in problem.variables}
    maker = TableMaker(Reading(fb, {}), None, names, domains)
    for piece in ground("c", parse(text), utility=False, names=names, belief=fb, registry=None):
        axes = list(piece.deps)
        fast = maker.table(piece, axes, utility=False)
        slow = maker._cell_by_cell(piece, axes, fast.shape, utility=False)
        assert np.array_equal(fast, slow), piece


def test_a_variable_named_like_a_function_is_refused():
    from alica.lang import default_registry

    problem = Problem((Var("dist", None, Integer(0, 1)),), (), (), FactBase(), registry=default_registry())
    with pytest.raises(ProblemError, match="registered function"):
        solve(problem)


@st.composite
def explorations(draw):
    n_agents = draw(st.integers(2, 4))
    n_frontiers = draw(st.integers(3, 8))
    xy = st.tuples(st.integers(0, 10), st.integers(0, 10))
    robots = {f"r{i}": draw(xy) for i in range(n_agents)}
    frontiers = {f"f{i}": draw(xy) for i in range(n_frontiers)}
    gains = {f: float(draw(st.integers(0, 9))) for f in frontiers}
    eps = float(draw(st.integers(0, 6)))
    reach = float(draw(st.integers(1, 15)))
    constraints = draw(st.sampled_from([(SPREAD, NEAR), (SPREAD,), (NEAR, DISTINCT), (DISTINCT,)]))
    utilities = draw(st.sampled_from([(GAIN,), (GAIN, PAIRS), ()]))
    fb = world(robots, frontiers, gains, eps=eps, reach=reach)
    return explore(fb, frontiers, constraints, utilities)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(explorations())
def test_branch_and_bound_equals_exhaustive_enumeration(problem):
    expected = exhaustive(problem)
    solution = solve(problem, clock=never)
    if expected is None:
        assert solution.status == "infeasible"
        return
    assert solution.status == "solved" and solution.optimal
    assert solution.utility == pytest.approx(expected, abs=1e-9)
    fb = problem.belief.copy()
    for var, value in solution.values.items():
        fb.set(var.name, var.agent, value=value)
    assert all(holds(c.node, fb) for c in problem.constraints)


def test_the_same_problem_gives_the_same_values():
    rng = np.random.default_rng(7)
    frontiers = {f"f{i}": tuple(rng.uniform(0, 30, 2)) for i in range(60)}
    gains = dict.fromkeys(frontiers, 1.0)  # many equal optima: the choice must still be repeatable
    fb = world({f"r{i}": tuple(rng.uniform(0, 30, 2)) for i in range(4)}, frontiers, gains)
    first = solve(explore(fb, frontiers), clock=never)
    second = solve(explore(fb, frontiers), clock=never)
    assert first.status == "solved" and first.values == second.values
