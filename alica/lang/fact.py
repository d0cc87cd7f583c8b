"""The one fact type every layer shares: a predicate applied to ground arguments.

The world model, the planner, perception and the skills all exchange facts as
:class:`Fact`. It is a named tuple ``(predicate, args)``, so it is immutable,
hashable, ordered and unpacks as ``name, args = fact``; :meth:`Fact.of` takes
the other spellings met at the edges (a flat ``('On', 'a', 'b')`` tuple as the
world model stores it, or a bare name for a 0-ary fact).
"""

from __future__ import annotations

from typing import NamedTuple

#: What a fact's arguments may be: symbols (object names), numbers, or tuples of them (positions).
Arg = object


class Fact(NamedTuple):
    """``predicate(*args)``, e.g. ``Fact('On', ('a', 'b'))``.

    Attributes:
        predicate: the predicate's name.
        args: the ground arguments, in order.
    """

    predicate: str
    args: tuple[Arg, ...] = ()

    @classmethod
    def of(cls, item: Fact | str | tuple[object, ...]) -> Fact:
        """A fact from ``Fact(...)``, a name (0-ary) or a flat tuple ``(predicate, *args)``.

        Raises:
            ValueError: the item has no predicate name first.
        """
        if isinstance(item, Fact):
            return item
        if isinstance(item, str):
            return cls(item, ())
        if not item or not isinstance(item[0], str):
            raise ValueError(f"a fact needs a predicate name first: {item!r}")
        return cls(item[0], tuple(item[1:]))

    @property
    def flat(self) -> tuple[object, ...]:
        """``(predicate, *args)``: the world model's key of the fact."""
        return (self.predicate, *self.args)

    def __str__(self) -> str:
        return f"{self.predicate}({', '.join(str(a) for a in self.args)})" if self.args else self.predicate
