"""``solve()``: picks the method for a problem and reports the answer.

* Only finite and integer variables: the exact branch and bound of
  :mod:`alica.solver.finite`; ``"infeasible"`` is then a proof, and a search that
  finishes returns the true optimum (``optimal=True``).
* Only real and point variables: the smooth ascent of :mod:`alica.solver.continuous`;
  ``"infeasible"`` means every restart ended without a feasible point, which is not
  a proof (the reason says so).
* Both: the finite search outside, a continuous solve at each of its leaves
  (:mod:`alica.solver.mixed`).

The answer is checked with the exact evaluator: ``satisfied`` says which constraints
hold at the returned values and ``utility`` is the sum of the utilities there.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping

from alica.errors import EvaluationError
from alica.lang.registry import Registry
from alica.solver.continuous import Continuous
from alica.solver.finite import FiniteSearch
from alica.solver.ground import Reading, Variables, ground
from alica.solver.problem import Finite, Integer, Problem, ProblemError, Solution, Var

#: Restarts of the continuous solver run together, one batch after another.
RESTARTS = 64


def check(problem: Problem, values: Mapping[Var, object]) -> tuple[dict[str, bool], float]:
    """Which constraints hold at ``values``, and the utility there, read with the exact evaluator.

    A solution in use is checked with it when the world may have changed (a robot
    moved, a frontier vanished): one that no longer satisfies is solved again.

    Raises:
        EvaluationError: a utility cannot be evaluated at ``values``.
    """
    from alica.lang.evaluator import evaluate, holds

    reading = Reading(problem.belief, values)
    env = reading.env()
    satisfied = {}
    for term in problem.constraints:
        try:
            satisfied[term.name] = bool(holds(term.node, reading, env, problem.registry))
        except EvaluationError:
            satisfied[term.name] = False
    utility = 0.0
    for term in problem.utilities:
        value = evaluate(term.node, reading, env, problem.registry)
        utility += float(value)  # type: ignore[arg-type]
    return satisfied, utility


def solve(
    problem: Problem,
    *,
    time_limit: float = 0.05,
    start: Mapping[Var, object] | None = None,
    clock: Callable[[], float] = time.perf_counter,
    restarts: int = RESTARTS,
) -> Solution:
    """Values for the problem's variables that satisfy its constraints and maximise its utilities.

    Args:
        problem: the variables, constraints, utilities and belief base.
        time_limit: seconds; the best answer so far is returned when they run out.
        start: a warm start (e.g. the team's last solution), tried first.
        clock: the time source (injected for tests and simulated time).
        restarts: random starts per batch of the continuous solver.

    Returns:
        The solution; its ``status`` is ``"solved"``, ``"infeasible"`` or ``"timeout"``.

    Raises:
        ProblemError: for a problem that cannot be solved as posed (e.g. a variable named like a function).
        EvaluationError: when a formula cannot be evaluated (an unknown fact where a value is needed, ...).
    """
    began = clock()
    deadline = began + time_limit
    names = Variables(problem)
    registry: Registry | None = problem.registry
    hard = [
        piece
        for term in problem.constraints
        for piece in ground(term.name, term.node, utility=False, names=names, belief=problem.belief, registry=registry)
    ]
    soft = [
        piece
        for term in problem.utilities
        for piece in ground(term.name, term.node, utility=True, names=names, belief=problem.belief, registry=registry)
    ]
    finite = [v for v in problem.variables if isinstance(v.domain, (Finite, Integer))]
    smooth = [v for v in problem.variables if not isinstance(v.domain, (Finite, Integer))]
    reading = Reading(problem.belief, {})

    values: dict[Var, object] | None
    if not smooth:
        search = FiniteSearch(finite, hard, soft, names, reading, registry)
        outcome = search.run(deadline, clock)
        values, complete, nodes = outcome.values, outcome.complete, outcome.nodes
        proof = True
        reason = search.infeasible_reason or "the search visited every assignment: none satisfies the constraints"
    elif not finite:
        engine = Continuous(problem, names, reading, registry)
        result = engine.run(deadline, clock, start=start, restarts=restarts)
        values, complete, nodes = result.values, result.complete, result.steps
        proof = False
        reason = (
            f"no feasible point from {result.tried} restarts (not a proof: the constraints may still be satisfiable)"
        )
    else:
        from alica.solver.mixed import solve_mixed

        values, complete, nodes, reason = solve_mixed(
            problem, finite, smooth, hard, soft, names, reading, deadline, clock, start
        )
        proof = False
    elapsed = clock() - began
    if values is None:
        status = "infeasible" if complete else "timeout"
        if not complete:
            reason = f"no solution found within {time_limit:g} s"
        satisfied = dict.fromkeys((t.name for t in problem.constraints), False)
        return Solution(status, {}, math.nan, satisfied, False, elapsed, reason, nodes)
    satisfied, utility = check(problem, values)
    if not all(satisfied.values()):  # the solvers check their answers; this would be a bug of ours
        failed = ", ".join(name for name, ok in satisfied.items() if not ok)
        raise ProblemError(f"internal: the solver's answer breaks {failed}")
    optimal = complete and proof
    reason = "" if optimal else f"best found within {time_limit:g} s" if not complete else "not proven optimal"
    return Solution("solved", values, utility, satisfied, optimal, elapsed, reason, nodes)
