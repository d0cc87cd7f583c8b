"""Printing RDDL syntax trees as text that the reader and pyRDDLGym read back.

One declaration per line, four spaces per level. Expressions get the
brackets they need and no more, except that ``if`` and the aggregations are
bracketed whenever they are operands, and the operand of ``-`` and ``~`` is
bracketed unless it is a name, parameter or application (pyRDDLGym lets ``~``
bind as tightly as unary minus; the reader lets it bind looser than the
comparisons; both read the printed text alike).
"""

from __future__ import annotations

from alica.prophet.rddl.ast import (
    Aggregate,
    Apply,
    Assignment,
    Binary,
    BoolConst,
    Cpf,
    Distribution,
    Domain,
    EnumValue,
    Expr,
    If,
    Instance,
    IntConst,
    Neg,
    NonFluents,
    Not,
    ObjectsDecl,
    Param,
    PVariable,
    RddlFile,
    RealConst,
    TypeDecl,
)
from alica.prophet.rddl.expressions import NOT_LEVEL, OPERATORS

_INDENT = "    "
# the parser's binding levels, shifted by one; unary minus and atoms bind tighter than every operator
_PRECEDENCE = {op: level + 1 for op, level in OPERATORS.items()}
_NOT, _NEG = NOT_LEVEL + 1, max(_PRECEDENCE.values()) + 1
_ATOM = _NEG + 1


def write_expr(expr: Expr) -> str:
    """An expression as RDDL text on one line.

    Args:
        expr: the expression.

    Returns:
        Text that :func:`~alica.prophet.rddl.parse_expr` reads to an equal expression.
    """
    return _expr(expr)[0]


def write_domain(domain: Domain) -> str:
    """A ``domain`` block as RDDL text (ends with a newline)."""
    lines = [f"domain {domain.name} {{"]
    if domain.requirements:
        lines += [f"{_INDENT}requirements = {{{', '.join(domain.requirements)}}};", ""]
    if domain.types:
        lines += _section("types", [_type(t) for t in domain.types])
    if domain.pvariables:
        lines += _section("pvariables", [_pvariable(p) for p in domain.pvariables])
    if domain.cpfs:
        lines += _section("cpfs", [_cpf(c) for c in domain.cpfs])
    if domain.reward is not None:
        lines += [f"{_INDENT}reward = {_layout(domain.reward, 2)};", ""]
    for title, items in (
        ("action-preconditions", domain.action_preconditions),
        ("state-invariants", domain.state_invariants),
        ("state-action-constraints", domain.state_action_constraints),
    ):
        if items:
            lines += _section(title, [f"{_layout(e, 3)};" for e in items])
    if lines[-1] == "":
        lines.pop()
    return "\n".join([*lines, "}", ""])


def write_non_fluents(block: NonFluents) -> str:
    """A ``non-fluents`` block as RDDL text (ends with a newline)."""
    lines = [f"non-fluents {block.name} {{", f"{_INDENT}domain = {block.domain.text};"]
    if block.objects:
        lines += _section("objects", [_objects(o) for o in block.objects], blank=False)
    if block.values:
        lines += _section("non-fluents", [_assignment(a) for a in block.values], blank=False)
    return "\n".join([*lines, "}", ""])


def write_instance(instance: Instance) -> str:
    """An ``instance`` block as RDDL text (ends with a newline)."""
    lines = [f"instance {instance.name} {{", f"{_INDENT}domain = {instance.domain.text};"]
    if instance.non_fluents is not None:
        lines.append(f"{_INDENT}non-fluents = {instance.non_fluents.text};")
    if instance.objects:
        lines += _section("objects", [_objects(o) for o in instance.objects], blank=False)
    if instance.init_state:
        lines += _section("init-state", [_assignment(a) for a in instance.init_state], blank=False)
    bound = "pos-inf" if instance.max_nondef_actions is None else str(instance.max_nondef_actions)
    lines.append(f"{_INDENT}max-nondef-actions = {bound};")
    if instance.horizon is not None:
        lines.append(f"{_INDENT}horizon = {instance.horizon};")
    if instance.discount is not None:
        lines.append(f"{_INDENT}discount = {_real(instance.discount)};")
    return "\n".join([*lines, "}", ""])


def write_rddl(item: RddlFile | Domain | NonFluents | Instance) -> str:
    """Any block, or all blocks of a file (domain, non-fluents, instance, in this order), as RDDL text.

    Args:
        item: a :class:`Domain`, :class:`NonFluents`, :class:`Instance` or :class:`RddlFile`.

    Returns:
        The text, ending with a newline; blocks are separated by a blank line.
    """
    if isinstance(item, Domain):
        return write_domain(item)
    if isinstance(item, NonFluents):
        return write_non_fluents(item)
    if isinstance(item, Instance):
        return write_instance(item)
    blocks = [b for b in (item.domain, item.non_fluents, item.instance) if b is not None]
    return "\n".join(write_rddl(b) for b in blocks)


def _section(title: str, items: list[str], *, blank: bool = True) -> list[str]:
    body = [f"{_INDENT * 2}{item}" for item in items]
    return [f"{_INDENT}{title} {{", *body, f"{_INDENT}}};", *([""] if blank else [])]


def _type(decl: TypeDecl) -> str:
    if decl.parent is None:
        return f"{decl.name} : {{{', '.join(decl.values)}}};"
    return f"{decl.name} : {decl.parent.text};"


def _pvariable(decl: PVariable) -> str:
    head = decl.name + (f"({', '.join(p.text for p in decl.params)})" if decl.params else "")
    parts = [decl.kind, decl.range.text]
    if decl.default is not None:
        parts.append(f"default = {write_expr(decl.default)}")
    if decl.level is not None:
        parts.append(f"level = {decl.level}")
    return f"{head} : {{{', '.join(parts)}}};"


def _cpf(cpf: Cpf) -> str:
    head = cpf.name + ("'" if cpf.primed else "")
    if cpf.params:
        head += f"({', '.join(p.name for p in cpf.params)})"
    return f"{head} = {_layout(cpf.expr, 3)};"


def _objects(decl: ObjectsDecl) -> str:
    return f"{decl.type.text} : {{{', '.join(n.text for n in decl.names)}}};"


def _assignment(item: Assignment) -> str:
    head = item.name + (f"({', '.join(a.text for a in item.args)})" if item.args else "")
    if isinstance(item.value, BoolConst):
        return f"{head};" if item.value.value else f"~{head};"
    return f"{head} = {write_expr(item.value)};"


def _layout(expr: Expr, depth: int) -> str:
    """An expression; an ``if`` chain is broken before ``then`` and ``else``, a long sum before ``+`` and ``-``."""
    if isinstance(expr, Binary) and expr.op in {"+", "-"} and len(write_expr(expr)) > 80:
        terms: list[tuple[str, Expr]] = []
        while isinstance(expr, Binary) and expr.op in {"+", "-"}:
            terms.append((expr.op, expr.right))
            expr = expr.left
        first = _expr(expr)
        lines = [first[0] if first[1] >= _PRECEDENCE["+"] else f"({first[0]})"]
        for op, term in reversed(terms):
            text, level = _expr(term)
            lines.append(f"{op} {text if level > _PRECEDENCE[op] else f'({text})'}")
        return ("\n" + _INDENT * depth).join(lines)
    if not isinstance(expr, If):
        return write_expr(expr)
    pad = "\n" + _INDENT * depth
    return f"if ({write_expr(expr.cond)}){pad}then {write_expr(expr.then)}{pad}else {_layout(expr.else_, depth)}"


def _real(value: float) -> str:
    text = repr(value)
    if "e" in text and "." not in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}.0e{exponent}"
    return text


def _expr(expr: Expr) -> tuple[str, int]:
    """The text of ``expr`` and how tightly it binds."""
    match expr:
        case BoolConst(value=value):
            return ("true" if value else "false"), _ATOM
        case IntConst(value=value):
            return str(value), (_NEG if value < 0 else _ATOM)
        case RealConst(value=value):
            return _real(value), (_NEG if value < 0 or repr(value).startswith("-") else _ATOM)
        case EnumValue(name=name) | Param(name=name):
            return name, _ATOM
        case Apply(name=name, args=args, primed=primed):
            head = name + ("'" if primed else "")
            return (f"{head}({', '.join(write_expr(a) for a in args)})" if args else head), _ATOM
        case Distribution(name=name, args=args):
            return f"{name}({', '.join(write_expr(a) for a in args)})", _ATOM
        case Neg(operand=operand):
            return f"-{_tight(operand)}", _NEG
        case Not(operand=operand):
            return f"~{_tight(operand)}", _NOT
        case Binary(op=op, left=left, right=right):
            level = _PRECEDENCE[op]
            left_text, left_level = _expr(left)
            right_text, right_level = _expr(right)
            if left_level < level:
                left_text = f"({left_text})"
            if right_level <= level:
                right_text = f"({right_text})"
            return f"{left_text} {op} {right_text}", level
        case If(cond=cond, then=then, else_=else_):
            return f"if ({write_expr(cond)}) then {write_expr(then)} else {write_expr(else_)}", 0
        case Aggregate(op=op, params=params, body=body):
            bound = ", ".join(f"{p.name} : {p.type.text}" for p in params)
            return f"{op}_{{{bound}}} [{write_expr(body)}]", 0
    raise TypeError(f"not an RDDL expression: {expr!r}")  # pragma: no cover


def _tight(operand: Expr) -> str:
    text, level = _expr(operand)
    simple = isinstance(operand, Apply | Param | EnumValue | BoolConst | Distribution)
    return text if simple and level == _ATOM else f"({text})"
