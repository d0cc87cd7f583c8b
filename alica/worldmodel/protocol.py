"""The world model as the layers above the runtime see it: a typed Protocol.

Skills, perception and the planning runtime read and write an agent's world
model through :class:`WorldModelLike`; :class:`~alica.worldmodel.WorldModel`
satisfies it (and so may a test double or a real robot's store). Facts come
out as :class:`~alica.lang.fact.Fact`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

from alica.lang.fact import Fact
from alica.worldmodel.delta import Delta, Key
from alica.worldmodel.stamp import Stamp

__all__ = ["ReplicaLike", "WorldModelLike"]


@runtime_checkable
class WorldModelLike(Protocol):
    """What the skills, perception and the planner use of an agent's world model."""

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """A register's value, set membership, ``False`` for a missing fact of a known predicate, else None."""
        ...

    def get(self, name: str, *args: object, default: object = None) -> object:
        """The live value of ``name(*args)``, or ``default``."""
        ...

    def holds(self, pred: str, *args: object) -> bool:
        """Whether ``pred(*args)`` is true."""
        ...

    def set(self, name: str, *args: object, value: object, ttl: float | None = None) -> Stamp:
        """Write ``name(*args) = value``."""
        ...

    def assert_fact(self, pred: str, *args: object) -> Stamp:
        """Make ``pred(*args)`` true."""
        ...

    def retract_fact(self, pred: str, *args: object) -> Stamp:
        """Make ``pred(*args)`` false."""
        ...

    def add_to_set(self, name: str, item: object) -> bool:
        """Add ``item`` to the set ``name``; whether it is new."""
        ...

    def add_object(self, obj: object, type_name: str) -> bool:
        """Make ``obj`` an object of ``type_name`` (for quantifiers); whether it is new."""
        ...

    def on_change(self, callback: Callable[[frozenset[Key]], None]) -> Callable[[], None]:
        """Call ``callback(changed_keys)`` after every write or merge that changes something; returns the unsubscriber."""
        ...

    def refresh(self) -> frozenset[Key]:
        """Drop values whose time to live ran out (once per engine tick); the registers that went stale."""
        ...

    def members(self, name: str) -> frozenset[object]:
        """The members of the set ``name``."""
        ...

    def objects(self, type_name: str) -> tuple[object, ...]:
        """The objects of ``type_name`` in a stable order."""
        ...

    def types(self) -> list[str]:
        """Type names with at least one object, sorted."""
        ...

    def facts(self) -> list[Fact]:
        """True facts and set memberships, sorted."""
        ...

    def values(self) -> list[tuple[str, tuple[object, ...], object]]:
        """Live function values (not truth values) as ``(name, args, value)``, sorted."""
        ...


@runtime_checkable
class ReplicaLike(WorldModelLike, Protocol):
    """A world model the engine replicates over the team: what it publishes and what it merges."""

    def take_delta(self) -> Delta | None:
        """What changed here since the last call (``None``: nothing)."""
        ...

    def snapshot(self) -> Delta:
        """Everything this replica holds, for a teammate that joins or missed deltas."""
        ...

    def merge(self, delta: Delta) -> frozenset[Key]:
        """Merge a delta or snapshot from any replica; the keys that changed."""
        ...
