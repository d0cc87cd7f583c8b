"""Canonical text for syntax trees.

``parse(unparse(node)) == node`` holds for every tree the parser can produce.
Parentheses are added only where precedence or associativity needs them, and
around a quantifier that is not the last thing in its context (its body would
otherwise swallow the text that follows it).
"""

from __future__ import annotations

from alica.lang.ast import (
    And,
    Attr,
    Binary,
    Bool,
    Call,
    Compare,
    Iff,
    Implies,
    Name,
    Node,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
)

# Precedence levels, lowest binding first.
_IFF, _IMPLIES, _OR, _AND, _NOT, _CMP, _ADD, _MUL, _UNARY, _POW, _ATOM = range(11)

_BINARY_PREC: dict[str, tuple[int, int, int]] = {
    # op: (own level, minimum level of left operand, of right operand)
    "+": (_ADD, _ADD, _MUL),
    "-": (_ADD, _ADD, _MUL),
    "*": (_MUL, _MUL, _UNARY),
    "/": (_MUL, _MUL, _UNARY),
    "%": (_MUL, _MUL, _UNARY),
    "^": (_POW, _ATOM, _UNARY),
}

_STRING_ESCAPES = str.maketrans({"\\": "\\\\", '"': '\\"', "\n": "\\n", "\t": "\\t", "\r": "\\r"})


def _level(node: Node) -> int:
    if isinstance(node, Iff):
        return _IFF
    if isinstance(node, Implies):
        return _IMPLIES
    if isinstance(node, Or):
        return _OR
    if isinstance(node, And):
        return _AND
    if isinstance(node, (Not, Quantified)):
        return _NOT
    if isinstance(node, Compare):
        return _CMP
    if isinstance(node, Binary):
        return _BINARY_PREC[node.op][0]
    if isinstance(node, Unary):
        return _UNARY
    return _ATOM


def quote(value: str) -> str:
    """A string literal for ``value`` that the lexer reads back unchanged."""
    return '"' + value.translate(_STRING_ESCAPES) + '"'


def format_number(value: float) -> str:
    """Text of a numeric literal."""
    return repr(value) if isinstance(value, float) else str(value)


def _binders(binders: tuple[tuple[str, str], ...]) -> str:
    groups: list[tuple[list[str], str]] = []
    for var, type_name in binders:
        if groups and groups[-1][1] == type_name:
            groups[-1][0].append(var)
        else:
            groups.append(([var], type_name))
    return ", ".join(f"{', '.join(names)} in {type_name}" for names, type_name in groups)


def _fmt(node: Node, minimum: int, tail: bool) -> str:
    if _level(node) < minimum or (isinstance(node, Quantified) and not tail):
        return "(" + _text(node, True) + ")"
    return _text(node, tail)


def _text(node: Node, tail: bool) -> str:
    if isinstance(node, Name):
        return node.name
    if isinstance(node, Number):
        return format_number(node.value)
    if isinstance(node, String):
        return quote(node.value)
    if isinstance(node, Bool):
        return "true" if node.value else "false"
    if isinstance(node, Call):
        return f"{node.name}({', '.join(_fmt(arg, _IFF, True) for arg in node.args)})"
    if isinstance(node, Attr):
        return f"{_fmt(node.obj, _ATOM, False)}.{node.name}"
    if isinstance(node, Unary):
        return node.op + _fmt(node.operand, _UNARY, False)
    if isinstance(node, Binary):
        _, left, right = _BINARY_PREC[node.op]
        return f"{_fmt(node.left, left, False)} {node.op} {_fmt(node.right, right, False)}"
    if isinstance(node, Compare):
        return f"{_fmt(node.left, _ADD, False)} {node.op} {_fmt(node.right, _ADD, False)}"
    if isinstance(node, Not):
        return "not " + _fmt(node.operand, _NOT, tail)
    if isinstance(node, (And, Or)):
        word, minimum = (" and ", _NOT) if isinstance(node, And) else (" or ", _AND)
        last = len(node.items) - 1
        return word.join(_fmt(item, minimum, tail and i == last) for i, item in enumerate(node.items))
    if isinstance(node, Implies):
        return f"{_fmt(node.left, _OR, False)} -> {_fmt(node.right, _IMPLIES, tail)}"
    if isinstance(node, Iff):
        return f"{_fmt(node.left, _IFF, False)} <-> {_fmt(node.right, _IMPLIES, tail)}"
    if isinstance(node, Quantified):
        return f"{node.kind} {_binders(node.binders)}: {_fmt(node.body, _IFF, True)}"
    raise TypeError(f"not a formula node: {node!r}")


def unparse(node: Node) -> str:
    """Canonical text of a formula.

    Args:
        node: the root node.

    Returns:
        Text that parses back to a tree equal to ``node``.
    """
    return _text(node, True)
