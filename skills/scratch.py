"""Typed slots of an agent's scratch space: what one skill of a pipeline hands to the next.

The scratch space (:attr:`alica.skills.context.SkillContextLike.scratch`) is
a plain ``dict[str, object]``. A :class:`ScratchSlot` names one key of it
together with the type stored there and the skill that writes it, so the
writer :meth:`~ScratchSlot.put` s a value and the reader :meth:`~ScratchSlot.get` s
it back as that type: a type checker sees the contract between the steps,
and a reader whose writer did not run (or wrote something else) gets a
message that names the step to run first.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, MutableMapping
from typing import Generic, TypeVar

from alica.errors import SkillError

__all__ = ["ScratchSlot"]

T = TypeVar("T")


class ScratchSlot(Generic[T]):
    """One key of the scratch space, the type of its value and the skill that writes it.

    Args:
        key: the key in the scratch space.
        kind: the class of the value (checked with ``isinstance`` on every read and write).
        producer: the skill (or skills) that writes it, named in the messages.
    """

    __slots__ = ("key", "kind", "producer")

    def __init__(self, key: str, kind: type[T], producer: str) -> None:
        self.key = key
        self.kind = kind
        self.producer = producer

    def __repr__(self) -> str:
        return f"<ScratchSlot {self.key!r}: {self.kind.__name__}>"

    def put(self, scratch: MutableMapping[str, object], value: T) -> None:
        """Store ``value`` under the slot's key.

        Raises:
            TypeError: ``value`` is not of the slot's type (a programming error of the writer).
        """
        if not isinstance(value, self.kind):
            raise TypeError(f"scratch[{self.key!r}] takes a {self.kind.__name__}, not a {type(value).__name__}")
        scratch[self.key] = value

    def get(self, scratch: Mapping[str, object]) -> T | None:
        """The value stored under the slot's key, or None when nothing is.

        Raises:
            SkillError: the key holds something else than the slot's type.
        """
        value = scratch.get(self.key)
        if value is None:
            return None
        if not isinstance(value, self.kind):
            raise SkillError(
                f"scratch[{self.key!r}] holds a {type(value).__name__}, not the {self.kind.__name__} "
                f"{self.producer} writes there"
            )
        return value

    def require(self, scratch: Mapping[str, object], reader: str) -> T:
        """The value stored under the slot's key.

        Raises:
            SkillError: nothing is stored there (naming the step to run first), or something of another type.
        """
        value = self.get(scratch)
        if value is None:
            raise SkillError(f"{reader}: no {self.kind.__name__} in scratch[{self.key!r}]: run {self.producer} first")
        return value

    def setdefault(self, scratch: MutableMapping[str, object], factory: Callable[[], T]) -> T:
        """The value stored under the slot's key, after storing ``factory()`` there when nothing was."""
        value = self.get(scratch)
        if value is None:
            value = factory()
            self.put(scratch, value)
        return value
