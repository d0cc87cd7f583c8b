"""What a solver is asked and what it answers: variables, their domains, problems and solutions.

A :class:`Problem` holds decision variables (:class:`Var`), hard constraints and
utilities (:class:`Term`, formulas of :mod:`alica.lang`) and the belief base every
other name of the formulas is read from. A variable is *static* (one value for the
team, read as ``x``) or *per agent* (one value for each agent, read as ``x(a)``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TypeAlias

from alica.errors import AlicaError
from alica.lang.ast import Node
from alica.lang.belief import BeliefBase
from alica.lang.registry import Registry


class ProblemError(AlicaError, ValueError):
    """A problem the solver cannot take: an empty domain, a variable that shadows a function, ..."""


@dataclass(frozen=True)
class Real:
    """A real number in ``[low, high]``."""

    low: float
    high: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise ProblemError(f"a real range needs finite low <= high, got [{self.low}, {self.high}]")


@dataclass(frozen=True)
class Integer:
    """An integer in ``[low, high]`` (both included)."""

    low: int
    high: int

    def __post_init__(self) -> None:
        if self.low > self.high:
            raise ProblemError(f"an integer range needs low <= high, got [{self.low}, {self.high}]")


@dataclass(frozen=True)
class Point:
    """A 2-D point ``(x, y)`` with both coordinates in ``[low, high]``."""

    low: float
    high: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise ProblemError(f"a point range needs finite low <= high, got [{self.low}, {self.high}]")


@dataclass(frozen=True)
class Finite:
    """One of the listed values (object names such as frontier cells, numbers, ...)."""

    values: tuple[object, ...]

    def __post_init__(self) -> None:
        if not self.values:
            raise ProblemError("a finite domain needs at least one value")


Domain: TypeAlias = Real | Integer | Point | Finite


@dataclass(frozen=True)
class Var:
    """A decision variable.

    Attributes:
        name: the (unified) plan variable name, e.g. ``"frontier"``.
        agent: ``None`` for a static variable; else the agent of a per-agent variable.
        domain: the values it may take.
    """

    name: str
    agent: str | None
    domain: Domain

    def __repr__(self) -> str:
        return self.name if self.agent is None else f"{self.name}({self.agent})"


@dataclass(frozen=True)
class Term:
    """A constraint (a truth formula) or a utility (a number to maximise), parsed."""

    name: str
    node: Node
    text: str


@dataclass(frozen=True)
class Problem:
    """Variables, hard constraints (all must hold) and utilities (their sum is maximised).

    Attributes:
        variables: the decision variables; at most one per (name, agent).
        constraints: hard constraints, truth formulas.
        utilities: soft terms, numbers; their sum is maximised.
        belief: facts, functions (``Pos``, ``gain``, ...), objects and the ``agents(E)`` domains.
        registry: registered functions (None: the built-ins).
        seed: seed of every random choice (restarts of the continuous solver).
    """

    variables: tuple[Var, ...]
    constraints: tuple[Term, ...]
    utilities: tuple[Term, ...]
    belief: BeliefBase
    registry: Registry | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        seen: set[tuple[str, str | None]] = set()
        kinds: dict[str, bool] = {}
        for var in self.variables:
            key = (var.name, var.agent)
            if key in seen:
                raise ProblemError(f"variable {var!r} is listed twice")
            seen.add(key)
            if kinds.setdefault(var.name, var.agent is None) != (var.agent is None):
                raise ProblemError(f"variable {var.name!r} is both static and per agent")


@dataclass(frozen=True)
class Solution:
    """The answer of :func:`alica.solver.solve`.

    Attributes:
        status: ``"solved"``, ``"infeasible"`` or ``"timeout"``.
        values: the value of every variable (empty unless solved); points are ``(x, y)`` tuples.
        utility: the sum of the utilities at ``values`` (nan when not solved).
        satisfied: constraint name -> whether it holds at ``values`` (read with the exact evaluator).
        optimal: whether the finite search finished (the value is the true optimum).
        time_s: time spent.
        reason: one line saying why, for ``"infeasible"`` and ``"timeout"``.
    """

    status: str
    values: Mapping[Var, object]
    utility: float
    satisfied: Mapping[str, bool]
    optimal: bool
    time_s: float
    reason: str = ""
    iterations: int = field(default=0, compare=False)

    def of(self, agent: str) -> dict[str, object]:
        """That agent's per-agent values, by variable name."""
        return {var.name: value for var, value in self.values.items() if var.agent == agent}

    def static(self) -> dict[str, object]:
        """The static variables' values, by name."""
        return {var.name: value for var, value in self.values.items() if var.agent is None}
