"""The immutable data replicas exchange: writes, adds, deltas and digests.

A :class:`Delta` is a batch of :class:`Write` (register) and :class:`Add`
(grow-only set and object) entries. The same class carries an incremental
delta, a snapshot of the whole state and the answer to a digest. Entries are
frozen and hold only plain data (see :mod:`alica.worldmodel.encoding`), so
an in-memory network can hand the same objects to every receiver.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from alica.worldmodel.encoding import OrderKey, bucket_hash, canonical, check_name, hash128, order_key
from alica.worldmodel.stamp import Stamp

KeyKind = Literal["register", "set", "object"]
AddKind = Literal["set", "object"]


@dataclass(frozen=True, slots=True)
class Key:
    """Something that changed: a register, a set membership or an object.

    Keys sort (``sorted(keys)``) in the same order in every process.

    Attributes:
        kind: ``"register"`` (a fact or function value), ``"set"`` or
            ``"object"``.
        name: the predicate or function name, the set name or the type name.
        args: the arguments of a register, ``(item,)`` for a set member or
            ``(obj,)`` for an object. For registers and sets ``(name, args)``
            is what :meth:`~alica.worldmodel.WorldModel.lookup` takes.
    """

    kind: KeyKind
    name: str
    args: tuple[object, ...]

    def sort_key(self) -> OrderKey:
        """The sort key used by ``<``."""
        return (self.kind, self.name, order_key(self.args))

    def __lt__(self, other: Key) -> bool:
        return self.sort_key() < other.sort_key()

    def __str__(self) -> str:
        inner = ", ".join(map(repr, self.args))
        return f"{self.kind}:{self.name}({inner})"


@dataclass(frozen=True, slots=True)
class Write:
    """One write of a last-writer-wins register ``name(*args)``.

    Facts are registers holding ``True`` or ``False``; function values hold any
    other plain value; ``None`` is a tombstone (the value was removed).

    Args:
        name: the predicate or function name.
        args: the arguments (plain data, no NaN).
        value: the new value, or ``None`` to remove it.
        stamp: when and by whom.
        expires: the time after which the value is stale (``None``: never),
            on the clock shared by the replicas.

    Raises:
        ValueError: a name, argument, value or ``expires`` is not of the
            documented kind.
        TypeError: ``stamp`` is not a :class:`Stamp`.
    """

    name: str
    args: tuple[object, ...]
    value: object
    stamp: Stamp
    expires: float | None = None
    ident: str = field(init=False, repr=False, compare=False)
    key_hash: int = field(init=False, repr=False, compare=False)
    entry_hash: int = field(init=False, repr=False, compare=False)
    key: Key = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        name = check_name(self.name, "a register name")
        if type(self.args) is not tuple:
            raise ValueError(f"the arguments of {name} must be a tuple, got {self.args!r}")
        try:
            args, args_text = canonical(self.args, key=True)
        except ValueError as exc:
            raise ValueError(f"an argument of {name} is {exc}") from None
        try:
            value, value_text = canonical(self.value)
        except ValueError as exc:
            raise ValueError(f"the value of {name} is {exc}") from None
        stamp = self.stamp
        if type(stamp) is not Stamp:
            raise TypeError(f"the stamp of a write to {name} must be a Stamp, got {stamp!r}")
        expires = self.expires
        if expires is not None:
            if type(expires) not in (int, float) or math.isnan(expires):
                raise ValueError(f"expires of {name} must be a time in seconds or None, got {expires!r}")
            expires = float(expires)
        ident = f"rs{len(name)}:{name}{args_text}"
        text = f"{ident}|{value_text}|{stamp.counter}|{len(stamp.writer)}:{stamp.writer}|{expires!r}"
        setattr_ = object.__setattr__
        setattr_(self, "args", args)
        setattr_(self, "value", value)
        setattr_(self, "expires", expires)
        setattr_(self, "ident", ident)
        setattr_(self, "key_hash", bucket_hash(ident))
        setattr_(self, "entry_hash", hash128(text))
        setattr_(self, "key", Key("register", name, args))  # type: ignore[arg-type]


@dataclass(frozen=True, slots=True)
class Add:
    """One add to a grow-only set (``kind="set"``) or of a typed object (``kind="object"``).

    When several agents add the same item, every replica keeps the add with
    the smallest stamp, so the stored state is the same everywhere.

    Args:
        kind: ``"set"`` or ``"object"``.
        name: the set name, or the type name of an object.
        item: the member or object (plain data, no NaN).
        stamp: when and by whom.

    Raises:
        ValueError: the kind, name or item is not of the documented kind.
        TypeError: ``stamp`` is not a :class:`Stamp`.
    """

    kind: AddKind
    name: str
    item: object
    stamp: Stamp
    ident: str = field(init=False, repr=False, compare=False)
    key_hash: int = field(init=False, repr=False, compare=False)
    entry_hash: int = field(init=False, repr=False, compare=False)
    key: Key = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        kind = self.kind
        if kind != "set" and kind != "object":
            raise ValueError(f"an add is to a 'set' or an 'object' type, got kind {kind!r}")
        name = check_name(self.name, "a set name" if kind == "set" else "a type name")
        try:
            item, item_text = canonical(self.item, key=True)
        except ValueError as exc:
            raise ValueError(f"an item of {name} is {exc}") from None
        stamp = self.stamp
        if type(stamp) is not Stamp:
            raise TypeError(f"the stamp of an add to {name} must be a Stamp, got {stamp!r}")
        ident = f"{kind[0]}s{len(name)}:{name}{item_text}"
        text = f"{ident}|{stamp.counter}|{len(stamp.writer)}:{stamp.writer}"
        setattr_ = object.__setattr__
        setattr_(self, "item", item)
        setattr_(self, "ident", ident)
        setattr_(self, "key_hash", bucket_hash(ident))
        setattr_(self, "entry_hash", hash128(text))
        setattr_(self, "key", Key(kind, name, (item,)))


Entry = Write | Add


@dataclass(frozen=True, slots=True)
class Delta:
    """A batch of entries: an incremental delta, a snapshot, or a reply to a digest.

    Merging a delta is idempotent, commutative and associative, so deltas may
    be delivered late, twice, or in any order. Entries are sorted by their
    canonical identity text, so equal states give equal deltas.

    Args:
        writes: register writes.
        adds: set and object adds.

    Raises:
        TypeError: an entry is not a :class:`Write` (in ``writes``) or an
            :class:`Add` (in ``adds``).
    """

    writes: tuple[Write, ...] = ()
    adds: tuple[Add, ...] = ()

    def __post_init__(self) -> None:
        if type(self.writes) is not tuple:
            object.__setattr__(self, "writes", tuple(self.writes))
        if type(self.adds) is not tuple:
            object.__setattr__(self, "adds", tuple(self.adds))
        for write in self.writes:
            if type(write) is not Write:
                raise TypeError(f"Delta.writes holds Write entries only, got {write!r}")
        for add in self.adds:
            if type(add) is not Add:
                raise TypeError(f"Delta.adds holds Add entries only, got {add!r}")

    @classmethod
    def of(cls, entries: list[Entry]) -> Delta:
        """A delta of ``entries`` in canonical order.

        Args:
            entries: writes and adds, in any order.

        Returns:
            The delta.
        """
        ordered = sorted(entries, key=_ident)
        return cls(
            tuple(entry for entry in ordered if type(entry) is Write),
            tuple(entry for entry in ordered if type(entry) is Add),
        )

    def __len__(self) -> int:
        return len(self.writes) + len(self.adds)

    def max_counter(self) -> int:
        """The largest Lamport counter in the delta (0 when empty)."""
        counters = [entry.stamp.counter for entry in self.writes] + [entry.stamp.counter for entry in self.adds]
        return max(counters, default=0)

    def sorted_keys(self) -> list[Key]:
        """The keys of the entries, sorted."""
        return sorted([entry.key for entry in self.writes] + [entry.key for entry in self.adds])


def _ident(entry: Entry) -> str:
    return entry.ident


@dataclass(frozen=True, slots=True)
class Digest:
    """A small summary of a replica's state, to compare replicas cheaply.

    Attributes:
        state_hash: a 128-bit hash of the whole state (XOR of the entry
            hashes); equal states have equal hashes.
        buckets: the same hash per bucket of keys; a peer answers
            :meth:`~alica.worldmodel.WorldModel.missing_for` with every entry
            in a bucket whose hash differs.
        clock: ``(writer, largest counter seen from that writer)`` pairs,
            sorted by writer. Informative only: with lost deltas a replica can
            have seen a writer's counter 9 and still lack its write 5, so it
            is never used to decide what a peer has.
        size: the number of stored entries (tombstones included).
    """

    state_hash: int
    buckets: tuple[int, ...]
    clock: tuple[tuple[str, int], ...]
    size: int

    def same_state(self, other: Digest) -> bool:
        """Whether the other digest describes the same state (up to hash collisions)."""
        return self.state_hash == other.state_hash and self.size == other.size
