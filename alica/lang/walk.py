"""Queries over syntax trees: traversal, calls, free names, literals."""

from __future__ import annotations

from collections.abc import Iterable, Iterator

from alica.errors import FormulaError
from alica.lang.ast import (
    And,
    Bool,
    Call,
    Compare,
    Name,
    Node,
    Not,
    Number,
    Quantified,
    String,
    children,
)
from alica.lang.parser import parse
from alica.lang.unparse import unparse

#: One literal: (positive, predicate name, arguments).
Literal = tuple[bool, str, tuple[object, ...]]

_LITERAL_HINT = (
    "planner conditions must be conjunctions of predicates, each optionally "
    "negated with 'not', such as onground(?x) and not holding(?r, ?x)"
)


def walk(node: Node) -> Iterator[Node]:
    """Every node of the tree in pre-order (parents before children).

    Args:
        node: the root node.

    Yields:
        ``node`` and all its descendants, left to right.
    """
    stack = [node]
    while stack:
        current = stack.pop()
        yield current
        stack.extend(reversed(children(current)))


def calls(node: Node) -> Iterator[Call]:
    """Every :class:`Call` node in the tree, in pre-order."""
    for sub in walk(node):
        if isinstance(sub, Call):
            yield sub


def free_names(node: Node) -> set[str]:
    """Identifiers used as :class:`Name` and not bound by an enclosing quantifier.

    Call names, attribute names and quantifier type names are not included.

    Args:
        node: the root node.

    Returns:
        The set of free identifiers.
    """
    found: set[str] = set()
    stack: list[tuple[Node, frozenset[str]]] = [(node, frozenset())]
    while stack:
        current, bound = stack.pop()
        if isinstance(current, Name):
            if current.name not in bound:
                found.add(current.name)
        elif isinstance(current, Quantified):
            stack.append((current.body, bound | {var for var, _ in current.binders}))
        else:
            stack.extend((child, bound) for child in children(current))
    return found


def _term(node: Node, text: str) -> object:
    if isinstance(node, Name):
        return node.name
    if isinstance(node, (String, Number)):
        return node.value
    raise FormulaError(
        f"argument '{unparse(node)}' is not a name or a constant",
        node.column,
        text,
        "literal arguments must be variables such as ?x or constants",
    )


def _conjuncts(node: Node) -> Iterator[Node]:
    """The items of nested conjunctions, left to right, without ``true``."""
    stack = [node]
    while stack:
        current = stack.pop()
        if isinstance(current, And):
            stack.extend(reversed(current.items))
        elif not (isinstance(current, Bool) and current.value):
            yield current


def _literal(item: Node, text: str) -> tuple[bool, Node, Literal]:
    positive = True
    atom = item
    if isinstance(item, Not):
        positive, atom = False, item.operand
    if isinstance(atom, Name):
        return positive, atom, (positive, atom.name, ())
    if isinstance(atom, Call):
        return positive, atom, (positive, atom.name, tuple(_term(arg, text) for arg in atom.args))
    if isinstance(atom, Compare) and atom.op in ("==", "!="):
        args = (_term(atom.left, text), _term(atom.right, text))
        sign = positive == (atom.op == "==")
        return sign, atom, (sign, "=", args)
    raise FormulaError(f"'{unparse(item)}' is not a literal", item.column, text, _LITERAL_HINT)


def _prepare(node_or_text: Node | str, text: str) -> tuple[Node, str]:
    if isinstance(node_or_text, str):
        return parse(node_or_text), node_or_text
    return node_or_text, text


def literals(node_or_text: Node | str, *, text: str = "") -> list[Literal]:
    """Flatten a conjunction of possibly negated atoms.

    ``not onground(?x) and holding(?r, ?x)`` gives
    ``[(False, 'onground', ('?x',)), (True, 'holding', ('?r', '?x'))]``.
    A bare name is a 0-ary atom, ``a = b`` gives the predicate ``'='`` (and
    ``a != b`` its negation), ``true`` is the empty conjunction. Arguments
    must be names (given as their identifier) or constants (their value).

    Args:
        node_or_text: the formula or its text.
        text: the formula text, for error messages when a node is given.

    Returns:
        The literals in written order.

    Raises:
        FormulaError: at the first part that is not a literal.
    """
    node, text = _prepare(node_or_text, text)
    return [_literal(item, text)[2] for item in _conjuncts(node)]


def literal_text(positive: bool, name: str, args: Iterable[object] = ()) -> str:
    """A literal written back as formula text: ``on(a, b)``, ``not clear(c)``, ``start``."""
    shown = tuple(args)
    atom = f"{name}({', '.join(map(str, shown))})" if shown else name
    return atom if positive else f"not {atom}"


def atoms(node_or_text: Node | str, *, text: str = "") -> list[Node]:
    """The atoms (without negation) of a conjunction of literals.

    Args:
        node_or_text: the formula or its text.
        text: the formula text, for error messages when a node is given.

    Returns:
        The :class:`Call`, :class:`Name` or equality :class:`Compare` nodes,
        in written order.

    Raises:
        FormulaError: at the first part that is not a literal.
    """
    node, text = _prepare(node_or_text, text)
    return [_literal(item, text)[1] for item in _conjuncts(node)]
