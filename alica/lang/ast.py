"""Syntax tree of formulas.

Every node is an immutable, hashable dataclass. Each node carries the 1-based
``column`` where its text starts; the column takes no part in equality or
hashing, so ``parse("a and b") == parse("a  and  b")``.

Synonyms are normalised by the parser: ``=`` is stored as ``==``, ``**`` as
``^``, ``&&``/``||``/``!`` as :class:`And`/:class:`Or`/:class:`Not`, and
``implies``/``iff`` as :class:`Implies`/:class:`Iff`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TypeAlias

#: Keywords of the language; they can never be identifiers.
KEYWORDS: frozenset[str] = frozenset({"and", "or", "not", "forall", "exists", "in", "implies", "iff", "true", "false"})

#: Comparison operators as stored in :class:`Compare` nodes.
COMPARE_OPS: frozenset[str] = frozenset({"<", "<=", ">", ">=", "==", "!="})

#: The domain word of ``x in agents(Name)`` binders (kept as the type name ``'agents(Name)'``).
AGENTS = "agents"

#: Kinds of :class:`Quantified` nodes: two quantifiers (truth values) and one aggregate (a number).
QUANTIFIER_KINDS: frozenset[str] = frozenset({"forall", "exists", "sum"})


def agents_of(type_name: str) -> str | None:
    """``'Explore'`` for the binder domain ``'agents(Explore)'``; ``None`` for a plain type name."""
    if type_name.startswith(AGENTS + "(") and type_name.endswith(")"):
        return type_name[len(AGENTS) + 1 : -1]
    return None


#: Arithmetic operators as stored in :class:`Binary` nodes.
ARITH_OPS: frozenset[str] = frozenset({"+", "-", "*", "/", "%", "^"})


class BaseNode:
    """Common base of all formula nodes; ``str(node)`` gives canonical text."""

    __slots__ = ()

    def __str__(self) -> str:
        from alica.lang.unparse import unparse

        return unparse(self)  # type: ignore[arg-type]


def _col() -> int:
    return field(default=0, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class Number(BaseNode):
    """A numeric literal (never negative: ``-1`` is ``Unary('-', Number(1))``)."""

    value: int | float
    column: int = _col()


@dataclass(frozen=True, slots=True)
class String(BaseNode):
    """A string literal."""

    value: str
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Bool(BaseNode):
    """``true`` or ``false``."""

    value: bool
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Name(BaseNode):
    """An identifier: a variable, a 0-ary predicate or a symbol constant."""

    name: str
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Call(BaseNode):
    """``name(arg, ...)``: a domain predicate, function or belief-base fact."""

    name: str
    args: tuple[Node, ...]
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Attr(BaseNode):
    """Attribute access ``obj.name``."""

    obj: Node
    name: str
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Unary(BaseNode):
    """Unary arithmetic; ``op`` is always ``'-'``."""

    op: str
    operand: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Binary(BaseNode):
    """Arithmetic ``left op right`` with ``op`` one of ``+ - * / % ^``."""

    op: str
    left: Node
    right: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Compare(BaseNode):
    """Comparison ``left op right`` with ``op`` one of ``< <= > >= == !=``."""

    op: str
    left: Node
    right: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Not(BaseNode):
    """Negation."""

    operand: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class And(BaseNode):
    """Conjunction of two or more items."""

    items: tuple[Node, ...]
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Or(BaseNode):
    """Disjunction of two or more items."""

    items: tuple[Node, ...]
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Implies(BaseNode):
    """Implication ``left -> right``."""

    left: Node
    right: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Iff(BaseNode):
    """Equivalence ``left <-> right``."""

    left: Node
    right: Node
    column: int = _col()


@dataclass(frozen=True, slots=True)
class Quantified(BaseNode):
    """``forall``/``exists`` over typed variables, or the aggregate ``sum``.

    Attributes:
        kind: ``'forall'``, ``'exists'`` or ``'sum'`` (the sum of an arithmetic
            body over all combinations: a number, not a truth value).
        binders: ``(variable, type name)`` pairs, in the order written; the type
            name ``'agents(E)'`` stands for the agents of entry point, task or
            state ``E`` (:func:`agents_of`).
        body: the quantified formula, or the summed term.
    """

    kind: str
    binders: tuple[tuple[str, str], ...]
    body: Node
    column: int = _col()


Node: TypeAlias = (
    Number | String | Bool | Name | Call | Attr | Unary | Binary | Compare | Not | And | Or | Implies | Iff | Quantified
)

#: Node types whose value is a truth value by construction (a ``sum`` :class:`Quantified` is not: see
#: :func:`is_logical`).
LOGICAL_TYPES: tuple[type, ...] = (Compare, Not, And, Or, Implies, Iff, Quantified, Bool)


def is_aggregate(node: object) -> bool:
    """Whether ``node`` is a ``sum`` aggregate (a number)."""
    return isinstance(node, Quantified) and node.kind == "sum"


def is_logical(node: object) -> bool:
    """Whether ``node``'s value is a truth value by construction."""
    return isinstance(node, LOGICAL_TYPES) and not is_aggregate(node)


def children(node: Node) -> tuple[Node, ...]:
    """The direct sub-nodes of ``node``, left to right.

    Args:
        node: any formula node.

    Returns:
        The child nodes (empty for literals and names).
    """
    if isinstance(node, (And, Or)):
        return node.items
    if isinstance(node, Call):
        return node.args
    if isinstance(node, (Binary, Compare, Implies, Iff)):
        return (node.left, node.right)
    if isinstance(node, (Not, Unary)):
        return (node.operand,)
    if isinstance(node, Attr):
        return (node.obj,)
    if isinstance(node, Quantified):
        return (node.body,)
    return ()
