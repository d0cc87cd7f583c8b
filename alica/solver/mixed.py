"""Mixed problems: the finite search outside, a continuous solve at each of its leaves.

The branch and bound of :mod:`alica.solver.finite` assigns the finite variables,
checking the pieces that read only them; at every full assignment that passes, the
continuous solver (:mod:`alica.solver.continuous`) runs with those values fixed, and
the utility of the pieces that read continuous variables is added. Since that
utility is not known before a leaf is solved, the bound cannot cut branches on
utility: every finite assignment that satisfies the finite constraints is a leaf.
This is fine for small problems (tens to a few hundred such assignments within the
time limit); the answer is never reported optimal, and ``"infeasible"`` is not a
proof (each leaf's continuous solve may have missed a feasible point).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from alica.lang.registry import Registry
from alica.solver.continuous import Continuous
from alica.solver.finite import FiniteSearch
from alica.solver.ground import Piece, Reading, Variables, value_of
from alica.solver.problem import Problem, Var

#: Restarts of each leaf's continuous solve.
LEAF_RESTARTS = 16
#: Ascent steps of each leaf's continuous solve.
LEAF_STEPS = 150


def solve_mixed(
    problem: Problem,
    finite: Sequence[Var],
    smooth: Sequence[Var],
    hard: Sequence[Piece],
    soft: Sequence[Piece],
    names: Variables,
    reading: Reading,
    deadline: float,
    clock: Callable[[], float],
    start: Mapping[Var, object] | None,
) -> tuple[dict[Var, object] | None, bool, int, str]:
    """Solve a problem with finite and continuous variables.

    Returns:
        The values (None when none were found), whether the search finished, the
        search nodes visited, and the reason to give when no values were found.
    """
    registry: Registry | None = problem.registry
    open_vars = frozenset(smooth)
    leaf_soft = [p for p in soft if open_vars.intersection(p.deps)]
    leaves = [0]

    def leaf(values: dict[Var, object]) -> tuple[float, dict[Var, object]] | None:
        leaves[0] += 1
        fixed = reading.with_values(values)
        engine = Continuous(problem, names, fixed, registry)
        result = engine.run(deadline, clock, start=start, restarts=LEAF_RESTARTS, max_steps=LEAF_STEPS)
        if result.values is None:
            return None
        exact = fixed.with_values(result.values)
        return sum(value_of(p, exact, registry) for p in leaf_soft), result.values

    search = FiniteSearch(finite, hard, soft, names, reading, registry, open_vars=open_vars, leaf=leaf)
    outcome = search.run(deadline, clock)
    values = None if outcome.values is None else {**outcome.values, **outcome.extra}
    reason = search.infeasible_reason or (
        f"no finite assignment led to a feasible continuous point ({leaves[0]} tried; not a proof)"
    )
    return values, outcome.complete, outcome.nodes, reason
