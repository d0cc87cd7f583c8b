"""Normal forms for grounding: quantifiers expanded over objects, negation normal form, DNF, flat effects.

Quantified variables are replaced by object names (objects never start with
``?``), so what remains mentions only the action parameters.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from alica.prophet.pddl.errors import PddlError
from alica.prophet.pddl.model import (
    And,
    Atom,
    Effect,
    Equals,
    Exists,
    FluentTerm,
    Forall,
    Formula,
    Imply,
    Increase,
    Not,
    Or,
    TypedName,
    When,
)

Literal = tuple[bool, Atom | Equals]
"""``(positive, atom)``: an atom or equality, or its negation."""

Clause = tuple[Literal, ...]
"""A conjunction of literals."""

ObjectsOf = Callable[[str], list[str]]
"""The objects of a type (subtypes included)."""

MAX_CLAUSES = 4096
"""The most conjunctions a formula may expand into."""
TOO_MANY = (
    f"the formula expands into more than {MAX_CLAUSES} disjuncts "
    "(an 'or' or 'exists' inside a 'forall', or a negated 'and')"
)
"""The message of the error :func:`dnf` raises beyond :data:`MAX_CLAUSES`: the grounder
(:mod:`alica.prophet.pddl.reach`) then writes the formula over derived predicates
(:mod:`alica.prophet.pddl.adl`) instead."""


@dataclass(frozen=True, slots=True)
class EffectItem:
    """One literal of a flattened effect.

    Attributes:
        condition: the ``when`` condition in DNF (None: unconditional).
        positive: add (True) or delete (False).
        atom: the atom.
    """

    condition: tuple[Clause, ...] | None
    positive: bool
    atom: Atom


def substitute(formula: Formula | Effect, mapping: Mapping[str, str]) -> Formula | Effect:
    """``formula`` with variables replaced as ``mapping`` says."""
    if isinstance(formula, Atom):
        return Atom(formula.predicate, tuple(mapping.get(a, a) for a in formula.args))
    if isinstance(formula, Equals):
        return Equals(mapping.get(formula.left, formula.left), mapping.get(formula.right, formula.right))
    if isinstance(formula, Not):
        return Not(substitute(formula.formula, mapping))  # type: ignore[arg-type]
    if isinstance(formula, And):
        return And(tuple(substitute(p, mapping) for p in formula.parts))  # type: ignore[arg-type]  # parts stay formulas
    if isinstance(formula, Or):
        return Or(tuple(substitute(p, mapping) for p in formula.parts))  # type: ignore[misc]
    if isinstance(formula, Imply):
        return Imply(substitute(formula.condition, mapping), substitute(formula.consequence, mapping))  # type: ignore[arg-type]
    if isinstance(formula, Exists | Forall):
        inner = {k: v for k, v in mapping.items() if k not in dict(formula.variables)}
        return type(formula)(formula.variables, substitute(formula.body, inner))  # type: ignore[arg-type]
    if isinstance(formula, When):
        return When(substitute(formula.condition, mapping), substitute(formula.effect, mapping))  # type: ignore[arg-type]
    if isinstance(formula, Increase):
        value = formula.value
        if isinstance(value, FluentTerm):
            value = FluentTerm(value.function, tuple(mapping.get(a, a) for a in value.args))
        return Increase(formula.fluent, value)
    raise TypeError(f"not a formula: {formula!r}")


def _bindings(variables: tuple[TypedName, ...], objects_of: ObjectsOf) -> list[dict[str, str]]:
    names = [v for v, _ in variables]
    pools = [objects_of(t) for _, t in variables]
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*pools)]


def expand(formula: Formula, objects_of: ObjectsOf) -> Formula:
    """``formula`` without quantifiers: ``forall`` becomes ``and``, ``exists`` becomes ``or`` over the objects."""
    if isinstance(formula, Atom | Equals):
        return formula
    if isinstance(formula, Not):
        return Not(expand(formula.formula, objects_of))
    if isinstance(formula, And):
        return And(tuple(expand(p, objects_of) for p in formula.parts))  # type: ignore[arg-type]
    if isinstance(formula, Or):
        return Or(tuple(expand(p, objects_of) for p in formula.parts))
    if isinstance(formula, Imply):
        return Imply(expand(formula.condition, objects_of), expand(formula.consequence, objects_of))
    if isinstance(formula, Exists | Forall):
        parts = tuple(expand(substitute(formula.body, b), objects_of) for b in _bindings(formula.variables, objects_of))  # type: ignore[arg-type]
        return And(parts) if isinstance(formula, Forall) else Or(parts)
    raise TypeError(f"not a formula: {formula!r}")


def dnf(formula: Formula) -> tuple[Clause, ...]:
    """The quantifier-free ``formula`` as a disjunction of conjunctions of literals.

    Raises:
        PddlError: it expands into more than :data:`MAX_CLAUSES` conjunctions.
    """
    return _dnf(formula, True)


def _dnf(formula: Formula, positive: bool) -> tuple[Clause, ...]:
    if isinstance(formula, Atom | Equals):
        return (((positive, formula),),)
    if isinstance(formula, Not):
        return _dnf(formula.formula, not positive)
    if isinstance(formula, Imply):
        return _dnf(Or((Not(formula.condition), formula.consequence)), positive)
    if isinstance(formula, And | Or):
        conjunction = isinstance(formula, And) == positive
        branches = [_dnf(p, positive) for p in formula.parts]  # type: ignore[arg-type]
        if not conjunction:
            out = tuple(c for branch in branches for c in branch)
        else:
            out = ((),)
            for branch in branches:
                out = tuple(a + b for a in out for b in branch)
                if len(out) > MAX_CLAUSES:
                    raise PddlError(TOO_MANY)
        if len(out) > MAX_CLAUSES:
            raise PddlError(TOO_MANY)
        return out
    raise TypeError(f"not a quantifier-free formula: {formula!r}")


def flatten_effect(effect: Effect, objects_of: ObjectsOf) -> tuple[list[EffectItem], list[int | float | FluentTerm]]:
    """The effect as literals (``forall`` expanded, ``when`` conditions in DNF) and its cost increases.

    Raises:
        PddlError: a cost increase inside ``when`` or ``forall``, or a nested ``when``.
    """
    items: list[EffectItem] = []
    costs: list[int | float | FluentTerm] = []
    _flatten(effect, None, objects_of, items, costs, top=True)
    return items, costs


def _flatten(
    effect: Effect,
    condition: tuple[Clause, ...] | None,
    objects_of: ObjectsOf,
    items: list[EffectItem],
    costs: list[int | float | FluentTerm],
    top: bool,
) -> None:
    if isinstance(effect, Atom):
        items.append(EffectItem(condition, True, effect))
    elif isinstance(effect, Not):
        items.append(EffectItem(condition, False, effect.formula))  # type: ignore[arg-type]
    elif isinstance(effect, And):
        for part in effect.parts:
            _flatten(part, condition, objects_of, items, costs, top)  # type: ignore[arg-type]
    elif isinstance(effect, Forall):
        for binding in _bindings(effect.variables, objects_of):
            _flatten(substitute(effect.body, binding), condition, objects_of, items, costs, False)  # type: ignore[arg-type]
    elif isinstance(effect, When):
        if condition is not None:
            raise PddlError("unsupported construct: a 'when' inside a 'when'")
        _flatten(effect.effect, dnf(expand(effect.condition, objects_of)), objects_of, items, costs, False)
    elif isinstance(effect, Increase):
        if not top or condition is not None:
            raise PddlError("unsupported construct: (increase (total-cost) ...) inside 'when' or 'forall'")
        costs.append(effect.value)
    else:
        raise TypeError(f"not an effect: {effect!r}")
