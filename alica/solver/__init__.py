"""The constraint solver: values for plan variables that satisfy constraints and maximise utilities.

A :class:`Problem` names decision variables (static, or one per agent), hard
constraints and utilities, formulas of :mod:`alica.lang`, and the belief base the rest
of each formula is read from; :func:`solve` returns a :class:`Solution`.

* :mod:`alica.solver.problem`: the data (domains, variables, problems, solutions).
* :mod:`alica.solver.ground`: reading variables in formulas; grounding into pieces.
* :mod:`alica.solver.tables`: pieces as numpy tables over finite domains.
* :mod:`alica.solver.finite`: exact branch and bound over finite and integer variables.
* :mod:`alica.solver.smooth`, :mod:`alica.solver.continuous`: formulas as smooth
  objectives, climbed by RProp from seeded restarts.
* :mod:`alica.solver.mixed`: the finite search with continuous solves at its leaves.
* :mod:`alica.solver.solve`: :func:`solve`, which picks among them.
"""

from __future__ import annotations

from alica.solver.problem import Domain, Finite, Integer, Point, Problem, ProblemError, Real, Solution, Term, Var
from alica.solver.solve import check, solve

__all__ = [
    "Domain",
    "Finite",
    "Integer",
    "Point",
    "Problem",
    "ProblemError",
    "Real",
    "Solution",
    "Term",
    "Var",
    "check",
    "solve",
]
