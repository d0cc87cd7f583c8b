"""The shared WorldModel: one agent's replica of the team's facts.

In IMPERA every robot keeps a local copy of a shared world model (robot
positions, map information, found drill samples, invalid sample candidates)
and merges what its teammates send. :class:`WorldModel` is that copy, built
as a state-based CRDT (see :mod:`alica.worldmodel.state`): replicas that have
merged the same writes, in any order and any number of times, hold the same
state. It knows nothing about the network; a transport moves the
:class:`~alica.worldmodel.Delta` values it hands out.
"""

from __future__ import annotations

import json

from alica.clock import Clock
from alica.lang.fact import Fact
from alica.worldmodel import listing
from alica.worldmodel.delta import Add, Write
from alica.worldmodel.encoding import order_key
from alica.worldmodel.replica import Replica
from alica.worldmodel.stamp import Stamp

_MISSING = object()


class WorldModel(Replica):
    """A replicated store of facts, function values, sets and typed objects.

    * **Registers** ``name(*args)`` are last-writer-wins: :meth:`set` for
      function values, :meth:`assert_fact` / :meth:`retract_fact` for facts
      (registers holding ``True``/``False``). Removing a value writes a
      tombstone.
    * **Sets** (:meth:`add_to_set`) and **objects** (:meth:`add_object`) only
      grow.
    * It is a :class:`~alica.lang.BeliefBase`: :meth:`lookup` answers a
      register's value, set membership for ``lookup(set_name, (item,))``,
      ``False`` for a missing fact of a known predicate and ``None`` for names
      it knows nothing about. A predicate is known while any register of that
      name and arity holds ``True`` or ``False`` (so retract a fact rather than
      :meth:`unset` it to keep it known); a set is known once it has a member.
      Registers are looked up before sets.

    Args:
        agent_id: the id of the agent owning this replica; unique in the team,
            it breaks ties between writes with equal counters.
        clock: the time source for ``ttl``; replicas must share its time base
            (simulated time). Without it ``ttl`` is refused and values from
            peers never expire.
        buckets: how many key buckets a digest has; all replicas of a team
            must use the same number (else :meth:`missing_for` sends
            everything).
        relay: whether :meth:`take_delta` also hands out entries merged from
            peers that were new here (gossip). Turn off when every agent hears
            every other directly.

    Replication (:meth:`take_delta`, :meth:`merge`, :meth:`snapshot`,
    :meth:`digest`, :meth:`missing_for`, :meth:`on_change`, :meth:`refresh`)
    comes from :class:`~alica.worldmodel.replica.Replica`.

    Raises:
        ValueError: ``agent_id`` is not a non-empty string or ``buckets`` is
            not a positive int.
    """

    def __init__(self, agent_id: str, *, clock: Clock | None = None, buckets: int = 64, relay: bool = True) -> None:
        super().__init__(agent_id, clock=clock, buckets=buckets, relay=relay)
        self._live = self._state.live
        self._sets = self._state.sets
        self._bools = self._state.bool_arity
        self._objects_cache: dict[str, tuple[object, ...]] = {}
        self._members_cache: dict[str, frozenset[object]] = {}

    # -- local writes ------------------------------------------------------

    def set(self, name: str, *args: object, value: object, ttl: float | None = None) -> Stamp:
        """Write ``name(*args) = value``; ``value=None`` removes it (a tombstone).

        Args:
            name: the function name, e.g. ``"pos"``.
            *args: its arguments, e.g. ``"scout"``.
            value: plain data (str, int, float, bool, None, tuples).
            ttl: seconds after which the value is stale and looks up as
                missing; needs a ``clock``.

        Returns:
            The stamp of the write.

        Raises:
            ValueError: a name, argument or value is not plain data, or
                ``ttl`` is not a positive number or there is no clock.
        """
        expires = None if ttl is None else self._expires(name, ttl)
        return self._write(Write(name, args, value, self._lamport.peek(), expires))

    def unset(self, name: str, *args: object) -> Stamp:
        """Remove the value of ``name(*args)`` by writing a tombstone.

        Returns:
            The stamp of the write.

        Raises:
            ValueError: a name or argument is not plain data.
        """
        return self._write(Write(name, args, None, self._lamport.peek()))

    def assert_fact(self, pred: str, *args: object) -> Stamp:
        """Make the fact ``pred(*args)`` true.

        Returns:
            The stamp of the write.

        Raises:
            ValueError: a name or argument is not plain data.
        """
        return self._write(Write(pred, args, True, self._lamport.peek()))

    def retract_fact(self, pred: str, *args: object) -> Stamp:
        """Make the fact ``pred(*args)`` false (the predicate stays known).

        Returns:
            The stamp of the write.

        Raises:
            ValueError: a name or argument is not plain data.
        """
        return self._write(Write(pred, args, False, self._lamport.peek()))

    def add_to_set(self, name: str, item: object) -> bool:
        """Add ``item`` to the grow-only set ``name``.

        Returns:
            Whether the item is new here (adding a present item writes nothing).

        Raises:
            ValueError: the name or item is not plain data.
        """
        return self._add(Add("set", name, item, self._lamport.peek()))

    def add_object(self, obj: object, type_name: str) -> bool:
        """Add ``obj`` to the objects of ``type_name`` (grow-only).

        Returns:
            Whether the object is new here.

        Raises:
            ValueError: the type name or object is not plain data.
        """
        return self._add(Add("object", type_name, obj, self._lamport.peek()))

    # -- reads -------------------------------------------------------------

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """The value of ``name(*args)`` for formula evaluation (hot path).

        Args:
            name: predicate, function or set name.
            args: argument values.

        Returns:
            A register's live value; for a set name with one argument whether
            it is a member; ``False`` for a missing fact of a known predicate;
            else ``None``.
        """
        try:
            value = self._live.get((name, args), _MISSING)
        except TypeError:  # an unhashable argument is never stored
            return None
        if value is not _MISSING:
            return value
        if len(args) == 1:
            members = self._sets.get(name)
            if members is not None:
                return args[0] in members  # hashable: the register lookup above hashed it
        if (name, len(args)) in self._bools:
            return False
        return None

    def get(self, name: str, *args: object, default: object = None) -> object:
        """The live value of ``name(*args)``, or ``default`` (missing, removed or stale)."""
        try:
            return self._live.get((name, args), default)
        except TypeError:
            return default

    def holds(self, pred: str, *args: object) -> bool:
        """Whether ``pred(*args)`` is true (a true fact or a set member)."""
        return self.lookup(pred, args) is True

    def stamp_of(self, name: str, *args: object) -> Stamp | None:
        """The stamp of the stored write to ``name(*args)`` (tombstones too), or None."""
        write = self._state.registers.get((name, args))
        return None if write is None else write.stamp

    def members(self, name: str) -> frozenset[object]:
        """The members of the set ``name`` (empty when it has none)."""
        cached = self._members_cache.get(name)
        if cached is None:
            cached = frozenset(self._sets.get(name, ()))
            self._members_cache[name] = cached
        return cached

    def objects(self, type_name: str) -> tuple[object, ...]:
        """The objects of ``type_name`` in a stable order, the same on every replica.

        Sorted by :func:`~alica.worldmodel.encoding.order_key` (None, booleans,
        numbers, strings, then tuples), cached until the type changes.
        """
        cached = self._objects_cache.get(type_name)
        if cached is None:
            cached = tuple(sorted(self._state.objects.get(type_name, ()), key=order_key))
            self._objects_cache[type_name] = cached
        return cached

    def types(self) -> list[str]:
        """Type names with at least one object, sorted."""
        return sorted(self._state.objects)

    def set_names(self) -> list[str]:
        """Names of sets with at least one member, sorted."""
        return sorted(self._sets)

    # -- listings ----------------------------------------------------------

    def facts(self) -> list[Fact]:
        """True facts and set memberships (``Fact(set_name, (item,))``) as :class:`~alica.lang.fact.Fact`, sorted."""
        return listing.facts(self._state)

    def values(self) -> list[tuple[str, tuple[object, ...], object]]:
        """Live function values (not truth values) as ``(name, args, value)``, sorted."""
        return listing.values(self._state)

    def to_json(self) -> dict[str, list[dict[str, object]]]:
        """The replicated state (stamps and tombstones included) as JSON data.

        Equal states give equal dumps on every replica and in every process;
        the owner's id and counter are not part of it.
        """
        return listing.to_json(self._state)

    def dumps(self) -> str:
        """:meth:`to_json` as compact JSON text with sorted keys (byte-identical for equal states)."""
        return json.dumps(self.to_json(), sort_keys=True, separators=(",", ":"))

    def __repr__(self) -> str:
        state = self._state
        return (
            f"WorldModel({self.agent_id!r}, {len(state.registers)} registers, {len(state.sets)} sets, "
            f"{len(state.objects)} types, counter {self.counter})"
        )

    # -- internals ---------------------------------------------------------

    def _write(self, write: Write) -> Stamp:
        self._commit(write)
        return write.stamp

    def _add(self, add: Add) -> bool:
        table = (self._sets if add.kind == "set" else self._state.objects).get(add.name)
        if table is not None and add.item in table:
            return False
        self._commit(add)
        return True

    def _membership_changed(self, add: Add) -> None:
        if add.kind == "set":
            self._members_cache.pop(add.name, None)
        else:
            self._objects_cache.pop(add.name, None)
