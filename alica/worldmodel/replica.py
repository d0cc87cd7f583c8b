"""One agent's replica: Lamport stamps, pending deltas, merging and subscribers.

:class:`Replica` is the part of a :class:`~alica.worldmodel.WorldModel`
that a transport talks to. It knows nothing about the network: it hands out
:class:`~alica.worldmodel.Delta` values (:meth:`Replica.take_delta`,
:meth:`Replica.snapshot`, :meth:`Replica.missing_for`) and merges the ones it
is given, in any order, any number of times.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from alica.clock import Clock
from alica.worldmodel.delta import Add, Delta, Digest, Entry, Key, Write
from alica.worldmodel.encoding import check_name
from alica.worldmodel.stamp import LamportClock
from alica.worldmodel.state import ReplicaState

Listener = Callable[[frozenset[Key]], None]


class Replica:
    """The replicated state of one agent and its exchange with peers.

    Args:
        agent_id: the id of the agent owning this replica; unique in the team,
            it breaks ties between writes with equal counters.
        clock: the time source for ``ttl``; replicas must share its time base
            (simulated time). Without it values never expire.
        buckets: how many key buckets a digest has; all replicas of a team
            must use the same number (else :meth:`missing_for` sends
            everything).
        relay: whether :meth:`take_delta` also hands out entries merged from
            peers that were new here (gossip). Turn off when every agent hears
            every other directly.

    Raises:
        ValueError: ``agent_id`` is not a non-empty string or ``buckets`` is
            not a positive int.
    """

    def __init__(self, agent_id: str, *, clock: Clock | None = None, buckets: int = 64, relay: bool = True) -> None:
        self._lamport = LamportClock(agent_id)
        self._time = clock
        self._relay = relay
        self._state = ReplicaState(buckets)
        self._pending: dict[tuple[str, str, object], Entry] = {}
        self._listeners: list[Listener] = []
        self._snapshot: tuple[int, Delta] | None = None

    @property
    def agent_id(self) -> str:
        """The id of the agent owning this replica."""
        return self._lamport.writer

    @property
    def counter(self) -> int:
        """The Lamport counter: the largest counter written or merged so far."""
        return self._lamport.counter

    def take_delta(self) -> Delta | None:
        """What changed here since the last call, to publish on a reliable channel.

        Returns:
            Local writes and (with ``relay``) entries merged from peers that
            were new here, latest entry per key; ``None`` when nothing changed.
        """
        if not self._pending:
            return None
        delta = Delta.of(list(self._pending.values()))
        self._pending.clear()
        return delta

    def merge(self, delta: Delta) -> frozenset[Key]:
        """Merge a delta or snapshot from any replica (idempotent, commutative, associative).

        Args:
            delta: from :meth:`take_delta`, :meth:`snapshot` or
                :meth:`missing_for` of any replica.

        Returns:
            The keys whose stored entry changed (listeners are told too).

        Raises:
            TypeError: ``delta`` is not a :class:`~alica.worldmodel.Delta`.
        """
        if not isinstance(delta, Delta):
            raise TypeError(
                f"merge takes a Delta (from take_delta, snapshot or missing_for), got {type(delta).__name__}"
            )
        changed = set(self._expire())
        state = self._state
        now = None if self._time is None else self._time.now()
        relay = self._pending if self._relay else None
        top = 0
        for write in delta.writes:
            top = max(top, write.stamp.counter)
            if state.put_write(write, now):
                changed.add(write.key)
                if relay is not None:
                    relay[("register", write.name, write.args)] = write
        for add in delta.adds:
            top = max(top, add.stamp.counter)
            if state.put_add(add)[0]:
                changed.add(add.key)
                self._membership_changed(add)
                if relay is not None:
                    relay[(add.kind, add.name, add.item)] = add
        self._lamport.observe(top)
        result = frozenset(changed)
        if result:
            self._notify(result)
        return result

    def snapshot(self) -> Delta:
        """The whole state, for a peer that (re)joins or after a partition heals."""
        version = self._state.version
        if self._snapshot is None or self._snapshot[0] != version:
            self._snapshot = (version, self._state.snapshot())
        return self._snapshot[1]

    def digest(self) -> Digest:
        """A small summary to compare with a peer's; see :class:`~alica.worldmodel.Digest`."""
        return self._state.digest()

    def missing_for(self, digest: Digest) -> Delta:
        """What a peer whose digest is ``digest`` may lack (never less than it lacks).

        Args:
            digest: the peer's :meth:`digest`.

        Returns:
            Every entry in a key bucket whose hash differs from the peer's
            (empty when the states are equal).

        Raises:
            TypeError: ``digest`` is not a :class:`~alica.worldmodel.Digest`.
        """
        return self._state.missing_for(digest)

    def on_change(self, callback: Listener) -> Callable[[], None]:
        """Call ``callback(changed_keys)`` after every local write or merge that changes something.

        The state is already updated when the callback runs; an exception it
        raises propagates to the writer or merger.

        Args:
            callback: receives a frozenset of :class:`~alica.worldmodel.Key`.

        Returns:
            A function that unsubscribes the callback.
        """
        self._listeners.append(callback)

        def unsubscribe() -> None:
            if callback in self._listeners:
                self._listeners.remove(callback)

        return unsubscribe

    def refresh(self) -> frozenset[Key]:
        """Drop values whose ``ttl`` ran out; call once per engine tick.

        Expired values also go at the next write or merge; reads never look
        at the clock.

        Returns:
            The registers that went stale (listeners are told too).
        """
        changed = frozenset(self._expire())
        if changed:
            self._notify(changed)
        return changed

    # -- for subclasses ----------------------------------------------------

    def _commit(self, entry: Write | Add) -> None:
        """Apply a local write or add stamped with ``self._lamport.peek()``."""
        changed = set(self._expire())
        self._lamport.observe(entry.stamp.counter)
        if type(entry) is Write:
            self._state.put_write(entry, None if self._time is None else self._time.now())
            self._pending[("register", entry.name, entry.args)] = entry
        else:
            self._state.put_add(entry)  # type: ignore[arg-type]
            self._membership_changed(entry)  # type: ignore[arg-type]
            self._pending[(entry.kind, entry.name, entry.item)] = entry  # type: ignore[union-attr]
        changed.add(entry.key)
        self._notify(frozenset(changed))

    def _expires(self, name: str, ttl: float) -> float:
        """The absolute time at which a value written now with ``ttl`` goes stale.

        Raises:
            ValueError: there is no clock, or ``ttl`` is not a positive number.
        """
        check_name(name, "a register name")
        if self._time is None:
            raise ValueError(f"ttl on {name} needs a clock: create the WorldModel with clock=ManualClock() or similar")
        if isinstance(ttl, bool) or not isinstance(ttl, (int, float)) or not math.isfinite(ttl) or ttl <= 0:
            raise ValueError(f"ttl on {name} must be a positive number of seconds, got {ttl!r}")
        return self._time.now() + float(ttl)

    def _membership_changed(self, add: Add) -> None:
        """Hook: the stored add for ``add.key`` changed (clear caches here)."""

    def _expire(self) -> list[Key]:
        if self._time is None:
            return []
        return self._state.expire(self._time.now())

    def _notify(self, changed: frozenset[Key]) -> None:
        for listener in list(self._listeners):
            listener(changed)
