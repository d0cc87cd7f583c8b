"""A simple in-memory belief base of ground facts, function values and objects."""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping

_MISSING = object()


def _key(item: str | tuple[object, ...]) -> tuple[str, tuple[object, ...]]:
    """``'explored'`` or ``('On', 'a', 'g')`` as ``(name, args)``."""
    if isinstance(item, str):
        return item, ()
    if not item or not isinstance(item[0], str):
        raise ValueError(f"a fact needs a name first: {item!r}")
    return item[0], tuple(item[1:])


class FactBase:
    """Ground facts, function values and typed objects, with a closed world.

    A predicate is *known* once a fact of it (with that many arguments) has
    been added or declared; a missing fact of a known predicate looks up as
    ``False``. Names the fact base knows nothing about look up as ``None``,
    which the evaluator reads as a symbol constant or, in a boolean position,
    as false. Facts, arguments and objects are symbols (strings), numbers or
    tuples.

    Args:
        facts: facts as ``('On', 'a', 'g')`` tuples, or a string for a 0-ary
            fact.
        values: function values keyed like facts: ``{('Pos', 'f1'): (0, 1),
            'eps': 0.5}``.
        objects: objects per type name: ``{'Frontier': ['f1', 'f2']}``.
    """

    def __init__(
        self,
        facts: Iterable[str | tuple[object, ...]] = (),
        values: Mapping[str | tuple[object, ...], object] | None = None,
        objects: Mapping[str, Iterable[object]] | None = None,
    ) -> None:
        self._facts: set[tuple[str, tuple[object, ...]]] = set()
        self._known: set[tuple[str, int]] = set()
        self._values: dict[tuple[str, tuple[object, ...]], object] = {}
        self._objects: dict[str, dict[object, None]] = {}
        for fact in facts:
            name, args = _key(fact)
            self.add(name, *args)
        for item, value in (values or {}).items():
            name, args = _key(item)
            self.set(name, *args, value=value)
        for type_name, members in (objects or {}).items():
            for obj in members:
                self.add_object(obj, type_name)

    # -- changes -------------------------------------------------------

    def add(self, pred: str, *args: object) -> None:
        """Make ``pred(*args)`` true."""
        self._facts.add((pred, args))
        self._known.add((pred, len(args)))

    def remove(self, pred: str, *args: object) -> bool:
        """Make ``pred(*args)`` false; returns whether it was true."""
        self._known.add((pred, len(args)))
        try:
            self._facts.remove((pred, args))
        except KeyError:
            return False
        return True

    def declare(self, pred: str, arity: int) -> None:
        """Make a predicate known, so that its missing facts look up as false."""
        self._known.add((pred, arity))

    def set(self, func: str, *args: object, value: object) -> None:
        """Set ``func(*args)`` to ``value`` (``None`` unsets it)."""
        if value is None:
            self._values.pop((func, args), None)
        else:
            self._values[(func, args)] = value

    def unset(self, func: str, *args: object) -> None:
        """Forget the value of ``func(*args)``."""
        self._values.pop((func, args), None)

    def add_object(self, obj: object, type_name: str) -> None:
        """Add ``obj`` to the objects of ``type_name`` (kept in insertion order)."""
        self._objects.setdefault(type_name, {})[obj] = None

    def remove_object(self, obj: object, type_name: str) -> None:
        """Remove ``obj`` from ``type_name``, if present."""
        self._objects.get(type_name, {}).pop(obj, None)

    # -- queries -------------------------------------------------------

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """The value of ``name(*args)``; see the class docstring.

        Args:
            name: predicate or function name.
            args: argument values.

        Returns:
            The function value if set, ``True`` for a present fact, ``False``
            for a missing fact of a known predicate, else ``None``.
        """
        key = (name, args)
        try:
            value = self._values.get(key, _MISSING)
            if value is not _MISSING:
                return value
            if key in self._facts:
                return True
        except TypeError:  # unhashable argument
            return None
        if (name, len(args)) in self._known:
            return False
        return None

    def holds(self, pred: str, *args: object) -> bool:
        """Whether the fact ``pred(*args)`` is present."""
        return (pred, args) in self._facts

    def value(self, func: str, *args: object) -> object | None:
        """The value of ``func(*args)``, or None."""
        return self._values.get((func, args))

    def objects(self, type_name: str) -> tuple[object, ...]:
        """The objects of ``type_name``, in insertion order."""
        return tuple(self._objects.get(type_name, ()))

    def types(self) -> list[str]:
        """Type names with at least one object, sorted."""
        return sorted(name for name, members in self._objects.items() if members)

    def facts(self) -> Iterator[tuple[object, ...]]:
        """Present facts as ``(pred, *args)`` tuples."""
        for name, args in self._facts:
            yield (name, *args)

    def copy(self) -> FactBase:
        """An independent copy."""
        other = FactBase()
        other._facts = set(self._facts)
        other._known = set(self._known)
        other._values = dict(self._values)
        other._objects = {name: dict(members) for name, members in self._objects.items()}
        return other

    def __contains__(self, fact: object) -> bool:
        if isinstance(fact, (str, tuple)):
            try:
                return _key(fact) in self._facts
            except (ValueError, TypeError):
                return False
        return False

    def __repr__(self) -> str:
        sizes = f"{len(self._facts)} facts, {len(self._values)} values, {len(self._objects)} types"
        return f"FactBase({sizes})"
