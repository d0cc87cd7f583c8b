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


#: A piece of output: text as it is, or ``(node, minimum level, tail)`` to format.
_Piece = str | tuple[Node, int, bool]


def _parts(node: Node, tail: bool) -> list[_Piece]:
    """The text of ``node`` as pieces; sub-nodes are formatted later by :func:`unparse`."""
    if isinstance(node, Name):
        return [node.name]
    if isinstance(node, Number):
        return [format_number(node.value)]
    if isinstance(node, String):
        return [quote(node.value)]
    if isinstance(node, Bool):
        return ["true" if node.value else "false"]
    if isinstance(node, Call):
        pieces: list[_Piece] = [node.name + "("]
        for i, arg in enumerate(node.args):
            if i:
                pieces.append(", ")
            pieces.append((arg, _IFF, True))
        pieces.append(")")
        return pieces
    if isinstance(node, Attr):
        return [(node.obj, _ATOM, False), "." + node.name]
    if isinstance(node, Unary):
        return [node.op, (node.operand, _UNARY, False)]
    if isinstance(node, Binary):
        _, left, right = _BINARY_PREC[node.op]
        return [(node.left, left, False), f" {node.op} ", (node.right, right, False)]
    if isinstance(node, Compare):
        return [(node.left, _ADD, False), f" {node.op} ", (node.right, _ADD, False)]
    if isinstance(node, Not):
        return ["not ", (node.operand, _NOT, tail)]
    if isinstance(node, (And, Or)):
        word, minimum = (" and ", _NOT) if isinstance(node, And) else (" or ", _AND)
        last = len(node.items) - 1
        pieces = []
        for i, item in enumerate(node.items):
            if i:
                pieces.append(word)
            pieces.append((item, minimum, tail and i == last))
        return pieces
    if isinstance(node, Implies):
        return [(node.left, _OR, False), " -> ", (node.right, _IMPLIES, tail)]
    if isinstance(node, Iff):
        return [(node.left, _IFF, False), " <-> ", (node.right, _IMPLIES, tail)]
    if isinstance(node, Quantified):
        body_level = _ADD if node.kind == "sum" else _IFF  # a sum's body is an arithmetic term
        return [f"{node.kind} {_binders(node.binders)}: ", (node.body, body_level, True)]
    raise TypeError(f"not a formula node: {node!r}")


def unparse(node: Node) -> str:
    """Canonical text of a formula.

    Args:
        node: the root node.

    Returns:
        Text that parses back to a tree equal to ``node``.
    """
    # an explicit stack instead of recursion: chains of any length unparse
    out: list[str] = []
    stack: list[_Piece] = [(node, _IFF, True)]
    while stack:
        piece = stack.pop()
        if isinstance(piece, str):
            out.append(piece)
            continue
        sub, minimum, tail = piece
        if _level(sub) < minimum or (isinstance(sub, Quantified) and not tail):
            stack.extend((")", (sub, _IFF, True), "("))
        else:
            stack.extend(reversed(_parts(sub, tail)))
    return "".join(out)
