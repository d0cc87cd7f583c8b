"""The lifted PDDL model: domains, problems, formulas and effects as immutable values.

Names are lower-cased (PDDL is case-insensitive). Variables keep their ``?``.
A typed name is a ``(name, type)`` pair; untyped names have type ``object``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from alica.prophet.planner import Feature
from alica.source import SourceSpan

OBJECT = "object"
"""The root type."""

TypedName = tuple[str, str]
"""A ``(name, type)`` pair: a parameter, variable, constant or object.

A variable's type may be ``(either t1 t2 ...)`` (see :func:`either`): then it stands for an
object of any of those types."""


def either(members: list[str] | tuple[str, ...]) -> str:
    """The name of the type ``(either m1 m2 ...)``: members sorted, repeats dropped, ``object`` absorbs all.

    >>> either(["crate", "storearea", "crate"])
    '(either crate storearea)'
    >>> either(["area"])
    'area'
    """
    unique = sorted(set(members))
    if OBJECT in unique:
        return OBJECT
    return unique[0] if len(unique) == 1 else f"(either {' '.join(unique)})"


def either_members(kind: str) -> tuple[str, ...]:
    """The member types of an ``(either ...)`` type name; ``(kind,)`` for a plain type."""
    if kind.startswith("(either ") and kind.endswith(")"):
        return tuple(kind[len("(either ") : -1].split())
    return (kind,)


@dataclass(frozen=True, slots=True)
class Atom:
    """``(predicate arg ...)``: args are variables (``?x``) or object names."""

    predicate: str
    args: tuple[str, ...] = ()

    def __str__(self) -> str:
        return f"({' '.join((self.predicate, *self.args))})"


@dataclass(frozen=True, slots=True)
class Equals:
    """``(= left right)`` between two terms."""

    left: str
    right: str

    def __str__(self) -> str:
        return f"(= {self.left} {self.right})"


@dataclass(frozen=True, slots=True)
class Not:
    """``(not formula)``; in effects the formula is an :class:`Atom` (a delete)."""

    formula: Formula

    def __str__(self) -> str:
        return f"(not {self.formula})"


@dataclass(frozen=True, slots=True)
class And:
    """``(and part ...)``; ``And(())`` is true (and the empty effect)."""

    parts: tuple[Formula, ...] | tuple[Effect, ...] = ()


@dataclass(frozen=True, slots=True)
class Or:
    """``(or part ...)``; ``Or(())`` is false."""

    parts: tuple[Formula, ...] = ()


@dataclass(frozen=True, slots=True)
class Imply:
    """``(imply condition consequence)``."""

    condition: Formula
    consequence: Formula


@dataclass(frozen=True, slots=True)
class Exists:
    """``(exists (?v - type ...) body)``."""

    variables: tuple[TypedName, ...]
    body: Formula


@dataclass(frozen=True, slots=True)
class Forall:
    """``(forall (?v - type ...) body)``: a formula, or an effect over every binding."""

    variables: tuple[TypedName, ...]
    body: Formula | Effect


@dataclass(frozen=True, slots=True)
class FluentTerm:
    """A numeric fluent (function application): ``(total-cost)``, ``(road-length ?a ?b)``."""

    function: str
    args: tuple[str, ...] = ()

    def __str__(self) -> str:
        return f"({' '.join((self.function, *self.args))})"


@dataclass(frozen=True, slots=True)
class When:
    """``(when condition effect)``: a conditional effect."""

    condition: Formula
    effect: Effect


@dataclass(frozen=True, slots=True)
class Increase:
    """``(increase (total-cost) value)``: value is a number or a fluent read from ``:init``."""

    fluent: FluentTerm
    value: int | float | FluentTerm


Formula = Atom | Equals | Not | And | Or | Imply | Exists | Forall
"""A precondition, goal or effect condition."""

Effect = Atom | Not | And | Forall | When | Increase
"""An action effect."""


@dataclass(frozen=True, slots=True)
class Predicate:
    """A predicate or function declaration: name and typed parameters."""

    name: str
    parameters: tuple[TypedName, ...] = ()

    @property
    def arity(self) -> int:
        """The number of parameters."""
        return len(self.parameters)


@dataclass(frozen=True, slots=True)
class Action:
    """An action schema.

    Attributes:
        name: the action name.
        parameters: typed parameters, in order.
        precondition: a formula (``And(())`` when absent).
        effect: an effect tree (``And(())`` when absent).
        span: where ``(:action`` is in its file (for errors found after reading; not part of equality).
    """

    name: str
    parameters: tuple[TypedName, ...]
    precondition: Formula = And(())
    effect: Effect = And(())
    span: SourceSpan | None = field(default=None, compare=False)

    @property
    def cost(self) -> int | float | FluentTerm | None:
        """The top-level ``(increase (total-cost) x)`` value (summed if numbers), None without one."""
        values = [e.value for e in top_level_parts(self.effect) if isinstance(e, Increase)]
        if not values:
            return None
        if len(values) == 1:
            return values[0]
        if all(not isinstance(v, FluentTerm) for v in values):
            return sum(v for v in values if not isinstance(v, FluentTerm))
        return values[0]


TOTAL_TIME = "total-time"
"""The makespan's fluent in a metric: ``(:metric minimize (total-time))``."""


@dataclass(frozen=True, slots=True)
class DurativeAction:
    """A durative action schema (PDDL 2.1 level 3, ``:durative-actions``).

    Attributes:
        name: the action name.
        parameters: typed parameters, in order.
        duration: ``(= ?duration d)``: a number, or a static function of the parameters read from ``:init``.
        at_start: what must hold when it starts (``(at start ...)`` conditions).
        over_all: what must hold while it runs, its end points excluded (``(over all ...)``).
        at_end: what must hold when it ends (``(at end ...)``).
        start_effect: what happens when it starts (``(at start ...)`` effects).
        end_effect: what happens when it ends (``(at end ...)`` effects).
        span: where ``(:durative-action`` is in its file (not part of equality).
    """

    name: str
    parameters: tuple[TypedName, ...]
    duration: int | float | FluentTerm
    at_start: Formula = And(())
    over_all: Formula = And(())
    at_end: Formula = And(())
    start_effect: Effect = And(())
    end_effect: Effect = And(())
    span: SourceSpan | None = field(default=None, compare=False)


def top_level_parts(effect: Effect) -> list[Effect]:
    """The parts of an effect or a formula below top-level ``and``s."""
    if isinstance(effect, And):
        out: list[Effect] = []
        for part in effect.parts:
            out.extend(top_level_parts(part))  # type: ignore[arg-type]
        return out
    return [effect]


@dataclass(frozen=True, slots=True)
class Axiom:
    """``(:derived (predicate ?x - t ...) body)``: a rule for a derived predicate.

    A derived predicate may have several rules (it holds when one body holds).

    Attributes:
        predicate: the derived predicate's name (declared in ``:predicates``).
        parameters: the head's typed variables, in order.
        body: the condition (any formula over the parameters).
        span: where ``(:derived`` is in its file (for errors found after reading; not part of equality).
    """

    predicate: str
    parameters: tuple[TypedName, ...]
    body: Formula
    span: SourceSpan | None = field(default=None, compare=False)

    @property
    def head(self) -> Atom:
        """The head as an atom over the parameters."""
        return Atom(self.predicate, tuple(v for v, _ in self.parameters))


@dataclass(frozen=True, slots=True)
class Metric:
    """``(:metric minimize (total-cost))``."""

    direction: str
    expression: FluentTerm


@dataclass(frozen=True, slots=True)
class FluentValue:
    """``(= (fluent args) value)`` in ``:init``."""

    fluent: FluentTerm
    value: int | float


@dataclass(frozen=True, slots=True)
class Domain:
    """A PDDL domain.

    Attributes:
        name: the domain name.
        requirements: the features it needs (declared, ``:adl`` expanded, and those found in use; always STRIPS).
        types: child type -> its parent types, sorted (``object`` is the implicit root
            and no key; a type declared under several parents, as ``area - object`` and ``area - surface``,
            has them all).
        constants: typed constants.
        predicates: predicate declarations.
        functions: function (numeric fluent) declarations.
        actions: action schemas.
        extra_requirements: declared requirement names that are no :class:`Feature`
            (``disjunctive-preconditions``, ``existential-preconditions``, ``universal-preconditions``).
        axioms: the rules of the derived predicates (``:derived``), in file order.
        durative_actions: durative action schemas (``:durative-action``), in file order.
    """

    name: str
    requirements: frozenset[Feature]
    types: dict[str, tuple[str, ...]] = field(default_factory=dict, hash=False)
    constants: tuple[TypedName, ...] = ()
    predicates: tuple[Predicate, ...] = ()
    functions: tuple[Predicate, ...] = ()
    actions: tuple[Action, ...] = ()
    extra_requirements: frozenset[str] = frozenset()
    axioms: tuple[Axiom, ...] = ()
    durative_actions: tuple[DurativeAction, ...] = ()

    @property
    def derived(self) -> frozenset[str]:
        """The names of the derived predicates (those with a ``:derived`` rule)."""
        return frozenset(a.predicate for a in self.axioms)

    def predicate(self, name: str) -> Predicate | None:
        """The predicate called ``name``, or None."""
        return next((p for p in self.predicates if p.name == name), None)

    def action(self, name: str) -> Action | None:
        """The action called ``name``, or None."""
        return next((a for a in self.actions if a.name == name), None)

    def durative_action(self, name: str) -> DurativeAction | None:
        """The durative action called ``name``, or None."""
        return next((a for a in self.durative_actions if a.name == name), None)

    def is_subtype(self, child: str, parent: str) -> bool:
        """Whether ``child`` is ``parent`` or below it (through any of its parents).

        ``parent`` may be an ``(either ...)`` type: then ``child`` must be below one of its members.
        """
        if parent == OBJECT or child == parent:
            return True
        wanted = set(either_members(parent))
        seen: set[str] = set()
        stack = [child]
        while stack:
            kind = stack.pop()
            if kind in wanted:
                return True
            if kind in seen:
                continue
            seen.add(kind)
            stack.extend(self.types.get(kind, ()))
        return False


@dataclass(frozen=True, slots=True)
class Problem:
    """A PDDL problem.

    Attributes:
        name: the problem name.
        domain_name: the ``(:domain ...)`` it is for.
        objects: typed objects.
        init: initial facts and fluent values, in file order.
        goal: the goal formula.
        metric: the metric, if any.
        requirements: features declared in the problem or found in its goal.
        extra_requirements: declared requirement names that are no :class:`Feature`.
    """

    name: str
    domain_name: str
    objects: tuple[TypedName, ...] = ()
    init: tuple[Atom | FluentValue, ...] = ()
    goal: Formula = And(())
    metric: Metric | None = None
    requirements: frozenset[Feature] = frozenset()
    extra_requirements: frozenset[str] = frozenset()

    @property
    def facts(self) -> tuple[Atom, ...]:
        """The initial facts (no fluent values)."""
        return tuple(i for i in self.init if isinstance(i, Atom))

    @property
    def fluent_values(self) -> dict[FluentTerm, int | float]:
        """The initial fluent values."""
        return {i.fluent: i.value for i in self.init if isinstance(i, FluentValue)}
