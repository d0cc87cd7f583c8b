"""The continuous solver: formulas compiled to a smooth objective, maximised by RProp with restarts.

Compilation (:class:`Compiler`) turns the constraints and utilities into a
:class:`~alica.solver.smooth.Graph` over a matrix ``X`` of shape ``(R, n)``: one row per
restart, one column per real variable and two per point variable. A quantifier at
the top (``forall a, b in agents(E): ...``, ``sum a in agents(E): ...``) is
vectorised: its combinations lie along a second axis and its body is compiled once.
Quantifiers inside it are unrolled. A sub-formula that reads no decision variable is
a constant, computed by the exact evaluator when compiled (per combination where a
quantifier is vectorised). Supported on decision variables: ``+ - * /``, ``^`` with a
constant exponent, unary minus, ``.x``/``.y`` of points, comparisons, ``and``,
``or``, ``not``, ``->``, ``<->``, ``forall``, ``exists``, ``sum``, and the built-ins
``dist``, ``sqrt``, ``abs``, ``min``, ``max``, ``MaximalDist`` and ``MinimalDist``
(points, or objects placed by ``Pos``).

The objective is ALICA's ``ConstraintUtility``: while the constraints do not hold
(their smooth truth ``C`` is below 1) a restart climbs ``C``; once they hold it climbs
the utility ``U``. Steps follow RProp (the sign of each partial derivative, a step
size per coordinate that grows by 1.2 while the sign stays and halves when it
flips), clipped to the variables' ranges. Restarts start at the warm start, if
given, then at points drawn from ``numpy.random.default_rng(problem.seed)``. A point
counts as feasible only when the exact evaluator agrees; a comparison must hold
with a margin of ``MARGIN`` in the smooth form, so that rounding does not undo it.
"""

from __future__ import annotations

import functools
import math
import numbers
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from itertools import product
from typing import Any

import numpy as np

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
    children,
)
from alica.lang.evaluator import evaluate, holds, shared_registry
from alica.lang.prelude import coordinates, maximal_dist, minimal_dist, place_dist, position
from alica.lang.registry import Registry
from alica.solver.ground import Reading, Variables
from alica.solver.problem import Point, Problem, ProblemError, Real, Var
from alica.solver.smooth import HOLDS, Graph, Operand

#: A comparison holds in the smooth form only with this much to spare.
MARGIN = 1e-6
#: Steps a restart may stay outside the constraints before their weight doubles.
PATIENCE = 10
#: Ascent steps per restart.
MAX_STEPS = 300
#: Steps without the best feasible utility growing by more than ``STALL_TOLERANCE`` (relative) that end the ascent.
STALL_STEPS = 30
#: See ``STALL_STEPS``.
STALL_TOLERANCE = 1e-4

_FLIP = {"<": ">=", "<=": ">", ">": "<=", ">=": "<", "==": "!=", "!=": "=="}


@dataclass(frozen=True)
class _Pt:
    x: Operand | float
    y: Operand | float


Value = Any  # a constant (python value or (1, K) array), a node (int) or a _Pt


class _Const:
    """A constant: a python value, or a ``(1, K)`` array along the vectorised quantifier."""

    __slots__ = ("value",)

    def __init__(self, value: Any) -> None:
        self.value = value


class Compiler:
    """Compiles a problem's formulas into one graph.

    Args:
        problem: the problem.
        names: its variables by name.
        reading: belief base with any fixed (finite) values.
        registry: registered functions.
        columns: each continuous variable's first column in ``X``.
    """

    def __init__(
        self, names: Variables, reading: Reading, registry: Registry | None, columns: dict[Var, int], width: int
    ) -> None:
        self.names = names
        self.reading = reading
        self.registry = registry
        self.entries = registry if registry is not None else shared_registry()
        self.columns = columns
        self.graph = Graph(width)
        self.k = 1
        self.var_names = set(names.static) | set(names.per_agent)

    # -- helpers -------------------------------------------------------

    def _mentions(self, node: Node) -> bool:
        return not self.var_names.isdisjoint(_names(node))

    def _const(self, node: Node, env: dict[str, object], truth: bool) -> _Const:
        """A sub-formula without decision variables, by the exact evaluator (per combination)."""
        arrays = {k: v for k, v in env.items() if isinstance(v, np.ndarray)}
        if arrays and _names(node).isdisjoint(arrays):
            env = {k: v for k, v in env.items() if k not in arrays}
            arrays = {}
        if not arrays:
            run = holds if truth else evaluate
            return _Const(run(node, self.reading, self.reading.env(env), self.registry))
        out = np.empty((1, self.k), dtype=object)
        for j in range(self.k):
            scalar = {k: (v[0, j] if isinstance(v, np.ndarray) else v) for k, v in env.items()}
            run = holds if truth else evaluate
            out[0, j] = run(node, self.reading, self.reading.env(scalar), self.registry)
        return _Const(_typed(out))

    def _num(self, value: Value) -> Operand | float:
        if isinstance(value, _Const):
            v = value.value
            if isinstance(v, np.ndarray):
                if v.dtype.kind not in "iuf" or v.dtype.kind == "b":
                    raise ProblemError(f"expected numbers, got {v.ravel()[:3]!r}")
                return v.astype(float)
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise ProblemError(f"expected a number, got {v!r}")
            return float(v)
        if isinstance(value, _Pt):
            raise ProblemError("a point where a number is needed (use .x, .y or dist)")
        return value

    def _point(self, value: Value) -> _Pt:
        if isinstance(value, _Pt):
            return value
        if isinstance(value, _Const):
            v = value.value
            if isinstance(v, np.ndarray):
                xs = np.empty(v.shape, dtype=float)
                ys = np.empty(v.shape, dtype=float)
                for index in np.ndindex(v.shape):
                    xs[index], ys[index] = self._place(v[index])
                return _Pt(xs, ys)
            x, y = self._place(v)
            return _Pt(x, y)
        raise ProblemError("a number where a point is needed")

    def _place(self, value: object) -> tuple[float, float]:
        where = position(self.reading, value)
        if where is None:
            raise EvaluationError(f"{value!r} is neither a point nor an object with a known Pos")
        xy = coordinates(where)
        return xy[0], xy[1]

    def _op(self, kind: str, *args: Operand | float, data: Any = None) -> Operand | float:
        if all(not isinstance(a, int) for a in args):  # constant folding
            return _fold(kind, [np.asarray(a, dtype=float) for a in args], data)
        return self.graph.add(kind, *(a if isinstance(a, int) else np.asarray(a, dtype=float) for a in args), data=data)

    # -- values --------------------------------------------------------

    def value(self, node: Node, env: dict[str, object]) -> Value:
        """A number, point or constant for ``node``."""
        if not self._mentions(node):
            return self._const(node, env, False)
        if isinstance(node, Name):
            if node.name in env:
                return _Const(env[node.name])
            if node.name in self.reading.statics:  # fixed by the outer (finite) search
                return _Const(self.reading.statics[node.name])
            var = self.names.static.get(node.name)
            if var is None:
                return self._const(node, env, False)
            return self._var(var, np.array([self.columns.get(var, -1)]), var)
        if isinstance(node, Call):
            return self._call(node, env)
        if isinstance(node, Binary):
            left, right = self.value(node.left, env), self.value(node.right, env)
            if node.op == "^":
                exponent = self._num(right)
                if isinstance(exponent, int) or np.ndim(exponent) != 0:
                    raise ProblemError(f"'{node}': the exponent must be a constant number")
                return self._op("pow", self._num(left), data=float(exponent))
            kind = {"+": "add", "-": "sub", "*": "mul", "/": "div"}.get(node.op)
            if kind is None:
                raise ProblemError(f"'{node}': '{node.op}' is not supported on continuous variables")
            if isinstance(left, _Pt) and isinstance(right, _Pt) and kind in ("add", "sub"):
                return _Pt(self._op(kind, left.x, right.x), self._op(kind, left.y, right.y))
            return self._op(kind, self._num(left), self._num(right))
        if isinstance(node, Unary):
            inner = self.value(node.operand, env)
            if isinstance(inner, _Pt):
                return _Pt(self._op("neg", inner.x), self._op("neg", inner.y))
            return self._op("neg", self._num(inner))
        if isinstance(node, Attr):
            inner = self.value(node.obj, env)
            if node.name in ("x", "y"):
                point = self._point(inner)
                return point.x if node.name == "x" else point.y
            raise ProblemError(f"'{node}': only .x and .y of a point are supported on continuous variables")
        if isinstance(node, Quantified) and node.kind == "sum":
            return self._quantified(node, env, negate=False)
        raise ProblemError(f"'{node}' is a truth value where a number is needed")

    def _var(self, var: Var, agents_cols: np.ndarray, sample: Var) -> Value:
        if isinstance(sample.domain, Point):
            return _Pt(self.graph.add("var", data=agents_cols), self.graph.add("var", data=agents_cols + 1))
        if isinstance(sample.domain, Real):
            return self.graph.add("var", data=agents_cols)
        raise ProblemError(f"{var!r}: a finite variable read where only continuous ones are solved")

    def _call(self, node: Call, env: dict[str, object]) -> Value:
        table = self.names.per_agent.get(node.name)
        if table is not None and len(node.args) == 1:
            if self._mentions(node.args[0]):
                raise ProblemError(f"'{node}': the agent of a per-agent variable must not depend on variables")
            agents = self._const(node.args[0], env, False).value
            flat = agents.ravel() if isinstance(agents, np.ndarray) else [agents]
            chosen = []
            for agent in flat:
                var = table.get(agent)
                if var is None:
                    raise ProblemError(f"'{node}': {node.name} has no variable for agent {agent!r}")
                chosen.append(var)
            fixed = [self.reading.per_agent.get((v.name, v.agent)) for v in chosen]
            if all(f is not None for f in fixed):  # finite values fixed by the outer search
                return _Const(_typed(np.array([fixed], dtype=object)) if isinstance(agents, np.ndarray) else fixed[0])
            cols = np.array([self.columns[v] for v in chosen])
            return self._var(chosen[0], cols, chosen[0])
        entry = self.entries.get(node.name)
        fn = entry.fn if entry is not None else None
        args = [self.value(arg, env) for arg in node.args]
        if fn in (maximal_dist, minimal_dist, place_dist):
            p, q = self._point(args[0]), self._point(args[1])
            dx = self._op("sub", p.x, q.x)
            dy = self._op("sub", p.y, q.y)
            d = self._op("sqrt", self._op("add", self._op("mul", dx, dx), self._op("mul", dy, dy)))
            if fn is place_dist:
                return d
            raise ProblemError(f"'{node}' is a truth value where a number is needed")
        if node.name == "sqrt" and len(args) == 1:
            return self._op("sqrt", self._num(args[0]))
        if node.name == "abs" and len(args) == 1:
            return self._op("abs", self._num(args[0]))
        if node.name in ("min", "max") and args:
            result = self._num(args[0])
            for other in args[1:]:
                result = self._op(node.name, result, self._num(other))
            return result
        if all(isinstance(a, _Const) for a in args):
            return self._const_call(node, args, truth=False)
        raise ProblemError(f"'{node}': {node.name} cannot be differentiated; only constants may be passed to it")

    def _const_call(self, node: Call, args: list[Any], truth: bool) -> _Const:
        """A call whose arguments are constants (finite values fixed outside), by the evaluator."""
        names = [f"?{i}" for i in range(len(args))]
        call = Call(node.name, tuple(Name(n) for n in names), node.column)
        return self._const(call, dict(zip(names, (a.value for a in args))), truth)

    # -- truths --------------------------------------------------------

    def truth(self, node: Node, env: dict[str, object], negate: bool = False) -> Value:
        """A smooth truth value (node), or a constant bool (or bool array)."""
        if not self._mentions(node):
            const = self._const(node, env, True).value
            if negate:
                const = np.logical_not(const) if isinstance(const, np.ndarray) else not const
            return _Const(const)
        if isinstance(node, Not):
            return self.truth(node.operand, env, not negate)
        if isinstance(node, (And, Or)):
            conj = isinstance(node, And) != negate
            items = [self.truth(item, env, negate) for item in node.items]
            return self._junction(items, conj)
        if isinstance(node, Implies):
            left = self.truth(node.left, env, not negate)
            right = self.truth(node.right, env, negate)
            return self._junction([left, right], conj=negate)
        if isinstance(node, Iff):
            both = self._junction([self.truth(node.left, env), self.truth(node.right, env)], conj=True)
            neither = self._junction([self.truth(node.left, env, True), self.truth(node.right, env, True)], conj=True)
            if negate:
                one = self._junction([self.truth(node.left, env), self.truth(node.right, env, True)], conj=True)
                other = self._junction([self.truth(node.left, env, True), self.truth(node.right, env)], conj=True)
                return self._junction([one, other], conj=False)
            return self._junction([both, neither], conj=False)
        if isinstance(node, Compare):
            op = _FLIP[node.op] if negate else node.op
            left, right = self.value(node.left, env), self.value(node.right, env)
            if isinstance(left, _Const) and isinstance(right, _Const):  # e.g. finite values fixed by the outer search
                return _Const(_constant_compare(op, left.value, right.value))
            return self._compare(op, self._num(left), self._num(right))
        if isinstance(node, Quantified):
            return self._quantified(node, env, negate)
        if isinstance(node, Call):
            entry = self.entries.get(node.name)
            fn = entry.fn if entry is not None else None
            if fn in (maximal_dist, minimal_dist) and len(node.args) == 3:
                args = [self.value(arg, env) for arg in node.args]
                p, q = self._point(args[0]), self._point(args[1])
                dx = self._op("sub", p.x, q.x)
                dy = self._op("sub", p.y, q.y)
                d = self._op("sqrt", self._op("add", self._op("mul", dx, dx), self._op("mul", dy, dy)))
                op = ">" if fn is maximal_dist else "<"
                return self._compare(_FLIP[op] if negate else op, d, self._num(args[2]))
            args = [self.value(arg, env) for arg in node.args]
            if all(isinstance(a, _Const) for a in args):
                const = self._const_call(node, args, truth=True).value
                if negate:
                    const = np.logical_not(const) if isinstance(const, np.ndarray) else not const
                return _Const(const)
        if isinstance(node, (Bool, Number, String)):
            return _Const(bool(node.value) != negate)
        raise ProblemError(f"'{node}' is not a truth value the continuous solver can follow")

    def _compare(self, op: str, left: Operand | float, right: Operand | float) -> Value:
        if op in ("<", "<="):
            return self._smooth(self._op("sub", right, left), MARGIN)
        if op in (">", ">="):
            return self._smooth(self._op("sub", left, right), MARGIN)
        gap = self._op("abs", self._op("sub", left, right))
        if op == "==":
            return self._smooth(self._op("neg", gap), -MARGIN)
        return self._smooth(gap, MARGIN)

    def _smooth(self, margin: Operand | float, threshold: float) -> Value:
        if isinstance(margin, int):
            return self.graph.add("cmp", margin, data=threshold)
        return _Const(np.asarray(margin) > threshold if np.ndim(margin) else bool(margin > threshold))

    def _junction(self, items: list[Value], conj: bool) -> Value:
        nodes: list[Operand] = []
        consts: list[Any] = []
        for item in items:
            (consts if isinstance(item, _Const) else nodes).append(item.value if isinstance(item, _Const) else item)
        const: Any = None
        if consts:
            const = consts[0]
            for c in consts[1:]:
                const = np.logical_and(const, c) if conj else np.logical_or(const, c)
        if not nodes:
            return _Const(const if isinstance(const, np.ndarray) else bool(const))
        if const is not None:
            if not isinstance(const, np.ndarray) and bool(const) == conj:
                pass  # True in an and, False in an or: no effect
            else:
                nodes.append(np.where(np.asarray(const), 1.0, -1.0))
        if len(nodes) == 1:
            return nodes[0]
        return self.graph.add("and" if conj else "or", *nodes)

    def _quantified(self, node: Quantified, env: dict[str, object], negate: bool) -> Value:
        kind = node.kind
        if negate:
            kind = "exists" if kind == "forall" else "forall"
        binders = [var for var, _ in node.binders]
        domains = [tuple(self.reading.objects(type_name)) for _, type_name in node.binders]
        combos = list(product(*domains))
        if not combos:
            return _Const(0.0) if kind == "sum" else _Const(kind == "forall")
        if self.k == 1 and not any(isinstance(v, np.ndarray) for v in env.values()):
            return self._vectorised(node, env, kind, binders, combos, negate)
        parts = []
        for combination in combos:
            inner = dict(env)
            inner.update(zip(binders, combination, strict=True))
            parts.append(self.value(node.body, inner) if kind == "sum" else self.truth(node.body, inner, negate))
        if kind == "sum":
            total: Operand | float = 0.0
            for part in parts:
                total = self._op("add", total, self._num(part))
            return total
        return self._junction(parts, conj=kind == "forall")

    def _vectorised(
        self,
        node: Quantified,
        env: dict[str, object],
        kind: str,
        binders: list[str],
        combos: list[tuple[object, ...]],
        negate: bool,
    ) -> Value:
        inner = dict(env)
        for j, name in enumerate(binders):
            column = np.empty((1, len(combos)), dtype=object)
            for i, combination in enumerate(combos):
                column[0, i] = combination[j]
            inner[name] = column
        self.k = len(combos)
        try:
            body = self.value(node.body, inner) if kind == "sum" else self.truth(node.body, inner, negate)
        finally:
            self.k = 1
        if isinstance(body, _Const):
            v = body.value
            if kind == "sum":
                return _Const(float(np.sum(np.broadcast_to(np.asarray(v, dtype=float), (1, len(combos))))))
            flags = np.broadcast_to(np.asarray(v, dtype=bool), (1, len(combos)))
            return _Const(bool(flags.all()) if kind == "forall" else bool(flags.any()))
        if kind == "sum":
            body = self._num(body)
            if not isinstance(body, int):
                return float(np.sum(np.broadcast_to(body, (1, len(combos)))))
        reducer = {"forall": "all", "exists": "any", "sum": "sum"}[kind]
        return self.graph.add(reducer, body, data=len(combos))


def _constant_compare(op: str, left: Any, right: Any) -> Any:
    """``left op right`` on constants (arrays element by element), as the evaluator compares."""

    def one(x: Any, y: Any) -> bool:
        if op in ("==", "!="):
            same = isinstance(x, (bool, np.bool_)) == isinstance(y, (bool, np.bool_)) and bool(x == y)
            return same if op == "==" else not same
        return bool({"<": x < y, "<=": x <= y, ">": x > y, ">=": x >= y}[op])

    if isinstance(left, np.ndarray) or isinstance(right, np.ndarray):
        return np.frompyfunc(one, 2, 1)(left, right).astype(bool)
    return one(left, right)


@functools.lru_cache(maxsize=4096)
def _names(node: Node) -> frozenset[str]:
    """Every name and called name in ``node``."""
    found: set[str] = set()
    stack = [node]
    while stack:
        item = stack.pop()
        if isinstance(item, (Name, Call)):
            found.add(item.name)
        stack.extend(children(item))
    return frozenset(found)


def _typed(values: np.ndarray) -> np.ndarray:
    """An object array as bools or floats when every element is one."""
    items = list(values.flat)
    if all(isinstance(v, (bool, np.bool_)) for v in items):
        return values.astype(bool)
    if all(isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)) for v in items):
        return values.astype(float)
    return values


def _fold(kind: str, args: list[np.ndarray], data: Any) -> Any:
    graph = Graph(0)
    graph.add(kind, *args, data=data)
    out = graph.forward(np.zeros((1, 0)))[-1]
    return float(out) if out.ndim == 0 else out


@dataclass
class Result:
    """What the continuous solver found."""

    values: dict[Var, object] | None
    utility: float
    complete: bool
    steps: int
    tried: int


class Continuous:
    """The continuous solver for one problem (its real and point variables).

    Args:
        problem: the problem.
        names: its variables by name.
        reading: belief base with any fixed (finite) values.
        registry: registered functions.
        fixed: values of variables solved elsewhere (finite ones of a mixed problem).
    """

    def __init__(self, problem: Problem, names: Variables, reading: Reading, registry: Registry | None) -> None:
        self.problem = problem
        self.registry = registry
        self.reading = reading
        self.vars = [v for v in problem.variables if isinstance(v.domain, (Real, Point))]
        self.columns: dict[Var, int] = {}
        lows: list[float] = []
        highs: list[float] = []
        for var in self.vars:
            self.columns[var] = len(lows)
            domain = var.domain
            assert isinstance(domain, (Real, Point))
            count = 2 if isinstance(domain, Point) else 1
            lows += [domain.low] * count
            highs += [domain.high] * count
        self.low = np.array(lows)
        self.high = np.array(highs)
        compiler = Compiler(names, reading, registry, self.columns, len(lows))
        truths = [compiler.truth(term.node, {}) for term in problem.constraints]
        self.constant_false = any(isinstance(t, _Const) and not bool(np.all(t.value)) for t in truths)
        nodes = [t for t in truths if not isinstance(t, _Const)]
        self.c_node: int | None = None
        if nodes:
            self.c_node = nodes[0] if len(nodes) == 1 else compiler.graph.add("and", *nodes)
        utils = [compiler._num(compiler.value(term.node, {})) for term in problem.utilities]
        u_nodes = [u for u in utils if isinstance(u, int)]
        self.u_node: int | None = None
        if u_nodes:
            total: Operand = u_nodes[0]
            for u in u_nodes[1:]:
                total = compiler.graph.add("add", total, u)
            self.u_node = total  # type: ignore[assignment]
        self.graph = compiler.graph

    def _values(self, row: np.ndarray) -> dict[Var, object]:
        out: dict[Var, object] = {}
        for var in self.vars:
            c = self.columns[var]
            out[var] = (float(row[c]), float(row[c + 1])) if isinstance(var.domain, Point) else float(row[c])
        return out

    def _exact(self, values: dict[Var, object]) -> bool:
        reading = self.reading.with_values(values)
        env = reading.env()
        try:
            return all(holds(t.node, reading, env, self.registry) for t in self.problem.constraints)
        except EvaluationError:
            return False

    def starts(self, restarts: int, start: Mapping[Var, object] | None) -> np.ndarray:
        """The restarts' first points: the warm start (if any), then seeded random points."""
        rng = np.random.default_rng(self.problem.seed)
        x = rng.uniform(self.low, self.high, size=(restarts, len(self.low)))
        if start:
            for var in self.vars:
                if var in start:
                    value = start[var]
                    c = self.columns[var]
                    if isinstance(var.domain, Point):
                        x[0, c : c + 2] = coordinates(value)[:2]
                    else:
                        x[0, c] = float(value)  # type: ignore[arg-type]
            x[0] = np.clip(x[0], self.low, self.high)
        return x

    def run(
        self,
        deadline: float,
        clock: Callable[[], float],
        *,
        start: Mapping[Var, object] | None = None,
        restarts: int = 64,
        x0: np.ndarray | None = None,
        max_steps: int = MAX_STEPS,
    ) -> Result:
        """Climb from every restart at once until a feasible point (no utility) or the steps run out."""
        if self.constant_false:
            return Result(None, math.nan, True, 0, 0)
        x = self.starts(restarts, start) if x0 is None else np.array(x0, dtype=float)
        r, n = x.shape
        span = np.maximum(self.high - self.low, 1e-9)
        step = np.broadcast_to(0.1 * span, (r, n)).copy()
        step_max, step_min = 0.5 * span, 1e-9 * span
        prev = np.zeros((r, n))
        best_u = np.full(r, -np.inf)
        best_x = x.copy()
        found = np.zeros(r, dtype=bool)
        bad = np.zeros(r, dtype=bool)
        ever = np.zeros(r, dtype=bool)
        outside = np.zeros(r, dtype=int)
        weight = np.full(r, 2.0)  # smooth says feasible, the evaluator does not (at a boundary)
        steps = 0
        complete = True
        record, since = -np.inf, 0  # the best utility found, and the steps since it last grew
        while steps < max_steps:
            steps += 1
            vals = self.graph.forward(x) if self.graph.ops else []
            c = vals[self.c_node][:, 0] if self.c_node is not None else np.ones(r)
            u = vals[self.u_node][:, 0] if self.u_node is not None else np.zeros(r)
            feasible = c > HOLDS
            if self.u_node is None:
                for i in np.flatnonzero(feasible & ~bad):
                    if self._exact(self._values(x[i])):
                        best_x[i], found[i] = x[i], True
                        break
                    bad[i] = True
            else:
                better = feasible & (u > best_u)
                best_u[better], best_x[better], found[better] = u[better], x[better], True
            if self.u_node is None and found.any():
                break
            if found.any():
                top = float(best_u[found].max())
                if top > record + STALL_TOLERANCE * (1.0 + abs(record) if math.isfinite(record) else 1.0):
                    record, since = top, 0
                else:
                    since += 1
                    if since >= STALL_STEPS:
                        break  # the best restart stopped improving: more steps would not pay
            if clock() > deadline:
                complete = False
                break
            if not self.graph.ops:
                break
            # before a restart first holds the constraints it climbs them alone (ALICA); afterwards it climbs
            # U + weight * (violation), an exact penalty, so that it can slide along the boundary of the
            # constraints; the weight doubles while the restart stays outside for PATIENCE steps
            ever |= feasible
            outside = np.where(feasible, 0, outside + 1)
            weight = np.where(outside >= PATIENCE, weight * 2.0, weight)
            outside = np.where(outside >= PATIENCE, 0, outside)
            seeds: dict[int, np.ndarray] = {}
            if self.c_node is not None:
                seeds[self.c_node] = np.where(feasible, 0.0, np.where(ever, weight, 1.0))[:, None]
            if self.u_node is not None:
                seeds[self.u_node] = np.where(feasible | ever, 1.0, 0.0)[:, None]
            g = self.graph.backward(x, vals, seeds)
            sign = np.sign(g)
            turn = sign * prev
            step = np.where(
                turn > 0, np.minimum(step * 1.2, step_max), np.where(turn < 0, np.maximum(step * 0.5, step_min), step)
            )
            sign = np.where(turn < 0, 0.0, sign)
            x = np.clip(x + sign * step, self.low, self.high)
            prev = sign
            if np.all(step <= 1e-7 * span):
                break
        # the best rows first (ties: the lower restart), each checked by the exact evaluator
        for i in sorted(np.flatnonzero(found), key=lambda i: (-best_u[i], i)):
            values = self._values(best_x[i])
            if self.u_node is None or self._exact(values):
                return Result(values, float(best_u[i]), complete, steps, r)
        return Result(None, math.nan, complete, steps, r)
