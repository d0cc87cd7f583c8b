"""The interface formulas are evaluated against."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Protocol, runtime_checkable


@runtime_checkable
class BeliefBase(Protocol):
    """What an agent believes: facts, function values and typed objects.

    Implementations must return ``None`` from :meth:`lookup` for names they
    know nothing about: the evaluator then reads an identifier as a symbol
    constant (``a`` in ``On(a, g)`` is the string ``'a'``) and, in a boolean
    position, treats the unknown fact as false (closed world).
    """

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """The value of a fact or function application.

        Args:
            name: predicate or function name.
            args: evaluated arguments.

        Returns:
            ``True``/``False`` for a predicate, the value for a function, or
            ``None`` when unknown.
        """
        ...

    def objects(self, type_name: str) -> Iterable[object]:
        """All objects of a type, for quantifiers (empty when none)."""
        ...
