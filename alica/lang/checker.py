"""Static checks of formulas that need no belief base.

Checked:

* calls of registered names with a wrong number of arguments;
* a quantifier binding the same variable twice;
* a number, string or arithmetic expression where a truth value is needed
  (operands of logical connectives, quantifier bodies, and the whole formula
  when ``boolean=True``);
* a string, ``true``/``false`` or a logical formula as an arithmetic operand,
  and ``true``/``false`` or a logical formula as an operand of ``<``, ``<=``,
  ``>``, ``>=``.

Unknown predicate and function names are allowed: they are facts of the
belief base.
"""

from __future__ import annotations

from alica.errors import FormulaError
from alica.lang.ast import (
    LOGICAL_TYPES,
    And,
    Binary,
    Bool,
    Call,
    Compare,
    Iff,
    Implies,
    Node,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
    children,
)
from alica.lang.parser import parse
from alica.lang.registry import Registry
from alica.lang.unparse import unparse


def _describe(node: Node) -> str:
    if isinstance(node, Number):
        return "a number"
    if isinstance(node, String):
        return "a string"
    if isinstance(node, Bool):
        return "a truth value"
    if isinstance(node, (Binary, Unary)):
        return "an arithmetic expression"
    return "a logical formula"


class _Checker:
    def __init__(self, registry: Registry | None, text: str) -> None:
        self.registry = registry
        self.text = text
        self.errors: list[FormulaError] = []

    def report(self, node: Node, message: str, hint: str = "") -> None:
        self.errors.append(FormulaError(message, node.column, self.text, hint))

    def visit(self, node: Node, boolean: bool) -> None:
        if boolean and isinstance(node, (Number, String, Binary, Unary)):
            self.report(
                node,
                f"'{unparse(node)}' is {_describe(node)}, not a truth value",
                "compare it, e.g. x > 0",
            )
        if isinstance(node, Call):
            self.check_call(node)
        elif isinstance(node, Quantified):
            self.check_binders(node)
        elif isinstance(node, (Binary, Unary)):
            for operand in children(node):
                if isinstance(operand, (String, *LOGICAL_TYPES)):
                    self.report(
                        operand,
                        f"'{unparse(operand)}' is {_describe(operand)}, not a number",
                        f"arithmetic needs numbers, e.g. x {getattr(node, 'op', '-')} 1",
                    )
        elif isinstance(node, Compare) and node.op not in ("==", "!="):
            for operand in (node.left, node.right):
                if isinstance(operand, LOGICAL_TYPES):
                    self.report(
                        operand,
                        f"'{unparse(operand)}' is {_describe(operand)}, which cannot be ordered",
                        "use = or != to compare truth values",
                    )
        logical = isinstance(node, (Not, And, Or, Implies, Iff, Quantified))
        for child in children(node):
            self.visit(child, logical)

    def check_call(self, node: Call) -> None:
        entry = self.registry.get(node.name) if self.registry is not None else None
        if entry is None or entry.accepts(len(node.args)):
            return
        hint = entry.doc or f"call {entry.name} with {entry.arity_text()}"
        self.report(node, f"{entry.name} takes {entry.arity_text()}, got {len(node.args)}", hint)

    def check_binders(self, node: Quantified) -> None:
        seen: set[str] = set()
        for var, _ in node.binders:
            if var in seen:
                self.report(
                    node,
                    f"variable '{var}' is bound twice by '{node.kind}'",
                    "give each variable its own name",
                )
            seen.add(var)


def check(
    node: Node | str,
    registry: Registry | None = None,
    *,
    text: str = "",
    boolean: bool = False,
) -> list[FormulaError]:
    """Find static problems in a formula.

    Args:
        node: the tree, or formula text (then ``text`` defaults to it).
        registry: registered predicates and functions whose arity is checked;
            None checks no arities.
        text: the formula text, for the errors' pointers.
        boolean: whether the whole formula must be a truth value (pass True
            for conditions); by default the top may also be a term such as
            a utility summand or a binding value. Operands of ``and``,
            ``or``, ``not``, ``->``, ``<->`` and quantifier bodies are always
            checked.

    Returns:
        The problems found, in pre-order; empty when none.

    Raises:
        FormulaError: when ``node`` is text that does not parse.
    """
    if isinstance(node, str):
        text = text or node
        node = parse(node)
    checker = _Checker(registry, text)
    checker.visit(node, boolean)
    return checker.errors
