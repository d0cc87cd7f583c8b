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

With a :class:`~alica.lang.vocabulary.Vocabulary` also checked:

* a predicate or function that is neither registered nor declared, with the
  closest known name as a suggestion;
* a declared one called with an arity it is not declared with;
* a declared function where a truth value is needed.

A bare name where a truth value is needed must be a bound variable (of a
quantifier, or one of ``bound``) or a registered or declared 0-ary predicate;
elsewhere a bare name is a symbol (an object constant such as ``a`` in
``On(a, g)``) and is never reported. Without a vocabulary unknown names are
allowed: they are facts of the belief base.
"""

from __future__ import annotations

import difflib

from alica.errors import FormulaError
from alica.lang.ast import (
    And,
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
    children,
    is_aggregate,
    is_logical,
)
from alica.lang.parser import parse
from alica.lang.registry import Registry
from alica.lang.unparse import unparse
from alica.lang.vocabulary import FUNCTION, PREDICATE, Vocabulary, arity_text


def _describe(node: Node) -> str:
    if isinstance(node, Number):
        return "a number"
    if isinstance(node, String):
        return "a string"
    if isinstance(node, Bool):
        return "a truth value"
    if isinstance(node, (Binary, Unary)):
        return "an arithmetic expression"
    if is_aggregate(node):
        return "a sum, a number"
    return "a logical formula"


class _Checker:
    def __init__(
        self, registry: Registry | None, text: str, vocabulary: Vocabulary | None, bound: frozenset[str]
    ) -> None:
        self.registry = registry
        self.text = text
        self.vocabulary = vocabulary
        self.bound = bound
        self.errors: list[FormulaError] = []

    def report(self, node: Node, message: str, hint: str = "") -> None:
        self.errors.append(FormulaError(message, node.column, self.text, hint))

    def visit(self, root: Node, boolean: bool) -> None:
        """Check ``root`` and its sub-formulas in pre-order, with an explicit stack (no recursion)."""
        outer = self.bound
        stack: list[tuple[Node, bool, frozenset[str]]] = [(root, boolean, outer)]
        while stack:
            node, boolean, self.bound = stack.pop()
            self.check_node(node, boolean)
            if isinstance(node, Quantified):
                # a quantifier's body is a truth value, a sum's a number
                body_boolean = not is_aggregate(node)
                stack.append((node.body, body_boolean, self.bound | {var for var, _ in node.binders}))
                continue
            logical = isinstance(node, (Not, And, Or, Implies, Iff))
            stack.extend((child, logical, self.bound) for child in reversed(children(node)))
        self.bound = outer

    def check_node(self, node: Node, boolean: bool) -> None:
        """The checks of one node (``boolean``: a truth value is needed here)."""
        if boolean and (isinstance(node, (Number, String, Binary, Unary)) or is_aggregate(node)):
            self.report(
                node,
                f"'{unparse(node)}' is {_describe(node)}, not a truth value",
                "compare it, e.g. x > 0",
            )
        if isinstance(node, Call):
            self.check_call(node)
            if node.name in self.bound and len(node.args) == 1:
                return  # a variable with one value per agent, read for one of them: frontier(a)
            if self.vocabulary is not None:
                self.check_declared(node, len(node.args), boolean)
        elif isinstance(node, Name):
            if self.vocabulary is not None and boolean and node.name not in self.bound:
                self.check_declared(node, 0, boolean)
        elif isinstance(node, Quantified):
            self.check_binders(node)
        elif isinstance(node, (Binary, Unary)):
            for operand in children(node):
                if isinstance(operand, String) or is_logical(operand):
                    self.report(
                        operand,
                        f"'{unparse(operand)}' is {_describe(operand)}, not a number",
                        f"arithmetic needs numbers, e.g. x {node.op} 1",
                    )
        elif isinstance(node, Compare) and node.op not in ("==", "!="):
            for operand in (node.left, node.right):
                if is_logical(operand):
                    self.report(
                        operand,
                        f"'{unparse(operand)}' is {_describe(operand)}, which cannot be ordered",
                        "use = or != to compare truth values",
                    )

    def check_declared(self, node: Name | Call, count: int, boolean: bool) -> None:
        """A name read as a predicate (``boolean``) or a function must be registered or declared."""
        assert self.vocabulary is not None
        name = node.name
        if self.registry is not None and name in self.registry:
            return  # registered: its arity is checked by check_call
        symbols = self.vocabulary.lookup(name)
        wanted = PREDICATE if boolean else FUNCTION
        if not symbols:
            close = difflib.get_close_matches(name, self._known(boolean), n=1, cutoff=0.6)
            mean = f" (did you mean '{close[0]}'?)" if close else ""
            self.report(
                node,
                f"unknown {wanted} '{name}'{mean}",
                f"declare it, e.g. under '{wanted}s:' as {name}/{count}, or import the file (or name with --skills the plug-in) that declares it",
            )
            return
        symbol = self.vocabulary.get(name, count)
        if symbol is None:
            arities = [s.arity for s in symbols]
            self.report(
                node,
                f"{symbols[0].kind} '{name}' takes {arity_text(arities)}, got {count}",
                symbols[0].doc or f"declared as {', '.join(str(s) for s in symbols)}",
            )
        elif boolean and symbol.kind == FUNCTION:
            self.report(
                node,
                f"'{unparse(node)}' is a function, not a predicate, so it is no truth value",
                f"compare its value, e.g. {unparse(node)} = x, or declare {symbol} as a predicate",
            )

    def _known(self, boolean: bool) -> list[str]:
        """Names to suggest: where a truth value is needed, the predicates and bound variables only."""
        names = set(self.bound) if boolean else set()
        if self.vocabulary is not None:
            names.update(s.name for s in self.vocabulary if not boolean or s.kind == PREDICATE)
        if self.registry is not None:
            names.update(e.name for e in self.registry if not boolean or e.kind == PREDICATE)
        return sorted(names)

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
    vocabulary: Vocabulary | None = None,
    bound: frozenset[str] | set[str] = frozenset(),
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
        vocabulary: the declared predicates and functions; when given, a
            name read as a predicate or function must be registered or
            declared with the arity it is used with. None checks no names.
        bound: variables bound around the formula (``self``, the plan's
            variables); a bare one is allowed where a truth value is needed.

    Returns:
        The problems found, in pre-order; empty when none.

    Raises:
        FormulaError: when ``node`` is text that does not parse.
    """
    if isinstance(node, str):
        text = text or node
        node = parse(node)
    checker = _Checker(registry, text, vocabulary, frozenset(bound))
    checker.visit(node, boolean)
    return checker.errors
