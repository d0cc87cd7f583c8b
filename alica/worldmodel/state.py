"""The replicated state: tables of entries and the join that merges them.

:class:`ReplicaState` is the CRDT itself, with no notion of an agent, a
Lamport clock or subscribers (:class:`~alica.worldmodel.Replica` adds those);
callers pass it the current time for expiry. Its state is a join-semilattice:

* a register ``(name, args)`` keeps the :class:`~alica.worldmodel.Write` with
  the largest stamp (equal stamps, which only a misconfigured team produces,
  are broken by the entry hash);
* a set member or an object keeps the :class:`~alica.worldmodel.Add` with the
  smallest stamp, so adding a present item again changes nothing.

Each rule is a max over a total order, hence idempotent, commutative and
associative. Besides the tables the state keeps derived views that make the
hot path one dict lookup: ``live`` (register values that are neither
tombstones nor expired), ``bool_arity`` (how many registers of each
``(name, arity)`` hold a truth value, which makes that predicate closed-world)
and per-bucket XOR hashes for digests.
"""

from __future__ import annotations

import heapq

from alica.worldmodel.delta import Add, Delta, Digest, Entry, Key, Write
from alica.worldmodel.stamp import newer

RegisterKey = tuple[str, tuple[object, ...]]


class ReplicaState:
    """Entries of one replica and the views derived from them.

    Args:
        buckets: how many key buckets digests have (at least 1).

    Raises:
        ValueError: ``buckets`` is not a positive int.
    """

    __slots__ = ("_expiry", "bool_arity", "bucket_hash", "live", "objects", "registers", "seen", "sets", "version")

    def __init__(self, buckets: int = 64) -> None:
        if type(buckets) is not int or buckets < 1:
            raise ValueError(f"buckets must be an int >= 1, got {buckets!r}")
        self.registers: dict[RegisterKey, Write] = {}
        self.live: dict[RegisterKey, object] = {}
        self.sets: dict[str, dict[object, Add]] = {}
        self.objects: dict[str, dict[object, Add]] = {}
        self.bool_arity: dict[tuple[str, int], int] = {}
        self.bucket_hash: list[int] = [0] * buckets
        self.seen: dict[str, int] = {}
        self.version = 0
        self._expiry: list[tuple[float, int, RegisterKey]] = []

    # -- the join --------------------------------------------------------

    def put_write(self, write: Write, now: float | None) -> bool:
        """Merge one register write.

        Args:
            write: the write.
            now: the current time for expiry, or None when the replica has
                no clock (values then never expire).

        Returns:
            Whether the stored entry changed.
        """
        self._observe(write.stamp.counter, write.stamp.writer)
        key = (write.name, write.args)
        old = self.registers.get(key)
        if old is not None:
            if old is write:
                return False
            wins = newer(write.stamp.counter, write.stamp.writer, old.stamp.counter, old.stamp.writer)
            if wins is None:
                wins = write.entry_hash > old.entry_hash
            if not wins:
                return False
            self._unhash(old)
            if type(old.value) is bool:
                self._count(old.name, len(old.args), -1)
        self.registers[key] = write
        self._hash(write)
        value = write.value
        if type(value) is bool:
            self._count(write.name, len(write.args), 1)
        if value is None or (write.expires is not None and now is not None and now >= write.expires):
            self.live.pop(key, None)
        else:
            self.live[key] = value
            if write.expires is not None and now is not None:
                heapq.heappush(self._expiry, (write.expires, self.version, key))
        self.version += 1
        return True

    def put_add(self, add: Add) -> tuple[bool, bool]:
        """Merge one set or object add.

        Args:
            add: the add.

        Returns:
            ``(changed, new)``: whether the stored entry changed, and whether
            the item was not a member before.
        """
        self._observe(add.stamp.counter, add.stamp.writer)
        table = (self.sets if add.kind == "set" else self.objects).setdefault(add.name, {})
        old = table.get(add.item)
        new = old is None
        if old is not None:
            if old is add:
                return False, False
            later = newer(add.stamp.counter, add.stamp.writer, old.stamp.counter, old.stamp.writer)
            if later is None:
                later = add.entry_hash > old.entry_hash
            if later:
                return False, False
            self._unhash(old)
            del table[old.item]  # re-key: the smallest add also decides how the item is spelled (1 or 1.0)
        table[add.item] = add
        self._hash(add)
        self.version += 1
        return True, new

    def expire(self, now: float) -> list[Key]:
        """Drop values whose time is up from the live view.

        Args:
            now: the current time.

        Returns:
            The registers whose value went stale.
        """
        stale: list[Key] = []
        heap = self._expiry
        while heap and heap[0][0] <= now:
            _, _, key = heapq.heappop(heap)
            write = self.registers.get(key)
            if write is not None and write.expires is not None and write.expires <= now and key in self.live:
                del self.live[key]
                stale.append(write.key)
        if stale:
            self.version += 1
        return stale

    # -- views -------------------------------------------------------------

    def entries(self) -> list[Entry]:
        """Every stored entry, in no particular order."""
        found: list[Entry] = list(self.registers.values())
        for table in self.sets.values():
            found.extend(table.values())
        for table in self.objects.values():
            found.extend(table.values())
        return found

    def snapshot(self) -> Delta:
        """The whole state as a delta."""
        return Delta.of(self.entries())

    def digest(self) -> Digest:
        """A summary of the state; see :class:`~alica.worldmodel.Digest`."""
        total = 0
        for value in self.bucket_hash:
            total ^= value
        clock = tuple(sorted(self.seen.items()))
        return Digest(total, tuple(self.bucket_hash), clock, self.size())

    def size(self) -> int:
        """How many entries are stored (tombstones included)."""
        count = len(self.registers)
        for table in self.sets.values():
            count += len(table)
        for table in self.objects.values():
            count += len(table)
        return count

    def missing_for(self, digest: Digest) -> Delta:
        """Everything a peer with ``digest`` may lack.

        The entries of every bucket whose hash differs from the peer's. A
        bucket with an equal hash holds the same entries on both sides (up to
        a 128-bit hash collision), so nothing the peer lacks is left out.

        Args:
            digest: the peer's digest.

        Returns:
            The entries to send (all of them when the bucket counts differ).
        """
        if not isinstance(digest, Digest):
            raise TypeError(f"missing_for takes a Digest from WorldModel.digest(), got {type(digest).__name__}")
        mine = self.bucket_hash
        if len(digest.buckets) != len(mine):
            return self.snapshot()
        theirs = digest.buckets
        count = len(mine)
        differ = [mine[index] != theirs[index] for index in range(count)]
        if not any(differ):
            return Delta()
        return Delta.of([entry for entry in self.entries() if differ[entry.key_hash % count]])

    def max_counter(self) -> int:
        """The largest Lamport counter seen from any writer."""
        return max(self.seen.values(), default=0)

    # -- bookkeeping -----------------------------------------------------

    def _observe(self, counter: int, writer: str) -> None:
        if self.seen.get(writer, 0) < counter:
            self.seen[writer] = counter

    def _hash(self, entry: Entry) -> None:
        index = entry.key_hash % len(self.bucket_hash)
        self.bucket_hash[index] ^= entry.entry_hash

    def _unhash(self, entry: Entry) -> None:
        self._hash(entry)  # XOR removes what XOR added

    def _count(self, name: str, arity: int, step: int) -> None:
        slot = (name, arity)
        count = self.bool_arity.get(slot, 0) + step
        if count:
            self.bool_arity[slot] = count
        else:
            del self.bool_arity[slot]
