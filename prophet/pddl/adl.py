"""Full ADL conditions without exponential blow-up: derived predicates for what would multiply out.

Expanding quantifiers over the objects and multiplying a condition out into
disjunctive normal form (:mod:`alica.prophet.pddl.normal`) is exponential for
an ``or``, ``exists`` or ``imply`` under a ``forall`` (or a negated ``and``,
which is the same thing). As Fast Downward's translator does, such a
sub-formula becomes a new derived predicate over its free variables instead:

* in negation normal form, ``(forall (?x) phi)`` whose ``phi`` is no plain
  conjunction becomes ``(not (new-axiom@k ...))`` with the rule
  ``new-axiom@k <- (exists (?x) (not phi))``;
* an ``and`` whose parts together would multiply out into more than
  :data:`MAX_PRODUCT` conjunctions gets a new predicate for each part that is
  itself a disjunction;
* an ``exists`` becomes more parameters of the rule (or action schema) it is
  in, or, where no parameters can be added (a ``when`` condition), a new
  predicate.

A ``forall`` over a plain conjunction stays: it expands into a conjunction.
Rules (:class:`Rule`) are conjunctions of literals over typed variables,
grounded like actions by the fixpoint of :mod:`alica.prophet.pddl.reach`. The
generated names contain ``@``, which no PDDL name may, so they never clash
with the domain's names, and they only name facts, never actions.

:func:`strata` orders the derived predicates so that a rule's negated derived
literals belong to lower strata (stratified negation, as PDDL 2.2 asks).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import dataclass

from alica.prophet.pddl.errors import PddlError
from alica.prophet.pddl.model import And, Atom, Equals, Exists, Forall, Formula, Imply, Not, Or, TypedName
from alica.prophet.pddl.normal import Clause, ObjectsOf, substitute
from alica.source import SourceSpan

NEW_PREFIX = "new-axiom@"
"""The prefix of the generated derived predicates (``new-axiom@0``, ...)."""
GOAL_PREDICATE = "goal@"
"""The 0-ary derived predicate a goal that is no conjunction becomes."""
MAX_PRODUCT = 16
"""The most conjunctions an ``and`` may multiply out into before its disjunctive parts become derived predicates."""


@dataclass(frozen=True, slots=True)
class Rule:
    """One rule of a derived predicate: ``predicate(head) <- clause``.

    Attributes:
        predicate: the derived predicate.
        head: the head's arguments (variables of ``parameters``, or objects).
        parameters: every variable of the rule, typed (the head's, then the body's existential ones).
        clause: the body, a conjunction of literals.
        origin: what the rule comes from, for messages (a derived predicate, an action or the goal).
        span: where that is in its file, when known.
    """

    predicate: str
    head: tuple[str, ...]
    parameters: tuple[TypedName, ...]
    clause: Clause
    origin: str
    span: SourceSpan | None = None


def nnf(formula: Formula, positive: bool = True) -> Formula:
    """``formula`` (or its negation) in negation normal form: ``not`` only on atoms and equalities, no ``imply``."""
    if isinstance(formula, Atom | Equals):
        return formula if positive else Not(formula)
    if isinstance(formula, Not):
        return nnf(formula.formula, not positive)
    if isinstance(formula, Imply):
        if positive:
            return Or((nnf(formula.condition, False), nnf(formula.consequence, True)))
        return And((nnf(formula.condition, True), nnf(formula.consequence, False)))
    if isinstance(formula, And | Or):
        parts = tuple(nnf(p, positive) for p in formula.parts)  # type: ignore[arg-type]
        return (And if isinstance(formula, And) == positive else Or)(parts)
    if isinstance(formula, Exists | Forall):
        body = nnf(formula.body, positive)  # type: ignore[arg-type]
        kind = type(formula) if positive else (Forall if isinstance(formula, Exists) else Exists)
        return kind(formula.variables, body)
    raise TypeError(f"not a formula: {formula!r}")


def free_variables(formula: Formula) -> set[str]:
    """The variables (``?x``) of ``formula`` that no quantifier in it binds."""
    if isinstance(formula, Atom):
        return {a for a in formula.args if a.startswith("?")}
    if isinstance(formula, Equals):
        return {a for a in (formula.left, formula.right) if a.startswith("?")}
    if isinstance(formula, Not):
        return free_variables(formula.formula)
    if isinstance(formula, Imply):
        return free_variables(formula.condition) | free_variables(formula.consequence)
    if isinstance(formula, And | Or):
        out: set[str] = set()
        for part in formula.parts:
            out |= free_variables(part)  # type: ignore[arg-type]
        return out
    if isinstance(formula, Exists | Forall):
        return free_variables(formula.body) - {v for v, _ in formula.variables}  # type: ignore[arg-type]
    raise TypeError(f"not a formula: {formula!r}")


def _conjunctive(formula: Formula) -> bool:
    """Whether a formula in NNF expands into one conjunction (literals, ``and``, ``forall`` only)."""
    if isinstance(formula, Atom | Equals | Not):
        return True
    if isinstance(formula, And):
        return all(_conjunctive(p) for p in formula.parts)  # type: ignore[arg-type]
    if isinstance(formula, Forall):
        return _conjunctive(formula.body)  # type: ignore[arg-type]
    if isinstance(formula, Or):
        return len(formula.parts) == 1 and _conjunctive(formula.parts[0])
    return False


class Compiler:
    """Turns conditions into clauses and rules (see the module docstring).

    Args:
        objects_of: the objects of a type (to expand a conjunctive ``forall``).

    Attributes:
        rules: the rules made so far (of the domain's derived predicates and the new ones).
        arity: the arity of each new predicate.
        origin: per new predicate, the derived predicate, action or goal it comes from.
    """

    def __init__(self, objects_of: ObjectsOf) -> None:
        self.objects_of = objects_of
        self.rules: list[Rule] = []
        self.arity: dict[str, int] = {}
        self.origin: dict[str, str] = {}
        self._fresh = 0

    def add_rules(
        self,
        predicate: str,
        parameters: tuple[TypedName, ...],
        body: Formula,
        origin: str,
        span: SourceSpan | None,
        head: tuple[str, ...] | None = None,
    ) -> None:
        """The rules of ``predicate(parameters) <- body`` (``body`` any formula over the parameters)."""
        args = head if head is not None else tuple(v for v, _ in parameters)
        for extra, clause in self.clauses(body, parameters, origin, span, lift=True):
            self.rules.append(Rule(predicate, args, (*parameters, *extra), clause, origin, span))

    def clauses(
        self, formula: Formula, parameters: tuple[TypedName, ...], origin: str, span: SourceSpan | None, lift: bool
    ) -> list[tuple[tuple[TypedName, ...], Clause]]:
        """``formula`` as a small disjunction of conjunctions, each with the existential variables it adds.

        Args:
            formula: any formula over ``parameters``.
            parameters: the variables in scope.
            origin: what the formula belongs to (named by the new predicates' messages).
            span: where that is.
            lift: whether an ``exists`` may add variables (else it becomes a new predicate).
        """
        scope = dict(parameters)
        simple = self._simplify(nnf(formula), scope, origin, span)
        return self._dnf(simple, scope, origin, span, lift)

    def _new(self, formula: Formula, scope: dict[str, str], origin: str, span: SourceSpan | None) -> Atom:
        """A new predicate over the free variables of ``formula`` (in scope order), with its rules."""
        free = free_variables(formula)
        params = tuple((v, t) for v, t in scope.items() if v in free)
        name = f"{NEW_PREFIX}{len(self.arity)}"
        self.arity[name] = len(params)
        self.origin[name] = origin
        self.add_rules(name, params, formula, origin, span)
        return Atom(name, tuple(v for v, _ in params))

    def _simplify(self, formula: Formula, scope: dict[str, str], origin: str, span: SourceSpan | None) -> Formula:
        """``formula`` (in NNF) with every ``forall`` over a non-conjunction replaced by a negated new predicate."""
        if isinstance(formula, Atom | Equals | Not):
            return formula
        if isinstance(formula, And | Or):
            parts = tuple(self._simplify(p, scope, origin, span) for p in formula.parts)  # type: ignore[arg-type]
            return type(formula)(parts)
        if isinstance(formula, Exists | Forall):
            inner = {**scope, **dict(formula.variables)}
            body = self._simplify(formula.body, inner, origin, span)  # type: ignore[arg-type]
            if isinstance(formula, Exists) or _conjunctive(body):
                return type(formula)(formula.variables, body)
            return Not(self._new(Exists(formula.variables, nnf(body, False)), scope, origin, span))
        raise TypeError(f"not a formula in NNF: {formula!r}")

    def _dnf(
        self, formula: Formula, scope: dict[str, str], origin: str, span: SourceSpan | None, lift: bool
    ) -> list[tuple[tuple[TypedName, ...], Clause]]:
        if isinstance(formula, Atom | Equals):
            return [((), ((True, formula),))]
        if isinstance(formula, Not):
            inner = formula.formula
            assert isinstance(inner, Atom | Equals)  # NNF: only atoms and equalities are negated
            return [((), ((False, inner),))]
        if isinstance(formula, Or):
            return [c for p in formula.parts for c in self._dnf(p, scope, origin, span, lift)]
        if isinstance(formula, And):
            branches = [self._dnf(p, scope, origin, span, lift) for p in formula.parts]  # type: ignore[arg-type]
            size = 1
            for branch in branches:
                size *= len(branch)
            if size > MAX_PRODUCT:
                for i, (part, branch) in enumerate(zip(formula.parts, branches, strict=True)):
                    if len(branch) > 1:
                        branches[i] = [((), ((True, self._new(part, scope, origin, span)),))]  # type: ignore[arg-type]
            out: list[tuple[tuple[TypedName, ...], Clause]] = [((), ())]
            for branch in branches:
                out = [(e1 + e2, c1 + c2) for e1, c1 in out for e2, c2 in branch]
            return out
        if isinstance(formula, Exists):
            if not lift:
                return [((), ((True, self._new(formula, scope, origin, span)),))]
            renamed: dict[str, str] = {}
            typed: list[TypedName] = []
            for name, kind in formula.variables:
                self._fresh += 1
                renamed[name] = f"{name}@{self._fresh}"
                typed.append((renamed[name], kind))
            body = substitute(formula.body, renamed)
            bound = {**scope, **dict(typed)}
            return [
                (tuple(typed) + extra, clause)
                for extra, clause in self._dnf(body, bound, origin, span, lift)  # type: ignore[arg-type]
            ]
        if isinstance(formula, Forall):  # conjunctive (see _simplify): one conjunction over the objects
            names = [v for v, _ in formula.variables]
            pools = [self.objects_of(t) for _, t in formula.variables]
            parts = tuple(
                substitute(formula.body, dict(zip(names, combo, strict=True))) for combo in itertools.product(*pools)
            )
            return self._dnf(And(parts), scope, origin, span, lift)  # type: ignore[arg-type]
        raise TypeError(f"not a formula in NNF: {formula!r}")


def strata(rules: Iterable[Rule], derived: set[str], origin: dict[str, str]) -> dict[str, int]:
    """The stratum of each derived predicate: at least its positive derived body predicates', above its negated ones'.

    Args:
        rules: every rule.
        derived: the derived predicates.
        origin: per generated predicate, the name to show for it.

    Raises:
        PddlError: a derived predicate depends on itself through a negation (not stratifiable).
    """
    rules = list(rules)
    edges: set[tuple[str, str, int]] = set()
    for rule in rules:
        for positive, atom in rule.clause:
            if isinstance(atom, Atom) and atom.predicate in derived:
                edges.add((rule.predicate, atom.predicate, 0 if positive else 1))
    level = dict.fromkeys(sorted(derived), 0)
    bound = len(level) + 1
    changed = True
    while changed:
        changed = False
        for head, body, weight in edges:
            if level[head] < level[body] + weight:
                level[head] = level[body] + weight
                changed = True
                if level[head] > bound:
                    _not_stratifiable(rules, edges, derived, origin)
    return level


def _not_stratifiable(rules: list[Rule], edges: set[tuple[str, str, int]], derived: set[str], origin: dict[str, str]):  # type: ignore[no-untyped-def]
    after: dict[str, set[str]] = {p: set() for p in derived}
    for head, body, _ in edges:
        after[head].add(body)

    def reach(start: str) -> set[str]:
        seen = {start}
        stack = [start]
        while stack:
            for nxt in after[stack.pop()]:
                if nxt not in seen:
                    seen.add(nxt)
                    stack.append(nxt)
        return seen

    for head, body, weight in sorted(edges):
        if weight and head in reach(body):
            cycle = sorted({p for p in reach(body) if head in reach(p)})
            shown = sorted({origin.get(p, p) for p in cycle})
            span = next((r.span for r in rules if r.predicate in cycle and r.span is not None), None)
            names = ", ".join(f"'{n}'" for n in shown)
            raise PddlError(
                f"unsupported construct: the derived predicates {names} depend on themselves through a negation "
                "(or a 'forall', which is a negated 'exists'): the rules are not stratifiable",
                span,
                "rewrite the rules so that no derived predicate depends negatively on itself",
            )
    raise PddlError("the derived predicates are not stratifiable")
