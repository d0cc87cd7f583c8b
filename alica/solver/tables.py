"""Tables of ground pieces: a piece's value for every combination of its variables' values.

A piece reading finite variables ``v1 .. vk`` becomes a k-dimensional numpy array,
axis ``i`` running over the domain of ``vi``. The formula is evaluated once over
arrays (numpy broadcasting does the combinations): literals and names stay scalars,
a variable becomes its domain laid along its axis, and ``and``/``or``/``not``,
comparisons and arithmetic on numbers are numpy operations. ``MaximalDist``,
``MinimalDist`` and ``dist`` (the built-ins) compute distances from the coordinates
of each domain value, looked up once. Every other call runs the evaluator once per
element of the broadcast arguments (a call on one variable: once per value). When
something cannot be done with arrays (an attribute of a value, a comparison of mixed
values, an error in a branch a short circuit would skip), the whole table is filled
by the evaluator, one combination at a time: slower, the same answer.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from itertools import product
from typing import Any

import numpy as np

from alica.errors import EvaluationError
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
)
from alica.lang.evaluator import evaluate, holds, shared_registry
from alica.lang.prelude import maximal_dist, minimal_dist, place_dist, position
from alica.lang.registry import Registry
from alica.solver.ground import Piece, Reading, Variables
from alica.solver.problem import Var

#: Most cells of one table; pieces over larger products are checked when their variables are assigned.
TABLE_LIMIT = 2_000_000

_NUMERIC = "biuf"
_FAST_DISTANCE: dict[Callable[..., Any], str] = {maximal_dist: ">", minimal_dist: "<", place_dist: "dist"}


class _Scalar(Exception):
    """Raised when the vectorised form cannot express a node; the caller fills the table one cell at a time."""


def _is_array(value: object) -> bool:
    return isinstance(value, np.ndarray)


def _element(value: Any, index: tuple[int, ...]) -> Any:
    if not _is_array(value):
        return value
    item = value[tuple(i if n > 1 else 0 for i, n in zip(index, value.shape))]
    return item.item() if isinstance(item, np.generic) else item


class TableMaker:
    """Builds tables of pieces over the finite domains of a problem.

    Args:
        reading: the problem's belief base with fixed values of the other variables.
        registry: registered functions (None: the built-ins).
        names: the problem's variables.
        domains: each finite variable's values, an object array.
    """

    def __init__(
        self, reading: Reading, registry: Registry | None, names: Variables, domains: dict[Var, np.ndarray]
    ) -> None:
        self.reading = reading
        self.registry = registry
        self.entries = registry if registry is not None else shared_registry()
        self.names = names
        self.domains = domains
        self._places: dict[object, tuple[float, float] | None] = {}
        self._domain_ids = {id(values) for values in domains.values()}
        self._domain_coords: dict[int, np.ndarray] = {}
        self._memo: dict[tuple[object, ...], Any] = {}
        self.fallbacks = 0

    # -- public ------------------------------------------------------

    def table(self, piece: Piece, axes: Sequence[Var], *, utility: bool) -> np.ndarray:
        """The piece's value (bool, or float for a utility) for every combination of ``axes``' values."""
        shape = tuple(len(self.domains[v]) for v in axes)
        env = self.reading.env(piece.bindings())
        try:
            value = self._vec(piece.node, env, list(axes), truth=not utility)
            out = np.broadcast_to(np.asarray(value), shape)
            if utility:
                if out.dtype.kind not in "iuf":
                    raise _Scalar
                return np.array(out, dtype=float)
            if out.dtype.kind != "b":
                raise _Scalar
            return np.array(out, dtype=bool)
        except (_Scalar, EvaluationError, TypeError, ValueError, FloatingPointError, ZeroDivisionError):
            self.fallbacks += 1
            return self._cell_by_cell(piece, axes, shape, utility=utility)

    # -- one cell at a time ----------------------------------------------

    def _cell_by_cell(self, piece: Piece, axes: Sequence[Var], shape: tuple[int, ...], *, utility: bool) -> np.ndarray:
        out = np.zeros(shape, dtype=float if utility else bool)
        per_agent = dict(self.reading.per_agent)
        statics = dict(self.reading.statics)
        reading = Reading(self.reading.belief, {})
        reading.per_agent, reading.statics = per_agent, statics
        bindings = piece.bindings()
        for index in product(*(range(n) for n in shape)):
            for var, i in zip(axes, index):
                value = self.domains[var][i]
                if var.agent is None:
                    statics[var.name] = value
                else:
                    per_agent[(var.name, var.agent)] = value
            env = reading.env(bindings)
            if utility:
                value = evaluate(piece.node, reading, env, self.registry)
                if isinstance(value, bool) or not isinstance(value, numbers.Real):
                    raise EvaluationError(f"utility '{piece.term}' gives {value!r}, not a number")
                out[index] = float(value)
            else:
                out[index] = holds(piece.node, reading, env, self.registry)
        return out

    # -- vectorised ----------------------------------------------------

    def _axis(self, var: Var, axes: list[Var]) -> np.ndarray:
        values = self.domains[var]
        shape = [1] * len(axes)
        shape[axes.index(var)] = len(values)
        return values.reshape(shape)

    def _scalar(self, node: Node, env: dict[str, object], truth: bool) -> Any:
        if truth:
            return holds(node, self.reading, env, self.registry)
        return evaluate(node, self.reading, env, self.registry)

    def _vec(self, node: Node, env: dict[str, object], axes: list[Var], *, truth: bool) -> Any:
        if isinstance(node, (Number, String, Bool)):
            return node.value
        if isinstance(node, Name):
            var = self.names.static.get(node.name)
            if var is not None and var in axes and node.name not in env:
                return self._axis(var, axes)
            return self._scalar(node, env, truth)
        if isinstance(node, Call):
            return self._call(node, env, axes, truth)
        if isinstance(node, Compare):
            return self._compare(node, env, axes)
        if isinstance(node, Not):
            return self._logic(np.logical_not, [self._vec(node.operand, env, axes, truth=True)])
        if isinstance(node, And):
            return self._logic(np.logical_and, [self._vec(item, env, axes, truth=True) for item in node.items])
        if isinstance(node, Or):
            return self._logic(np.logical_or, [self._vec(item, env, axes, truth=True) for item in node.items])
        if isinstance(node, Implies):
            left = self._logic(np.logical_not, [self._vec(node.left, env, axes, truth=True)])
            return self._logic(np.logical_or, [left, self._vec(node.right, env, axes, truth=True)])
        if isinstance(node, Iff):
            left = self._vec(node.left, env, axes, truth=True)
            right = self._vec(node.right, env, axes, truth=True)
            return self._logic(np.equal, [left, right])
        if isinstance(node, Binary) and node.op in "+-*/":
            left = self._number(self._vec(node.left, env, axes, truth=False))
            right = self._number(self._vec(node.right, env, axes, truth=False))
            if not (_is_array(left) or _is_array(right)):
                return self._scalar(node, env, truth)
            if node.op == "/" and np.any(np.asarray(right) == 0):
                raise _Scalar
            return {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.true_divide}[node.op](left, right)
        if isinstance(node, Unary):
            operand = self._number(self._vec(node.operand, env, axes, truth=False))
            return -operand if _is_array(operand) else self._scalar(node, env, truth)
        if isinstance(node, Quantified):
            return self._quantified(node, env, axes, truth)
        # attributes, powers, %: by the evaluator when no variable is inside, else cell by cell
        if not any(d in axes for d in self._deps(node, env)):
            return self._scalar(node, env, truth)
        raise _Scalar

    def _deps(self, node: Node, env: dict[str, object]) -> set[Var]:
        from alica.solver.ground import dependencies

        return dependencies(node, env, self.names, self.reading, self.registry)

    @staticmethod
    def _number(value: Any) -> Any:
        if _is_array(value):
            if value.dtype.kind not in "iuf":
                raise _Scalar
            return value
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise _Scalar
        return value

    @staticmethod
    def _logic(op: Any, items: list[Any]) -> Any:
        for item in items:
            if _is_array(item):
                if item.dtype.kind != "b":
                    raise _Scalar
            elif not isinstance(item, (bool, np.bool_)):
                raise _Scalar
        if len(items) == 1:
            result = op(items[0])
        else:
            result = items[0]
            for item in items[1:]:
                result = op(result, item)
        return result if _is_array(result) else bool(result)

    def _compare(self, node: Compare, env: dict[str, object], axes: list[Var]) -> Any:
        left = self._vec(node.left, env, axes, truth=False)
        right = self._vec(node.right, env, axes, truth=False)
        if not (_is_array(left) or _is_array(right)):
            return self._scalar(node, env, True)
        kinds = {np.asarray(left).dtype.kind, np.asarray(right).dtype.kind}
        numeric = kinds <= set("iuf") and not isinstance(left, bool) and not isinstance(right, bool)
        op = node.op
        if op in ("==", "!="):
            if not numeric:
                # object names: compare as the evaluator does (a bool never equals a non-bool)
                same = np.frompyfunc(_same, 2, 1)(left, right).astype(bool)
                return same if op == "==" else ~same
            return np.equal(left, right) if op == "==" else np.not_equal(left, right)
        if not numeric:
            raise _Scalar
        return {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal}[op](left, right)

    def _quantified(self, node: Quantified, env: dict[str, object], axes: list[Var], truth: bool) -> Any:
        binders = [var for var, _ in node.binders]
        domains = [tuple(self.reading.objects(type_name)) for _, type_name in node.binders]
        parts = []
        for combination in product(*domains):
            inner = dict(env)
            inner.update(zip(binders, combination, strict=True))
            parts.append(self._vec(node.body, inner, axes, truth=node.kind != "sum"))
        if node.kind == "sum":
            total: Any = 0
            for part in parts:
                total = total + self._number(part)
            return total
        if not parts:
            return node.kind == "forall"
        return self._logic(np.logical_and if node.kind == "forall" else np.logical_or, parts)

    def _call(self, node: Call, env: dict[str, object], axes: list[Var], truth: bool) -> Any:
        per_agent = self.names.per_agent.get(node.name)
        if per_agent is not None and len(node.args) == 1:
            agent = self._vec(node.args[0], env, axes, truth=False)
            if _is_array(agent):
                raise _Scalar
            var = per_agent.get(agent)
            if var is not None and var in axes:
                return self._axis(var, axes)
        args = [self._vec(arg, env, axes, truth=False) for arg in node.args]
        if not any(_is_array(a) for a in args):
            return self._scalar(node, env, truth)
        entry = self.entries.get(node.name)
        fast = _FAST_DISTANCE.get(entry.fn) if entry is not None else None
        if fast is not None:
            return self._distance(fast, args)
        return self._each(node, args, truth)

    def _key(self, value: Any) -> object:
        """A memo key for an argument: a domain laid along an axis by identity and shape, else the value."""
        if _is_array(value):
            base = value.base if value.base is not None else value
            if id(base) not in self._domain_ids:
                raise TypeError("not memoisable")
            return ("axis", id(base), value.shape)
        hash(value)
        return ("value", type(value).__name__, value)

    def _memoised(self, key: tuple[object, ...], make: Callable[[], Any]) -> Any:
        try:
            full = tuple(key)
            hash(full)
        except TypeError:
            return make()
        if full not in self._memo:
            self._memo[full] = make()
        return self._memo[full]

    def _each(self, node: Call, args: list[Any], truth: bool) -> np.ndarray:
        """The call evaluated once per element of its broadcast arguments (memoised by domain and arguments)."""
        try:
            key = ("each", node.name, truth, *(self._key(a) for a in args))
        except TypeError:
            return self._each_now(node, args, truth)
        result: np.ndarray = self._memoised(key, lambda: self._each_now(node, args, truth))
        return result

    def _each_now(self, node: Call, args: list[Any], truth: bool) -> np.ndarray:
        shape = np.broadcast_shapes(*(np.shape(a) for a in args))
        names = [f"?{i}" for i in range(len(args))]
        call = Call(node.name, tuple(Name(n) for n in names), node.column)
        out = np.empty(shape, dtype=object)
        for index in np.ndindex(shape):
            env = self.reading.env(dict(zip(names, (_element(a, index) for a in args))))
            out[index] = self._scalar(call, env, truth)
        kinds = {type(v) for v in out.flat}
        if kinds <= {bool, np.bool_}:
            return out.astype(bool)
        if all(issubclass(k, numbers.Real) and not issubclass(k, bool) for k in kinds):
            return out.astype(float)
        return out

    def _place(self, value: object) -> tuple[float, float] | None:
        key = value if isinstance(value, (str, int, float)) else None
        if key is not None and key in self._places:
            return self._places[key]
        where = position(self.reading, value)
        place: tuple[float, float] | None = None
        if where is not None:
            from alica.lang.prelude import coordinates

            xy = coordinates(where)
            place = (xy[0], xy[1]) if len(xy) == 2 else None
            if place is None:
                raise _Scalar  # 3-D positions: by the evaluator
        if key is not None:
            self._places[key] = place
        return place

    def _coords(self, value: Any) -> np.ndarray:
        """``(..., 2)`` coordinates of every element (nan where the position is unknown)."""
        if not _is_array(value):
            place = self._place(value)
            return np.array(place if place is not None else (math.nan, math.nan), dtype=float)
        base = value.base if value.base is not None else value
        if id(base) in self._domain_ids:  # a variable's domain laid along its axis: its coordinates once
            flat = self._domain_coords.get(id(base))
            if flat is None:
                flat = self._coords(base.reshape(-1).copy())
                self._domain_coords[id(base)] = flat
            return flat.reshape(value.shape + (2,))
        out = np.empty(value.shape + (2,), dtype=float)
        for index in np.ndindex(value.shape):
            place = self._place(value[index])
            out[index] = place if place is not None else (math.nan, math.nan)
        return out

    def _distance(self, kind: str, args: list[Any]) -> Any:
        p = self._coords(args[0])
        q = self._coords(args[1])
        try:
            pair = sorted([repr(self._key(args[0])), repr(self._key(args[1]))])  # distance is symmetric
            distance = self._memoised(("dist", *pair), lambda: np.hypot(p[..., 0] - q[..., 0], p[..., 1] - q[..., 1]))
        except TypeError:
            distance = np.hypot(p[..., 0] - q[..., 0], p[..., 1] - q[..., 1])
        if kind == "dist":
            if np.isnan(distance).any():
                raise _Scalar  # the evaluator names the unknown position
            return distance
        bound = self._number(args[2])
        if _is_array(bound):
            raise _Scalar
        # where numpy's rounding could differ from the evaluator's math.dist, recompute those cells as it does
        close = np.argwhere(np.abs(distance - bound) <= 1e-9 * max(1.0, abs(float(bound))))
        if len(close):
            distance = distance.copy()
            pb, qb = np.broadcast_arrays(p, q)
            for index in map(tuple, close):
                distance[index] = math.dist(tuple(pb[index]), tuple(qb[index]))
        with np.errstate(invalid="ignore"):
            return distance > bound if kind == ">" else distance < bound


def _same(x: object, y: object) -> bool:
    if isinstance(x, (bool, np.bool_)) != isinstance(y, (bool, np.bool_)):
        return False
    return bool(x == y)
