"""The continuous solver (compilation, gradients, known optima) and mixed problems."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.lang import FactBase, holds, parse
from alica.solver import Finite, Point, Problem, ProblemError, Real, Term, Var, solve
from alica.solver.continuous import Compiler
from alica.solver.ground import Reading, Variables

APART = "forall a, b in agents(Form): a == b or dist(pos(a), pos(b)) >= 1.0"
CENTRE = "forall a in agents(Form): dist(pos(a), centre) <= 3.0"


def never() -> float:
    return 0.0


def term(name: str, text: str) -> Term:
    return Term(name, parse(text), text)


def formation(n: int, seed: int = 0) -> Problem:
    fb = FactBase()
    for i in range(n):
        fb.add_object(f"r{i}", "agents(Form)")
    fb.set("Pos", "centre", value=(0.0, 0.0))
    variables = tuple(Var("pos", f"r{i}", Point(-5, 5)) for i in range(n))
    return Problem(variables, (term("apart", APART), term("centre", CENTRE)), (), fb, seed=seed)


def test_a_formation_of_ten_is_feasible_and_checked_exactly():
    problem = formation(10)
    solution = solve(problem, clock=never, restarts=100)
    assert solution.status == "solved" and solution.satisfied == {"apart": True, "centre": True}
    points = [solution.of(f"r{i}")["pos"] for i in range(10)]
    assert all(math.dist(p, (0, 0)) <= 3.0 for p in points)
    assert all(math.dist(p, q) >= 1.0 for i, p in enumerate(points) for q in points[i + 1 :])


def test_same_seed_same_answer_other_seed_other_answer():
    first = solve(formation(6, seed=4), clock=never)
    again = solve(formation(6, seed=4), clock=never)
    other = solve(formation(6, seed=5), clock=never)
    assert first.values == again.values
    assert first.values != other.values


def test_a_warm_start_that_holds_is_kept():
    problem = formation(3)
    start = {v: (float(i) * 1.5 - 1.5, 0.0) for i, v in enumerate(problem.variables)}
    solution = solve(problem, clock=never, start=start)
    assert solution.values == start


def test_no_feasible_point_is_reported_infeasible_and_not_a_proof():
    fb = FactBase(values={("Pos", "rock"): (0.0, 0.0)})
    problem = Problem(
        (Var("p", None, Point(-5, 5)),), (term("ring", "dist(p, rock) >= 2 and dist(p, rock) <= 1"),), (), fb
    )
    solution = solve(problem, clock=never)
    assert solution.status == "infeasible" and "not a proof" in solution.reason
    assert solution.satisfied == {"ring": False}


@pytest.mark.parametrize(
    ("constraint", "utility", "expected"),
    [
        ("x + y <= 1", "x + y", 1.0),
        ("x + y <= 1", "x + 2 * y", 2.0),
        ("x >= 0.25", "-(x - 0.5) ^ 2 - abs(y + 0.5)", 0.0),
        ("not (x > 0.3)", "x", 0.3),
        ("x <= 0.2 or y <= 0.2", "x + y", 1.2),
        ("max(x, y) <= 0.6 and sqrt(x) >= 0.5", "x + y", 1.2),
    ],
)
def test_continuous_problems_with_known_optima(constraint, utility, expected):
    problem = Problem(
        (Var("x", None, Real(-1, 1)), Var("y", None, Real(-1, 1))),
        (term("c", constraint),),
        (term("u", utility),),
        FactBase(),
    )
    solution = solve(problem, clock=never)
    assert solution.status == "solved" and solution.satisfied == {"c": True}
    assert solution.utility == pytest.approx(expected, abs=5e-3)


def test_a_point_kept_off_a_rock_goes_as_near_the_goal_as_it_may():
    fb = FactBase(values={("Pos", "rock"): (0.0, 0.0), ("Pos", "goal"): (1.0, 0.0)})
    problem = Problem(
        (Var("p", None, Point(-5, 5)),),
        (term("off", "not MinimalDist(p, rock, 2)"),),
        (term("near", "-dist(p, goal)"),),
        fb,
    )
    solution = solve(problem, clock=never)
    x, y = solution.static()["p"]  # type: ignore[misc]
    assert solution.status == "solved"
    assert (x, y) == pytest.approx((2.0, 0.0), abs=1e-3)


def test_gradients_match_finite_differences():
    fb = FactBase(values={("Pos", "c"): (0.5, -0.25)})
    fb.add_object("r1", "agents(T)")
    fb.add_object("r2", "agents(T)")
    problem = Problem(
        (Var("p", "r1", Point(-3, 3)), Var("p", "r2", Point(-3, 3)), Var("w", None, Real(0, 2))),
        (),
        (term("u", "sum a in agents(T): w * dist(p(a), c) ^ 2 - abs(p(a).x) + max(p(a).y, w) / (1 + w)"),),
        fb,
    )
    names = Variables(problem)
    columns = {problem.variables[0]: 0, problem.variables[1]: 2, problem.variables[2]: 4}
    compiler = Compiler(names, Reading(fb, {}), None, columns, 5)
    node = compiler._num(compiler.value(problem.utilities[0].node, {}))
    assert isinstance(node, int)
    x = np.random.default_rng(1).uniform(0.1, 1.5, size=(3, 5))
    vals = compiler.graph.forward(x)
    g = compiler.graph.backward(x, vals, {node: np.ones((3, 1))})
    h = 1e-6
    for j in range(5):
        up, down = x.copy(), x.copy()
        up[:, j] += h
        down[:, j] -= h
        numeric = (compiler.graph.forward(up)[node] - compiler.graph.forward(down)[node])[:, 0] / (2 * h)
        assert g[:, j] == pytest.approx(numeric, rel=1e-4, abs=1e-6)
    # and the value is the evaluator's
    for row in x:
        values = {problem.variables[0]: (row[0], row[1]), problem.variables[1]: (row[2], row[3])}
        reading = Reading(fb, {**values, problem.variables[2]: row[4]})
        from alica.lang import evaluate

        exact = evaluate(problem.utilities[0].node, reading, reading.env())
        assert float(compiler.graph.forward(row[None, :])[node][0, 0]) == pytest.approx(exact, rel=1e-9)


def test_an_unsupported_function_of_a_variable_is_a_clear_error():
    problem = Problem((Var("x", None, Real(0, 1)),), (term("c", "floor(x) >= 0"),), (), FactBase())
    with pytest.raises(ProblemError, match="floor"):
        solve(problem)


def test_a_mixed_problem_assigns_frontiers_and_places_a_point():
    fb = FactBase()
    for name, xy in {"f1": (0.0, 0.0), "f2": (4.0, 0.0), "f3": (8.0, 0.0)}.items():
        fb.set("Pos", name, value=xy)
        fb.set("gain", name, value=1.0)
    fb.set("gain", "f3", value=3.0)
    fb.add_object("r1", "agents(E)")
    fb.add_object("r2", "agents(E)")
    frontier = Finite(("f1", "f2", "f3"))
    variables = (Var("frontier", "r1", frontier), Var("frontier", "r2", frontier), Var("base", None, Point(-10, 10)))
    problem = Problem(
        variables,
        (
            term("distinct", "forall a, b in agents(E): a == b or frontier(a) != frontier(b)"),
            term("reach", "forall a in agents(E): dist(base, frontier(a)) <= 2.5"),
        ),
        (term("gain", "sum a in agents(E): gain(frontier(a))"),),
        fb,
    )
    solution = solve(problem, clock=never)
    assert solution.status == "solved" and all(solution.satisfied.values())
    assert {solution.of("r1")["frontier"], solution.of("r2")["frontier"]} == {"f2", "f3"}
    assert solution.utility == 4.0 and not solution.optimal
    base = solution.static()["base"]
    assert holds("dist(b, f2) <= 2.5 and dist(b, f3) <= 2.5", fb, {"b": base})
