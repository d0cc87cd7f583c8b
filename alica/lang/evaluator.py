"""Evaluation of formulas against a belief base, by compiling trees to closures.

A tree is compiled once per registry into nested Python closures taking
``(belief, env)``; compiled closures are cached on the registry (keyed by the
identity of the tree, which :func:`~alica.lang.parser.parse` caches by text)
and the cache is cleared when the registry changes.

Every sub-formula is compiled either for its *value* (arguments, operands of
comparisons and arithmetic, the top of :func:`evaluate`) or for its *truth*
(operands of ``and``/``or``/``not``/``->``/``<->``, quantifier bodies, the
top of :func:`holds`). The two differ only for names and calls the belief
base does not know: their truth is ``False`` (closed world), while as a value
an unknown name is the symbol string and an unknown call is an error.
"""

from __future__ import annotations

import numbers
import operator
from collections.abc import Callable, Mapping
from itertools import product
from typing import Any

from alica.errors import EvaluationError
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
from alica.lang.belief import BeliefBase
from alica.lang.parser import parse
from alica.lang.prelude import default_registry
from alica.lang.registry import Entry, Registry
from alica.lang.unparse import unparse

Env = dict[str, object]
Closure = Callable[[BeliefBase, Env], Any]

_CACHE_LIMIT = 8192
_XYZ = {"x": 0, "y": 1, "z": 2}
_ARITH: dict[str, Callable[[Any, Any], Any]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": operator.truediv,
    "%": operator.mod,
    "^": operator.pow,
}
_ORDER: dict[str, Callable[[Any, Any], bool]] = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}
_default: Registry | None = None


def _fail(node: Node, message: str) -> EvaluationError:
    """An EvaluationError naming the sub-expression and its column.

    The error gets the attributes ``column`` and ``expression``.
    """
    expression = unparse(node)
    error = EvaluationError(f"{message} in '{expression}' at column {node.column}")
    error.column = node.column  # type: ignore[attr-defined]
    error.expression = expression  # type: ignore[attr-defined]
    return error


def _show(value: object) -> str:
    """A short ``repr`` for messages (never fails, at most 60 characters)."""
    try:
        text = repr(value)
    except Exception:  # e.g. ints too long to print
        text = f"<{type(value).__name__}>"
    return text if len(text) <= 60 else text[:57] + "..."


def _is_number(value: object) -> bool:
    kind = type(value)
    if kind is int or kind is float:
        return True
    return kind is not bool and isinstance(value, numbers.Real)


def _truth(node: Node, value: object) -> bool:
    if value is True or value is False:
        return value
    if type(value).__name__ == "bool_":  # numpy booleans
        return bool(value)
    raise _fail(node, f"expected a truth value, got {_show(value)}")


def _is_bool(value: object) -> bool:
    return value is True or value is False


class _Compiler:
    """Turns trees into closures for one registry."""

    def __init__(self, registry: Registry) -> None:
        self.registry = registry

    # -- dispatch ------------------------------------------------------

    def value(self, node: Node) -> Closure:
        method = _VALUE.get(type(node))
        if method is None:
            if type(node) in _TRUTH:
                return self.truth(node)
            raise TypeError(f"not a formula node: {node!r}")
        return method(self, node)

    def truth(self, node: Node) -> Closure:
        method = _TRUTH.get(type(node))
        if method is not None:
            return method(self, node)
        get = self.value(node)

        def check(b: BeliefBase, e: Env) -> bool:
            value = get(b, e)
            if value is True or value is False:
                return value
            return _truth(node, value)

        return check

    # -- helpers -------------------------------------------------------

    def invoker(self, node: Node, entry: Entry) -> Callable[[BeliefBase, tuple[Any, ...]], Any]:
        fn = entry.fn
        if entry.needs_belief:

            def call(b: BeliefBase, args: tuple[Any, ...]) -> Any:
                return fn(b, *args)

        else:

            def call(b: BeliefBase, args: tuple[Any, ...]) -> Any:
                return fn(*args)

        def invoke(b: BeliefBase, args: tuple[Any, ...]) -> Any:
            try:
                return call(b, args)
            except EvaluationError:
                raise
            except Exception as exc:
                raise _fail(node, f"{entry.name} failed: {type(exc).__name__}: {exc}") from exc

        return invoke

    def lookup(self, node: Node, name: str) -> Callable[[BeliefBase, tuple[Any, ...]], Any]:
        def look(b: BeliefBase, args: tuple[Any, ...]) -> Any:
            try:
                return b.lookup(name, args)
            except EvaluationError:
                raise
            except Exception as exc:
                raise _fail(node, f"belief base lookup failed: {type(exc).__name__}: {exc}") from exc

        return look

    def entry(self, node: Name | Call, count: int) -> Entry | None:
        entry = self.registry.get(node.name)
        if entry is None:
            return None
        if isinstance(node, Name):
            return entry if entry.accepts(0) else None
        if not entry.accepts(count):
            raise _fail(node, f"{entry.name} takes {entry.arity_text()}, got {count}")
        return entry

    # -- values --------------------------------------------------------

    def v_const(self, node: Number | String | Bool) -> Closure:
        value = node.value
        return lambda b, e: value

    def v_name(self, node: Name) -> Closure:
        name = node.name
        entry = self.entry(node, 0)
        if entry is not None:
            invoke = self.invoker(node, entry)

            def registered(b: BeliefBase, e: Env) -> Any:
                if name in e:
                    return e[name]
                return invoke(b, ())

            return registered
        look = self.lookup(node, name)

        def symbol(b: BeliefBase, e: Env) -> Any:
            if name in e:
                return e[name]
            value = look(b, ())
            return name if value is None else value

        return symbol

    def call_parts(self, node: Call) -> tuple[tuple[Closure, ...], Entry | None]:
        args = tuple(self.value(arg) for arg in node.args)
        return args, self.entry(node, len(args))

    def v_call(self, node: Call) -> Closure:
        args, entry = self.call_parts(node)
        if entry is not None:
            invoke = self.invoker(node, entry)
            return lambda b, e: invoke(b, tuple([arg(b, e) for arg in args]))
        look = self.lookup(node, node.name)

        def fact(b: BeliefBase, e: Env) -> Any:
            values = tuple([arg(b, e) for arg in args])
            value = look(b, values)
            if value is None:
                raise _missing(node, values)
            return value

        return fact

    def v_attr(self, node: Attr) -> Closure:
        # a.b.c...: one loop over the chain, however long
        chain: list[Attr] = []
        inner: Node = node
        while isinstance(inner, Attr):
            chain.append(inner)
            inner = inner.obj
        get = self.value(inner)
        chain.reverse()
        if len(chain) == 1:
            return lambda b, e: _attribute(node, get(b, e))

        def attrs(b: BeliefBase, e: Env) -> Any:
            obj = get(b, e)
            for link in chain:
                obj = _attribute(link, obj)
            return obj

        return attrs

    def v_unary(self, node: Unary) -> Closure:
        return self.power_chain(node)

    def v_binary(self, node: Binary) -> Closure:
        if node.op == "^":
            return self.power_chain(node)
        # a + b - c * ...: the left spine of + - * / % in one loop
        spine: list[Binary] = []
        inner: Node = node
        while isinstance(inner, Binary) and inner.op != "^":
            spine.append(inner)
            inner = inner.left
        first = self.value(inner)
        spine.reverse()
        steps = tuple((link, self.value(link.right)) for link in spine)
        if len(steps) == 1:
            right = steps[0][1]
            return lambda b, e: _arith(node, first(b, e), right(b, e))

        def arith(b: BeliefBase, e: Env) -> Any:
            x = first(b, e)
            for link, right in steps:
                x = _arith(link, x, right(b, e))
            return x

        return arith

    def power_chain(self, node: Unary | Binary) -> Closure:
        """``a ^ -b ^ c ...`` and ``- - x``: the right spine of ``^`` and unary minus in one loop.

        The bases are evaluated first, left to right, then the innermost
        operand, then the operators from the inside out.
        """
        links: list[Unary | Binary] = []
        inner: Node = node
        while True:
            if isinstance(inner, Unary):
                links.append(inner)
                inner = inner.operand
            elif isinstance(inner, Binary) and inner.op == "^":
                links.append(inner)
                inner = inner.right
            else:
                break
        bases = tuple(self.value(link.left) if isinstance(link, Binary) else None for link in links)
        last = self.value(inner)
        if len(links) == 1:
            base = bases[0]
            if base is None:
                return lambda b, e: _negate(node, last(b, e))
            return lambda b, e: _arith(node, base(b, e), last(b, e))
        pairs = tuple(zip(links, bases, strict=True))
        backwards = tuple(reversed(pairs))

        def chain(b: BeliefBase, e: Env) -> Any:
            values = [None if base is None else base(b, e) for _, base in pairs]
            x = last(b, e)
            for i, (link, base) in enumerate(backwards, 1):
                x = _negate(link, x) if base is None else _arith(link, values[-i], x)
            return x

        return chain

    # -- truths --------------------------------------------------------

    def t_bool(self, node: Bool) -> Closure:
        value = node.value
        return lambda b, e: value

    def t_name(self, node: Name) -> Closure:
        name = node.name
        entry = self.entry(node, 0)
        invoke = self.invoker(node, entry) if entry is not None else None
        look = self.lookup(node, name)

        def name_truth(b: BeliefBase, e: Env) -> bool:
            if name in e:
                value = e[name]
            elif invoke is not None:
                value = invoke(b, ())
            else:
                value = look(b, ())
                if value is None:
                    return False
            if value is True or value is False:
                return value
            return _truth(node, value)

        return name_truth

    def t_call(self, node: Call) -> Closure:
        args, entry = self.call_parts(node)
        if entry is not None:
            invoke = self.invoker(node, entry)

            def predicate(b: BeliefBase, e: Env) -> bool:
                value = invoke(b, tuple([arg(b, e) for arg in args]))
                if value is True or value is False:
                    return value
                return _truth(node, value)

            return predicate
        look = self.lookup(node, node.name)

        def fact(b: BeliefBase, e: Env) -> bool:
            value = look(b, tuple([arg(b, e) for arg in args]))
            if value is True or value is False:
                return value
            if value is None:
                return False
            return _truth(node, value)

        return fact

    def t_compare(self, node: Compare) -> Closure:
        left, right = self.value(node.left), self.value(node.right)
        op = node.op
        if op in ("==", "!="):
            negate = op == "!="

            def equal(b: BeliefBase, e: Env) -> bool:
                x = left(b, e)
                y = right(b, e)
                if _is_bool(x) != _is_bool(y):
                    return negate
                try:
                    same = bool(x == y)
                except Exception as exc:
                    raise _fail(node, f"cannot compare {_show(x)} and {_show(y)}: {exc}") from exc
                return same is not negate

            return equal
        fn = _ORDER[op]

        def order(b: BeliefBase, e: Env) -> bool:
            x = left(b, e)
            y = right(b, e)
            if (_is_number(x) and _is_number(y)) or (isinstance(x, str) and isinstance(y, str)):
                return bool(fn(x, y))
            raise _fail(node, f"cannot compare {_show(x)} {op} {_show(y)}")

        return order

    def t_not(self, node: Not) -> Closure:
        count = 0
        inner: Node = node
        while isinstance(inner, Not):
            count += 1
            inner = inner.operand
        get = self.truth(inner)
        if count % 2 == 0:
            return get
        return lambda b, e: not get(b, e)

    def t_and(self, node: And) -> Closure:
        items = tuple(self.truth(item) for item in node.items)
        if len(items) == 2:
            first, second = items
            return lambda b, e: first(b, e) and second(b, e)

        def conjunction(b: BeliefBase, e: Env) -> bool:
            return all(item(b, e) for item in items)

        return conjunction

    def t_or(self, node: Or) -> Closure:
        items = tuple(self.truth(item) for item in node.items)
        if len(items) == 2:
            first, second = items
            return lambda b, e: first(b, e) or second(b, e)

        def disjunction(b: BeliefBase, e: Env) -> bool:
            return any(item(b, e) for item in items)

        return disjunction

    def t_implies(self, node: Implies) -> Closure:
        # a -> b -> c ... is right-nested: true at the first false premise
        premises: list[Closure] = []
        inner: Node = node
        while isinstance(inner, Implies):
            premises.append(self.truth(inner.left))
            inner = inner.right
        last = self.truth(inner)
        if len(premises) == 1:
            left = premises[0]
            return lambda b, e: (not left(b, e)) or last(b, e)
        chain = tuple(premises)

        def implication(b: BeliefBase, e: Env) -> bool:
            for premise in chain:
                if not premise(b, e):
                    return True
            return bool(last(b, e))

        return implication

    def t_iff(self, node: Iff) -> Closure:
        # a <-> b <-> c ... is left-nested: one loop from the left
        rights: list[Node] = []
        inner: Node = node
        while isinstance(inner, Iff):
            rights.append(inner.right)
            inner = inner.left
        first = self.truth(inner)
        steps = tuple(self.truth(right) for right in reversed(rights))
        if len(steps) == 1:
            right = steps[0]
            return lambda b, e: first(b, e) == right(b, e)

        def equivalence(b: BeliefBase, e: Env) -> bool:
            x = first(b, e)
            for step in steps:
                x = x == step(b, e)
            return bool(x)

        return equivalence

    def domains(self, node: Quantified) -> Callable[[BeliefBase], list[tuple[object, ...]]]:
        """The objects of each binder's type, listed by the belief base."""
        types = tuple(type_name for _, type_name in node.binders)

        def domains(b: BeliefBase) -> list[tuple[object, ...]]:
            try:
                return [tuple(b.objects(type_name)) for type_name in types]
            except EvaluationError:
                raise
            except Exception as exc:
                raise _fail(node, f"cannot list objects: {type(exc).__name__}: {exc}") from exc

        return domains

    def v_quantified(self, node: Quantified) -> Closure:
        if node.kind != "sum":
            return self.t_quantified(node)
        body = self.value(node.body)
        names = tuple(var for var, _ in node.binders)
        domains = self.domains(node)

        def total(b: BeliefBase, e: Env) -> Any:
            inner = dict(e)
            result: Any = 0
            for combination in product(*domains(b)):
                inner.update(zip(names, combination, strict=True))
                term = body(b, inner)
                if not _is_number(term):
                    raise _fail(node.body, f"a sum adds numbers, but '{unparse(node.body)}' is {_show(term)}")
                result = result + term
            return result

        return total

    def t_quantified(self, node: Quantified) -> Closure:
        if node.kind == "sum":
            get = self.v_quantified(node)

            def check(b: BeliefBase, e: Env) -> bool:
                return _truth(node, get(b, e))

            return check
        body = self.truth(node.body)
        names = tuple(var for var, _ in node.binders)
        universal = node.kind == "forall"
        domains = self.domains(node)

        if len(names) == 1:
            var = names[0]

            def single(b: BeliefBase, e: Env) -> bool:
                (domain,) = domains(b)
                inner = dict(e)
                for obj in domain:
                    inner[var] = obj
                    if body(b, inner) is not universal:
                        return not universal
                return universal

            return single

        def several(b: BeliefBase, e: Env) -> bool:
            inner = dict(e)
            for combination in product(*domains(b)):
                inner.update(zip(names, combination, strict=True))
                if body(b, inner) is not universal:
                    return not universal
            return universal

        return several


def _attribute(node: Attr, obj: object) -> Any:
    """``obj.name`` as the formula language reads it (mapping key, attribute, x/y/z index)."""
    name = node.name
    if isinstance(obj, Mapping):
        if name in obj:
            return obj[name]
    elif not name.startswith("_"):
        try:
            return getattr(obj, name)
        except AttributeError:
            pass
        index = _XYZ.get(name)
        if index is not None and not isinstance(obj, (str, bytes)):
            try:
                return obj[index]  # type: ignore[index]
            except (TypeError, IndexError, KeyError):
                pass
    raise _fail(node, f"{_show(obj)} has no attribute '{name}'")


def _negate(node: Unary | Binary, value: object) -> Any:
    if _is_number(value):
        return -value  # type: ignore[operator]
    raise _fail(node, f"cannot negate {_show(value)}")


def _arith(node: Unary | Binary, x: Any, y: Any) -> Any:
    """``x op y`` for the operator of ``node``, with the language's errors."""
    op = node.op
    if not (_is_number(x) and _is_number(y)):
        raise _fail(node, f"cannot apply '{op}' to {_show(x)} and {_show(y)}")
    if op == "^" and type(x) is int and type(y) is int and y * x.bit_length() > 4096:
        x = float(x)  # keep exact powers small; huge ones overflow as floats
    try:
        result = _ARITH[op](x, y)
    except ZeroDivisionError:
        raise _fail(node, "division by zero") from None
    except (OverflowError, ValueError) as exc:
        raise _fail(node, f"arithmetic error: {exc}") from None
    if type(result) is complex:
        raise _fail(node, "result is not a real number")
    return result


def _missing(node: Call, values: tuple[Any, ...]) -> EvaluationError:
    written = unparse(node)
    looked = f"{node.name}({', '.join(map(_show, values))})"
    error = EvaluationError(f"no value for {written} in the belief base (looked up {looked}) at column {node.column}")
    error.column = node.column  # type: ignore[attr-defined]
    error.expression = written  # type: ignore[attr-defined]
    return error


_VALUE: dict[type, Callable[[_Compiler, Any], Closure]] = {
    Number: _Compiler.v_const,
    String: _Compiler.v_const,
    Bool: _Compiler.v_const,
    Name: _Compiler.v_name,
    Call: _Compiler.v_call,
    Attr: _Compiler.v_attr,
    Unary: _Compiler.v_unary,
    Binary: _Compiler.v_binary,
    Quantified: _Compiler.v_quantified,
}
_TRUTH: dict[type, Callable[[_Compiler, Any], Closure]] = {
    Bool: _Compiler.t_bool,
    Name: _Compiler.t_name,
    Call: _Compiler.t_call,
    Compare: _Compiler.t_compare,
    Not: _Compiler.t_not,
    And: _Compiler.t_and,
    Or: _Compiler.t_or,
    Implies: _Compiler.t_implies,
    Iff: _Compiler.t_iff,
    Quantified: _Compiler.t_quantified,
}


def shared_registry() -> Registry:
    """The registry used when none is given: the built-ins, created once."""
    global _default
    if _default is None:
        _default = default_registry()
    return _default


def _compiled(node_or_text: Node | str, registry: Registry | None, boolean: bool) -> Closure:
    node = parse(node_or_text) if isinstance(node_or_text, str) else node_or_text
    registry = registry if registry is not None else shared_registry()
    cache = registry._compiled
    key = (id(node), boolean)
    hit = cache.get(key)
    if hit is not None and hit[0] is node:
        return hit[1]
    compiler = _Compiler(registry)
    closure = compiler.truth(node) if boolean else compiler.value(node)
    if len(cache) >= _CACHE_LIMIT:
        cache.clear()
    cache[key] = (node, closure)
    return closure


def _env(env: Mapping[str, object] | None) -> Env:
    if env is None:
        return {}
    return env if type(env) is dict else dict(env)


def evaluate(
    node_or_text: Node | str,
    belief: BeliefBase,
    env: Mapping[str, object] | None = None,
    registry: Registry | None = None,
) -> object:
    """The value of a formula or term.

    Args:
        node_or_text: a tree or formula text (parsed with the cache).
        belief: the belief base facts, values and objects come from.
        env: variable bindings, e.g. ``{'self': robot}``; never modified.
        registry: predicates and functions; the built-ins when None.

    Returns:
        The value; a bool for logical formulas.

    Raises:
        FormulaError: when text does not parse.
        EvaluationError: naming the failing sub-expression and its column.
    """
    return _compiled(node_or_text, registry, False)(belief, _env(env))


def holds(
    node_or_text: Node | str,
    belief: BeliefBase,
    env: Mapping[str, object] | None = None,
    registry: Registry | None = None,
) -> bool:
    """Whether a formula is true; the top is read as a truth value.

    Arguments as for :func:`evaluate`. An unknown fact at the top (``holds
    ("explored", fb)``) is false.

    Raises:
        FormulaError: when text does not parse.
        EvaluationError: when evaluation fails or the value is not a bool.
    """
    return _compiled(node_or_text, registry, True)(belief, _env(env))


def compile_formula(
    node_or_text: Node | str, registry: Registry | None = None, *, boolean: bool = True
) -> Callable[..., Any]:
    """Compile once, run many times.

    Args:
        node_or_text: a tree or formula text.
        registry: predicates and functions, resolved now; the built-ins when
            None.
        boolean: compile like :func:`holds` (True) or :func:`evaluate`.

    Returns:
        A function ``run(belief, env=None)`` giving the result.
    """
    closure = _compiled(node_or_text, registry, boolean)

    def run(belief: BeliefBase, env: Mapping[str, object] | None = None) -> Any:
        return closure(belief, _env(env))

    return run
