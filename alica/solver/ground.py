"""Reading decision variables in formulas, and grounding constraints into pieces.

**Reading.** A formula reads a static variable ``x`` as a name and a per-agent
variable as ``x(a)``. :class:`Reading` is a belief base over the problem's own that
answers ``x(a)`` with agent ``a``'s value; static values go into the evaluation
environment (:meth:`Reading.env`), where a name is looked up first. Everything else
falls through to the problem's belief base and registry, as in :mod:`alica.lang.evaluator`.

**Grounding.** A constraint ``forall a, b in agents(Explore): body`` stands for one
condition per pair of agents; a utility ``sum a in agents(Explore): gain(frontier(a))``
for one term per agent. :func:`ground` expands the top of a formula (``and``,
``forall``; ``sum`` and ``+`` for utilities) into :class:`Piece` objects, each a
sub-formula with the quantifier variables bound in ``env`` and the set of decision
variables it reads, so that a search can check a piece as soon as those are assigned.
Quantifiers further down stay in the piece; its dependencies are found by walking
every binding of them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from itertools import product

from alica.errors import EvaluationError
from alica.lang.ast import And, Binary, Call, Name, Node, Quantified, children
from alica.lang.belief import BeliefBase
from alica.lang.evaluator import evaluate, holds
from alica.lang.registry import Registry
from alica.solver.problem import Problem, ProblemError, Var


class Reading:
    """A belief base that reads per-agent decision variables from an assignment.

    Args:
        belief: the problem's belief base (everything else).
        values: the assignment, variable -> value (static ones are served by :meth:`env`).
    """

    def __init__(self, belief: BeliefBase, values: Mapping[Var, object]) -> None:
        self.belief = belief
        self.per_agent: dict[tuple[str, object], object] = {}
        self.statics: dict[str, object] = {}
        for var, value in values.items():
            if var.agent is None:
                self.statics[var.name] = value
            else:
                self.per_agent[(var.name, var.agent)] = value

    def with_values(self, values: Mapping[Var, object]) -> Reading:
        """A reading with these values added to (or replacing) the ones held."""
        other = Reading(self.belief, values)
        other.per_agent = {**self.per_agent, **other.per_agent}
        other.statics = {**self.statics, **other.statics}
        return other

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """``x(a)`` for a per-agent variable ``x``; otherwise the problem's belief base."""
        if len(args) == 1:
            try:
                value = self.per_agent.get((name, args[0]), None)
            except TypeError:  # an unhashable argument is never an agent
                value = None
            if value is not None:
                return value
        return self.belief.lookup(name, args)

    def objects(self, type_name: str) -> Iterable[object]:
        """The objects of a type, from the problem's belief base."""
        return self.belief.objects(type_name)

    def env(self, extra: Mapping[str, object] | None = None) -> dict[str, object]:
        """The evaluation environment: the static variables' values, then ``extra`` (quantifier bindings)."""
        env = dict(self.statics)
        if extra:
            env.update(extra)
        return env


@dataclass(frozen=True)
class Piece:
    """One ground part of a constraint or utility.

    Attributes:
        term: the name of the constraint or utility it comes from.
        node: the sub-formula.
        env: the quantifier variables bound above it.
        deps: the decision variables it reads, in the problem's order.
    """

    term: str
    node: Node
    env: tuple[tuple[str, object], ...]
    deps: tuple[Var, ...]

    def bindings(self) -> dict[str, object]:
        """``env`` as a dict."""
        return dict(self.env)


class Variables:
    """The problem's variables by the names formulas use."""

    def __init__(self, problem: Problem) -> None:
        self.order = {var: i for i, var in enumerate(problem.variables)}
        self.static: dict[str, Var] = {}
        self.per_agent: dict[str, dict[object, Var]] = {}
        for var in problem.variables:
            if var.agent is None:
                self.static[var.name] = var
            else:
                self.per_agent.setdefault(var.name, {})[var.agent] = var
        registry = problem.registry
        for name in (*self.static, *self.per_agent):
            if registry is not None and name in registry:
                raise ProblemError(f"variable {name!r} has the name of a registered function; rename it")

    def sort(self, deps: Iterable[Var]) -> tuple[Var, ...]:
        """The variables in the problem's order, each once."""
        return tuple(sorted(set(deps), key=self.order.__getitem__))


def dependencies(
    node: Node, env: Mapping[str, object], names: Variables, belief: BeliefBase, registry: Registry | None
) -> set[Var]:
    """The decision variables ``node`` reads with the quantifier variables of ``env`` bound.

    ``x(a)`` with ``a`` bound (or any argument free of decision variables) depends on
    that agent's ``x``; an argument that itself reads decision variables makes the
    node depend on every agent's ``x``.
    """
    found: set[Var] = set()
    _walk(node, dict(env), names, belief, registry, found)
    return found


def _walk(
    node: Node, env: dict[str, object], names: Variables, belief: BeliefBase, registry: Registry | None, found: set[Var]
) -> None:
    if isinstance(node, Name):
        if node.name not in env and node.name in names.static:
            found.add(names.static[node.name])
        return
    if isinstance(node, Call) and len(node.args) == 1 and node.name in names.per_agent:
        inner: set[Var] = set()
        _walk(node.args[0], env, names, belief, registry, inner)
        found |= inner
        table = names.per_agent[node.name]
        if inner:
            found.update(table.values())
            return
        try:
            agent = evaluate(node.args[0], belief, env, registry)
        except EvaluationError:
            found.update(table.values())
            return
        var = table.get(agent)
        if var is not None:
            found.add(var)
        return
    if isinstance(node, Quantified):
        binders = [var for var, _ in node.binders]
        domains = [tuple(belief.objects(type_name)) for _, type_name in node.binders]
        for combination in product(*domains):
            inner_env = dict(env)
            inner_env.update(zip(binders, combination, strict=True))
            _walk(node.body, inner_env, names, belief, registry, found)
        return
    for child in children(node):
        _walk(child, env, names, belief, registry, found)


def ground(
    name: str, node: Node, *, utility: bool, names: Variables, belief: BeliefBase, registry: Registry | None
) -> list[Piece]:
    """Split a constraint (or utility) into ground pieces whose conjunction (or sum) is the whole.

    Args:
        name: the term's name, kept on each piece.
        node: its formula.
        utility: split ``sum`` and ``+`` (a utility) rather than ``forall`` and ``and``.
        names: the problem's variables.
        belief: where quantifier domains come from.
        registry: registered functions (for evaluating agent arguments).

    Returns:
        The pieces, in the order of the formula and its quantifier domains.
    """
    pieces: list[Piece] = []

    def split(part: Node, env: dict[str, object]) -> None:
        if utility and isinstance(part, Binary) and part.op == "+":
            split(part.left, env)
            split(part.right, env)
            return
        if not utility and isinstance(part, And):
            for item in part.items:
                split(item, env)
            return
        if isinstance(part, Quantified) and part.kind == ("sum" if utility else "forall"):
            binders = [var for var, _ in part.binders]
            domains = [tuple(belief.objects(type_name)) for _, type_name in part.binders]
            for combination in product(*domains):
                inner = dict(env)
                inner.update(zip(binders, combination, strict=True))
                split(part.body, inner)
            return
        deps = names.sort(dependencies(part, env, names, belief, registry))
        pieces.append(Piece(name, part, tuple(env.items()), deps))

    split(node, {})
    return pieces


def check_piece(piece: Piece, reading: Reading, registry: Registry | None) -> bool:
    """Whether a constraint piece holds under the assignment of ``reading``."""
    return holds(piece.node, reading, reading.env(piece.bindings()), registry)


def value_of(piece: Piece, reading: Reading, registry: Registry | None) -> float:
    """The number a utility piece gives under the assignment of ``reading``."""
    value = evaluate(piece.node, reading, reading.env(piece.bindings()), registry)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise EvaluationError(f"utility '{piece.term}' gives {value!r}, not a number")
    return float(value)
