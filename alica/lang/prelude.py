"""Built-in functions and the IMPERA distance predicates.

``MaximalDist(a, b, d)`` and ``MinimalDist(a, b, d)`` follow Eq. 3-4 of the
IMPERA paper: with ``p1 = Pos(a)`` and ``p2 = Pos(b)`` read from the belief
base function ``Pos``, ``MaximalDist`` holds iff the Euclidean distance of
``p1`` and ``p2`` is greater than ``d`` and ``MinimalDist`` iff it is smaller.
Both are false when either position is unknown. An argument that is a point
itself (a pair ``(x, y)``, a mapping or an object with ``x``, ``y``; a solved
point variable, say) is taken as its own position; ``dist`` and ``closeness``
take object names (through ``Pos``) as well as points. Where ``Pos`` has no
value, the skills' own ``pos`` (what navigation, the arm skills and the blocks
world's perception write) is read. The paper's Eq. 1 spreads
frontier points apart with
``forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2``.
"""

from __future__ import annotations

import builtins
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from alica.lang.belief import BeliefBase
from alica.lang.registry import Registry


def coordinates(point: object) -> tuple[float, ...]:
    """The coordinates of a point.

    Args:
        point: a sequence of numbers, a mapping with keys ``'x'``, ``'y'``
            (and optionally ``'z'``), or an object with attributes ``x``,
            ``y`` (and optionally ``z``).

    Returns:
        The coordinates as floats.

    Raises:
        TypeError: when ``point`` is none of these.
    """
    if isinstance(point, Mapping):
        keys = ("x", "y", "z") if "z" in point else ("x", "y")
        return tuple(float(point[key]) for key in keys)
    if isinstance(point, Sequence) and not isinstance(point, str):
        return tuple(float(value) for value in point)
    if hasattr(point, "x") and hasattr(point, "y"):
        values = [point.x, point.y]
        if getattr(point, "z", None) is not None:
            values.append(point.z)  # type: ignore[attr-defined]
        return tuple(float(value) for value in values)
    raise TypeError(f"{point!r} is not a point (use a sequence, a mapping or an object with x, y)")


def dist(p: object, q: object) -> float:
    """Euclidean distance of two points; a missing coordinate counts as 0."""
    a, b = coordinates(p), coordinates(q)
    size = max(len(a), len(b))
    a += (0.0,) * (size - len(a))
    b += (0.0,) * (size - len(b))
    return math.dist(a, b)


def is_point(value: object) -> bool:
    """Whether ``value`` is a point (not an object name): numbers in a sequence, a mapping or x/y attributes."""
    if isinstance(value, (str, bytes)):
        return False
    if isinstance(value, Sequence):
        return len(value) in (2, 3) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    if isinstance(value, Mapping):
        return "x" in value and "y" in value
    return hasattr(value, "x") and hasattr(value, "y")


def position(belief: BeliefBase, a: object) -> object | None:
    """Where ``a`` is: ``a`` itself when it is a point, else ``Pos(a)`` or, without it, ``pos(a)`` (None when unknown)."""
    if is_point(a):
        return a
    if a is None:
        return None
    found = belief.lookup("Pos", (a,))
    return found if found is not None else belief.lookup("pos", (a,))


def _position_distance(belief: BeliefBase, a: object, b: object) -> float | None:
    p1 = position(belief, a)
    p2 = position(belief, b)
    if p1 is None or p2 is None:
        return None
    return dist(p1, p2)


def place_dist(belief: BeliefBase, a: object, b: object) -> float:
    """``dist`` of the formula language: points, or objects placed by ``Pos``."""
    distance = _position_distance(belief, a, b)
    if distance is None:
        unknown = a if position(belief, a) is None else b
        raise ValueError(f"{unknown!r} is neither a point nor an object with a known Pos")
    return distance


def closeness(belief: BeliefBase, a: object, b: object) -> float:
    """``1 / (1 + dist(a, b))``: 1 where ``a`` and ``b`` are at the same place, towards 0 farther apart.

    0 when either position is unknown, so that a utility summand built on it
    stays defined (and in [0, 1]) before perception has placed everything.
    """
    distance = _position_distance(belief, a, b)
    return 0.0 if distance is None else 1.0 / (1.0 + distance)


def choose(key: object, *cases: object) -> object:
    """``choose(k, k1, v1, k2, v2, ..., default)``: the ``v`` of the first ``k_i`` equal to ``k``, else ``default``.

    Raises:
        ValueError: no default (an odd number of arguments after ``key``).
    """
    if len(cases) % 2 == 0:
        raise ValueError(
            f"choose takes a key, pairs of case and value, and a default; got {len(cases) + 1} arguments (add a default)"
        )
    for i in range(0, len(cases) - 1, 2):
        if cases[i] == key:
            return cases[i + 1]
    return cases[-1]


def maximal_dist(belief: BeliefBase, a: object, b: object, d: float) -> bool:
    """IMPERA Eq. 3: ``Pos(a)`` and ``Pos(b)`` are farther apart than ``d``."""
    distance = _position_distance(belief, a, b)
    return distance is not None and distance > d


def minimal_dist(belief: BeliefBase, a: object, b: object, d: float) -> bool:
    """IMPERA Eq. 4: ``Pos(a)`` and ``Pos(b)`` are closer than ``d``."""
    distance = _position_distance(belief, a, b)
    return distance is not None and distance < d


def _extreme(pick: Callable[[Iterable[Any]], object], args: tuple[object, ...]) -> object:
    values: Iterable[Any] = args
    if len(args) == 1 and isinstance(args[0], Iterable) and not isinstance(args[0], str):
        values = args[0]
    return pick(values)


def _min(*args: object) -> object:
    """Smallest argument, or smallest item of one iterable argument."""
    return _extreme(builtins.min, args)


def _max(*args: object) -> object:
    """Largest argument, or largest item of one iterable argument."""
    return _extreme(builtins.max, args)


def _round(value: float, digits: int | None = None) -> float:
    """Round to ``digits`` decimals (to an integer when omitted)."""
    return builtins.round(value, digits) if digits is not None else builtins.round(value)


def having(belief: BeliefBase, type_name: object, fluent: object) -> list[object]:
    """The objects of a type for which the unary function or predicate ``fluent`` has a value, sorted by name.

    A world model's object sets only grow; what was retracted loses its
    values. ``having(Frontier, gain)`` lists the frontiers that are frontiers
    now, as a variable's ``candidates`` or in a condition.
    """
    name = str(fluent)
    found = []
    for obj in belief.objects(str(type_name)):
        value = belief.lookup(name, (obj,))
        if value is not None and value is not False:  # a gain of 0.0 is a value
            found.append(obj)
    return sorted(found, key=str)


def count(belief: BeliefBase, type_name: object, fluent: object | None = None) -> int:
    """Number of objects of a type in the belief base; with ``fluent``, of those for which it has a value."""
    if fluent is not None:
        return len(having(belief, type_name, fluent))
    return sum(1 for _ in belief.objects(str(type_name)))


def default_registry() -> Registry:
    """A fresh registry holding the built-in functions and predicates.

    Returns:
        A registry with ``sqrt``, ``abs``, ``min``, ``max``, ``dist``,
        ``closeness``, ``choose``, ``floor``, ``ceil``, ``round``, ``count``, ``having``, ``MaximalDist`` and
        ``MinimalDist``; callers may add to it freely.
    """
    registry = Registry()
    fn = "function"
    registry.register("sqrt", math.sqrt, 1, kind=fn, doc="square root")
    registry.register("abs", builtins.abs, 1, kind=fn, doc="absolute value")
    registry.register("min", _min, (1, None), kind=fn, doc=_min.__doc__ or "")
    registry.register("max", _max, (1, None), kind=fn, doc=_max.__doc__ or "")
    registry.register(
        "dist", place_dist, 2, kind=fn, needs_belief=True, doc="Euclidean distance of two points (or objects' Pos)"
    )
    registry.register(
        "closeness",
        closeness,
        2,
        kind=fn,
        needs_belief=True,
        doc="closeness(a, b): 1 / (1 + dist(a, b)), 0 when a position is unknown",
    )
    registry.register(
        "choose", choose, (2, None), kind=fn, doc="choose(k, k1, v1, ..., default): the v of the first k_i equal to k"
    )
    registry.register("floor", math.floor, 1, kind=fn, doc="largest integer <= x")
    registry.register("ceil", math.ceil, 1, kind=fn, doc="smallest integer >= x")
    registry.register("round", _round, (1, 2), kind=fn, doc=_round.__doc__ or "")
    registry.register(
        "count",
        count,
        (1, 2),
        kind=fn,
        needs_belief=True,
        doc="count(Type): objects of a type; count(Type, f): those for which f(o) has a value",
    )
    registry.register(
        "having",
        having,
        2,
        kind=fn,
        needs_belief=True,
        doc="having(Type, f): the objects of a type for which f(o) has a value, sorted",
    )
    registry.register(
        "MaximalDist",
        maximal_dist,
        3,
        needs_belief=True,
        doc="MaximalDist(a, b, d): distance of Pos(a) and Pos(b) is greater than d",
    )
    registry.register(
        "MinimalDist",
        minimal_dist,
        3,
        needs_belief=True,
        doc="MinimalDist(a, b, d): distance of Pos(a) and Pos(b) is less than d",
    )
    return registry
