"""The RDDL syntax tree: frozen, slotted dataclasses.

Every node keeps the line and column where it was written; they take no part
in equality, so that a tree read back from :func:`~alica.prophet.rddl.writer.write_rddl`
equals the tree written.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True)
class BoolConst:
    """``true`` or ``false``."""

    value: bool
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class IntConst:
    """An integer literal (negative when written with a leading ``-``)."""

    value: int
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class RealConst:
    """A real literal (``0.9``, ``1e-3``; negative when written with a leading ``-``)."""

    value: float
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class EnumValue:
    """An enum value; ``name`` includes the ``@`` (``@low``)."""

    name: str
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Param:
    """A parameter; ``name`` includes the ``?`` (``?r``)."""

    name: str
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Apply:
    """A pvariable application ``f(?x, a)``, a 0-ary ``f``, or an object name used as an argument.

    ``primed`` marks the next-state value of a state fluent (``f'(?x)``, as observation cpfs use it).
    """

    name: str
    args: tuple[Expr, ...] = ()
    primed: bool = False
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Neg:
    """Unary minus ``-e``."""

    operand: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Not:
    """Negation ``~e``."""

    operand: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Binary:
    """A binary operation; ``op`` is one of ``+ - * / == ~= < <= > >= ^ & | => <=>``."""

    op: str
    left: Expr
    right: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class If:
    """``if (cond) then then_ else else_``."""

    cond: Expr
    then: Expr
    else_: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class TypedParam:
    """A parameter bound by a quantifier or aggregation: ``?x : xPos``."""

    name: str
    type: Name
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Aggregate:
    """``sum_{...} e``, ``prod_{...} e``, ``forall_{...} e`` or ``exists_{...} e``; ``op`` is the word before ``_``."""

    op: str
    params: tuple[TypedParam, ...]
    body: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Distribution:
    """A distribution such as ``Bernoulli(p)``, ``KronDelta(e)`` or ``Normal(m, v)``."""

    name: str
    args: tuple[Expr, ...]
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


Expr = BoolConst | IntConst | RealConst | EnumValue | Param | Apply | Neg | Not | Binary | If | Aggregate | Distribution
"""An RDDL expression."""
Constant = BoolConst | IntConst | RealConst | EnumValue | Apply
"""A value in a declaration, a non-fluents block or an initial state (an :class:`Apply` names an object)."""


@dataclass(frozen=True, slots=True)
class Name:
    """A name that refers to a declaration (a type, an object), kept with its place."""

    text: str
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class TypeDecl:
    """A type: ``robot : object;`` (``parent`` names the super type) or ``level : {@low, @high};``.

    Attributes:
        name: the type's name.
        parent: the super type of an object type; None for an enum type.
        values: the enum values (with ``@``); empty for an object type.
    """

    name: str
    parent: Name | None
    values: tuple[str, ...] = ()
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class PVariable:
    """A pvariable declaration ``name(types) : { kind, range, default = v };``.

    Attributes:
        name: the pvariable's name.
        params: the types of its parameters.
        kind: ``non-fluent``, ``state-fluent``, ``action-fluent``, ``interm-fluent``,
            ``observ-fluent`` or ``derived-fluent``.
        range: ``bool``, ``int``, ``real`` or a type name.
        default: the default value, if declared.
        level: the ``level`` of an interm fluent, if declared.
    """

    name: str
    params: tuple[Name, ...]
    kind: str
    range: Name
    default: Constant | None = None
    level: int | None = None
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Cpf:
    """A conditional probability function ``name'(?x, ...) = expr;`` (``primed`` for next-state fluents)."""

    name: str
    primed: bool
    params: tuple[Param, ...]
    expr: Expr
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Domain:
    """A ``domain`` block.

    Attributes:
        name: the domain's name.
        requirements: the requirement names.
        types: the type declarations.
        pvariables: the pvariable declarations.
        cpfs: the conditional probability functions.
        reward: the reward expression, if any.
        action_preconditions: the ``action-preconditions`` constraints.
        state_invariants: the ``state-invariants`` constraints.
        state_action_constraints: the ``state-action-constraints`` (or ``constraints``).
    """

    name: str
    requirements: tuple[str, ...] = ()
    types: tuple[TypeDecl, ...] = ()
    pvariables: tuple[PVariable, ...] = ()
    cpfs: tuple[Cpf, ...] = ()
    reward: Expr | None = None
    action_preconditions: tuple[Expr, ...] = ()
    state_invariants: tuple[Expr, ...] = ()
    state_action_constraints: tuple[Expr, ...] = ()
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class ObjectsDecl:
    """The objects of one type: ``robot : {r1, r2};``."""

    type: Name
    names: tuple[Name, ...]
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Assignment:
    """A value of a ground pvariable: ``F(a, b) = 3;``, ``G(a);`` (true) or ``~H;`` (false)."""

    name: str
    args: tuple[Name, ...]
    value: Constant
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class NonFluents:
    """A ``non-fluents`` block: the objects and the non-fluent values of a domain's instances."""

    name: str
    domain: Name
    objects: tuple[ObjectsDecl, ...] = ()
    values: tuple[Assignment, ...] = ()
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class Instance:
    """An ``instance`` block.

    Attributes:
        name: the instance's name.
        domain: the domain it instantiates.
        non_fluents: the non-fluents block it uses, if any.
        objects: objects declared in the instance itself.
        init_state: the initial values of state fluents that differ from their defaults.
        max_nondef_actions: the bound on concurrent actions; None for ``pos-inf``.
        horizon: the number of steps, if given.
        discount: the discount factor, if given.
    """

    name: str
    domain: Name
    non_fluents: Name | None = None
    objects: tuple[ObjectsDecl, ...] = ()
    init_state: tuple[Assignment, ...] = ()
    max_nondef_actions: int | None = None
    horizon: int | None = None
    discount: float | None = None
    line: int = field(default=0, compare=False, repr=False, kw_only=True)
    column: int = field(default=0, compare=False, repr=False, kw_only=True)


@dataclass(frozen=True, slots=True)
class RddlFile:
    """The blocks of one RDDL text; each is None when the text has none."""

    domain: Domain | None = None
    non_fluents: NonFluents | None = None
    instance: Instance | None = None
