"""A small reverse-mode differentiator over numpy arrays, for the continuous solver.

A :class:`Graph` is a list of operations built once (by :mod:`alica.solver.continuous`)
and run many times. Every value has the shape ``(R, K)``: ``R`` restarts solved at once
and ``K`` the combinations of a quantifier vectorised along the second axis (``K = 1``
outside). An operand is either a node (an ``int``, the index of an earlier operation)
or a constant numpy array broadcast against it.

Truth values follow ALICA's ``ConstraintUtility``: a comparison is ``1`` when it holds
and ``steepness * margin`` (zero or less) when it does not; ``and`` is ``1`` when
every item holds and otherwise the sum of the items' violations (each at most the
minimum, so "min-like", but every violated item gets a gradient at once); ``or`` is
the maximum.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

Operand = int | np.ndarray

#: Slope of a violated comparison.
STEEPNESS = 1.0
#: A truth value above this holds.
HOLDS = 0.5


@dataclass
class Op:
    """One operation: ``kind``, its operands and constant data."""

    kind: str
    args: tuple[Operand, ...]
    data: Any = None


@dataclass
class Graph:
    """Operations in the order they run; node ``i`` is the result of ``ops[i]``."""

    width: int
    ops: list[Op] = field(default_factory=list)

    def add(self, kind: str, *args: Operand, data: Any = None) -> int:
        self.ops.append(Op(kind, args, data))
        return len(self.ops) - 1

    # -- running -------------------------------------------------------

    def forward(self, x: np.ndarray) -> list[np.ndarray]:
        """The value of every node for the points ``x`` (shape ``(R, width)``)."""
        vals: list[np.ndarray] = []

        def get(a: Operand) -> np.ndarray:
            return vals[a] if isinstance(a, int) else a

        for op in self.ops:
            k = op.kind
            args = [get(a) for a in op.args]
            if k == "var":
                out = x[:, op.data]
            elif k == "add":
                out = args[0] + args[1]
            elif k == "sub":
                out = args[0] - args[1]
            elif k == "mul":
                out = args[0] * args[1]
            elif k == "div":
                out = args[0] / args[1]
            elif k == "neg":
                out = -args[0]
            elif k == "pow":
                out = np.power(args[0], op.data)
            elif k == "sqrt":
                out = np.sqrt(np.maximum(args[0], 0.0) + 1e-12)
            elif k == "abs":
                out = np.abs(args[0])
            elif k == "max":
                out = np.maximum(args[0], args[1])
            elif k == "min":
                out = np.minimum(args[0], args[1])
            elif k == "cmp":  # margin above data holds
                m = args[0] - op.data
                out = np.where(m > 0, 1.0, STEEPNESS * m)
            elif k == "and":
                stack = np.broadcast_arrays(*args)
                held = np.all([s > HOLDS for s in stack], axis=0)
                out = np.where(held, 1.0, np.sum([np.minimum(s, 0.0) for s in stack], axis=0))
            elif k == "or":
                out = np.max(np.broadcast_arrays(*args), axis=0)
            elif k == "all":  # and over axis 1
                a = np.broadcast_to(args[0], (x.shape[0], op.data))
                held = np.all(a > HOLDS, axis=1, keepdims=True)
                out = np.where(held, 1.0, np.sum(np.minimum(a, 0.0), axis=1, keepdims=True))
            elif k == "any":
                out = np.max(np.broadcast_to(args[0], (x.shape[0], op.data)), axis=1, keepdims=True)
            elif k == "sum":
                out = np.sum(np.broadcast_to(args[0], (x.shape[0], op.data)), axis=1, keepdims=True)
            else:  # pragma: no cover - every kind is built by the compiler
                raise AssertionError(k)
            vals.append(np.asarray(out, dtype=float))
        return vals

    def backward(self, x: np.ndarray, vals: list[np.ndarray], seeds: dict[int, np.ndarray]) -> np.ndarray:
        """The gradient with respect to ``x`` of ``sum(seed * node)`` over the seeded nodes."""
        grads: list[np.ndarray | None] = [None] * len(self.ops)
        for node, seed in seeds.items():
            previous = grads[node]
            grads[node] = seed if previous is None else previous + seed
        gx = np.zeros_like(x)

        def get(a: Operand) -> np.ndarray:
            return vals[a] if isinstance(a, int) else a

        def push(a: Operand, g: np.ndarray) -> None:
            if not isinstance(a, int):
                return
            shape = vals[a].shape
            if g.shape != shape:
                g = _unbroadcast(g, shape)
            previous = grads[a]
            grads[a] = g if previous is None else previous + g

        for i in range(len(self.ops) - 1, -1, -1):
            g = grads[i]
            if g is None:
                continue
            op = self.ops[i]
            k, args = op.kind, op.args
            if k == "var":
                np.add.at(gx.T, op.data, np.broadcast_to(g, vals[i].shape).T)
            elif k == "add":
                push(args[0], g)
                push(args[1], g)
            elif k == "sub":
                push(args[0], g)
                push(args[1], -g)
            elif k == "mul":
                push(args[0], g * get(args[1]))
                push(args[1], g * get(args[0]))
            elif k == "div":
                b = get(args[1])
                push(args[0], g / b)
                push(args[1], -g * get(args[0]) / (b * b))
            elif k == "neg":
                push(args[0], -g)
            elif k == "pow":
                a = get(args[0])
                push(args[0], g * op.data * np.power(a, op.data - 1))
            elif k == "sqrt":
                push(args[0], g * 0.5 / vals[i])
            elif k == "abs":
                push(args[0], g * np.sign(get(args[0])))
            elif k in ("max", "min"):
                a, b = np.broadcast_arrays(get(args[0]), get(args[1]))
                first = (a >= b) if k == "max" else (a <= b)
                push(args[0], np.where(first, g, 0.0))
                push(args[1], np.where(first, 0.0, g))
            elif k == "cmp":
                push(args[0], np.where(vals[i] >= 1.0, 0.0, g * STEEPNESS))
            elif k == "and":
                stack = np.broadcast_arrays(*(get(a) for a in args))
                open_ = vals[i] < 1.0
                for operand, item in zip(args, stack):
                    push(operand, np.where(open_ & (item <= 0.0), g, 0.0))
            elif k == "or":
                stack = np.broadcast_arrays(*(get(a) for a in args))
                best = np.argmax(stack, axis=0)
                for j, arg in enumerate(args):
                    push(arg, np.where(best == j, g, 0.0))
            elif k == "all":
                a = np.broadcast_to(get(args[0]), (x.shape[0], op.data))
                push(args[0], np.where((vals[i] < 1.0) & (a <= 0.0), g, 0.0))
            elif k == "any":
                a = np.broadcast_to(get(args[0]), (x.shape[0], op.data))
                best = np.argmax(a, axis=1)[:, None] == np.arange(op.data)[None, :]
                push(args[0], np.where(best, g, 0.0))
            elif k == "sum":
                push(args[0], np.broadcast_to(g, (x.shape[0], op.data)))
        return gx


def _unbroadcast(g: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """Sum ``g`` down to ``shape`` (undo numpy broadcasting)."""
    while g.ndim > len(shape):
        g = g.sum(axis=0)
    for axis, n in enumerate(shape):
        if n == 1 and g.shape[axis] != 1:
            g = g.sum(axis=axis, keepdims=True)
    return g
