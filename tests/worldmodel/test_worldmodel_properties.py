"""Property tests: replicas converge, and nothing written is lost, whatever the network does.

Random interleavings of writes by 2-4 replicas are mixed with random
deliveries of their deltas (late, duplicated, reordered, or never: dropped),
then the replicas exchange snapshots or digest answers once. Every replica
must then hold byte-identical state in which every register has the write
with the largest stamp made to it and every set the union of all adds.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.worldmodel import Delta, Stamp, WorldModel, order_key

REGISTERS = [("pos", ("r1",)), ("pos", ("r2",)), ("map", (0, 0)), ("map", (0, 1)), ("battery", ())]
FACTS = [("found", ("s1",)), ("found", ("s2",)), ("explored", ())]
SETS = ["invalid_candidates", "visited"]
TYPES = ["Sample", "Frontier"]
Step = tuple[Any, ...]

coords = st.floats(min_value=-10, max_value=10, allow_nan=False)
values = st.one_of(st.none(), st.integers(-3, 3), st.text(max_size=3), st.tuples(coords, coords), st.booleans())
items = st.one_of(st.sampled_from(["c1", "c2", "c3"]), st.integers(0, 3), st.tuples(st.integers(0, 2), st.just("x")))
replica = st.integers(0, 3)
action = st.one_of(
    st.tuples(st.just("set"), replica, st.sampled_from(REGISTERS), values),
    st.tuples(st.just("fact"), replica, st.sampled_from(FACTS), st.booleans()),
    st.tuples(st.just("unset"), replica, st.sampled_from(REGISTERS + FACTS)),
    st.tuples(st.just("add"), replica, st.sampled_from(SETS), items),
    st.tuples(st.just("object"), replica, st.sampled_from(TYPES), items),
    st.tuples(st.just("publish"), replica),
    st.tuples(st.just("deliver"), st.integers(0, 10_000), replica),
)


@dataclass
class Team:
    """Replicas, the deltas they published, and an oracle of every write made."""

    replicas: list[WorldModel]
    outbox: list[Delta] = field(default_factory=list)
    writes: dict[tuple[str, tuple[object, ...]], list[tuple[Stamp, object]]] = field(default_factory=dict)
    sets: dict[str, set[object]] = field(default_factory=dict)
    objects: dict[str, set[object]] = field(default_factory=dict)
    merged_top: list[int] = field(default_factory=list)

    @classmethod
    def of(cls, size: int, buckets: int = 64) -> Team:
        team = cls([WorldModel(f"agent{index}", buckets=buckets) for index in range(size)])
        team.merged_top = [0] * size
        return team

    def run(self, step: Step) -> None:
        kind, *rest = step
        if kind == "deliver":
            index, dst = rest
            if self.outbox:
                self.merge(dst % len(self.replicas), self.outbox[index % len(self.outbox)])
            return
        who = rest[0] % len(self.replicas)
        wm = self.replicas[who]
        if kind == "publish":
            delta = wm.take_delta()
            if delta is not None:
                self.outbox.append(delta)
            return
        before = wm.counter
        if kind in ("set", "fact", "unset"):
            (name, args), *value = rest[1:]
            if kind == "set":
                stamp, written = wm.set(name, *args, value=value[0]), value[0]
            elif kind == "unset":
                stamp, written = wm.unset(name, *args), None
            elif value[0]:
                stamp, written = wm.assert_fact(name, *args), True
            else:
                stamp, written = wm.retract_fact(name, *args), False
            # Lamport rule: the new write is larger than everything merged so far.
            assert stamp.counter == before + 1 > self.merged_top[who]
            self.writes.setdefault((name, args), []).append((stamp, written))
        elif kind == "add":
            name, item = rest[1:]
            wm.add_to_set(name, item)
            self.sets.setdefault(name, set()).add(item)
        else:
            type_name, obj = rest[1:]
            wm.add_object(obj, type_name)
            self.objects.setdefault(type_name, set()).add(obj)

    def merge(self, who: int, delta: Delta) -> None:
        self.replicas[who].merge(delta)
        self.merged_top[who] = max(self.merged_top[who], delta.max_counter())

    def exchange_snapshots(self) -> None:
        snapshots = [wm.snapshot() for wm in self.replicas]
        for who in range(len(self.replicas)):
            for snapshot in snapshots:
                self.merge(who, snapshot)

    def exchange_digests(self) -> None:
        for who, wm in enumerate(self.replicas):
            for peer in self.replicas:
                if peer is not wm:
                    self.merge(who, peer.missing_for(wm.digest()))

    def check_converged(self) -> None:
        first = self.replicas[0]
        dump = first.dumps()
        for wm in self.replicas[1:]:
            assert wm.dumps() == dump
            assert wm.digest().same_state(first.digest())
            assert wm.facts() == first.facts()
        for wm in self.replicas:
            for (name, args), history in self.writes.items():
                stamp, value = max(history, key=lambda write: write[0])
                assert wm.stamp_of(name, *args) == stamp
                assert wm.get(name, *args) == value
                if value is True:
                    assert wm.lookup(name, args) is True
            for name, members in self.sets.items():
                assert wm.members(name) == members
                for item in members:
                    assert wm.lookup(name, (item,)) is True
            for type_name, objs in self.objects.items():
                assert wm.objects(type_name) == tuple(sorted(objs, key=order_key))


@settings(max_examples=200)
@given(
    size=st.integers(2, 4),
    steps=st.lists(action, max_size=60),
    final=st.sampled_from(["snapshot", "digest"]),
    buckets=st.sampled_from([1, 4, 64]),
)
def test_replicas_converge_and_lose_no_write(size: int, steps: list[Step], final: str, buckets: int) -> None:
    team = Team.of(size, buckets)
    for step in steps:
        team.run(step)
    if final == "snapshot":
        team.exchange_snapshots()
    else:
        team.exchange_digests()
    team.check_converged()


@settings(max_examples=100)
@given(steps=st.lists(action, max_size=50), size=st.integers(2, 4))
def test_reliable_delivery_of_every_delta_converges_without_a_final_exchange(steps: list[Step], size: int) -> None:
    team = Team.of(size)
    for step in steps:
        if step[0] != "deliver":
            team.run(step)
    for wm in team.replicas:  # publish what is left
        team.run(("publish", team.replicas.index(wm)))
    # Deliver every delta to everyone, each replica in its own order (reversed for odd ones).
    for who in range(size):
        order = team.outbox if who % 2 == 0 else list(reversed(team.outbox))
        for delta in order:
            team.merge(who, delta)
    team.check_converged()


def deltas_of(steps: list[Step]) -> list[Delta]:
    """Deltas published by three replicas that run ``steps`` (with some deliveries)."""
    team = Team.of(3)
    for step in steps:
        team.run(step)
    for who in range(3):
        team.run(("publish", who))
    return team.outbox


@settings(max_examples=150)
@given(
    steps=st.lists(action, min_size=1, max_size=40),
    orders=st.lists(st.integers(0, 10_000), max_size=30),
    shuffle=st.randoms(use_true_random=False),
)
def test_merge_is_commutative_idempotent_and_associative(
    steps: list[Step], orders: list[int], shuffle: random.Random
) -> None:
    deltas = deltas_of(steps)
    if not deltas:
        return
    reference = WorldModel("ref")
    for delta in deltas:
        reference.merge(delta)
    expected = reference.dumps()
    # Any order, with duplicates.
    shuffled = list(deltas) + [deltas[index % len(deltas)] for index in orders]
    shuffle.shuffle(shuffled)
    other = WorldModel("other")
    for delta in shuffled:
        other.merge(delta)
    assert other.dumps() == expected
    # Any grouping: join two halves separately, then join the results.
    cut = len(orders) % (len(deltas) + 1)
    left, right, joined = WorldModel("left"), WorldModel("right"), WorldModel("joined")
    for delta in deltas[:cut]:
        left.merge(delta)
    for delta in deltas[cut:]:
        right.merge(delta)
    joined.merge(right.snapshot())
    joined.merge(left.snapshot())
    assert joined.dumps() == expected
    # Merging one's own snapshot changes nothing.
    assert joined.merge(joined.snapshot()) == frozenset()


@settings(max_examples=200)
@given(
    mine=st.lists(action, max_size=40),
    theirs=st.lists(action, max_size=40),
    dropped=st.integers(0, 2**40 - 1),
    buckets=st.sampled_from([1, 2, 8, 64]),
)
def test_missing_for_never_under_approximates(mine: list[Step], theirs: list[Step], dropped: int, buckets: int) -> None:
    a, b = WorldModel("a", buckets=buckets), WorldModel("b", buckets=buckets)
    for step in theirs:
        _apply_local(b, step)
    for index, step in enumerate(mine):
        _apply_local(a, step)
        delta = a.take_delta()  # one delta per write; the bits of `dropped` lose some
        if delta is not None and not dropped >> index & 1:
            b.merge(delta)
    answer = a.missing_for(b.digest())
    assert len(answer) <= len(a.snapshot())
    b.merge(answer)
    # b now holds at least everything a holds: a's full state adds nothing.
    assert b.merge(a.snapshot()) == frozenset()
    a.merge(b.missing_for(a.digest()))
    assert a.dumps() == b.dumps()


def _apply_local(wm: WorldModel, step: Step) -> None:
    kind, *rest = step
    if kind == "set":
        (name, args), value = rest[1:]
        wm.set(name, *args, value=value)
    elif kind == "fact":
        (name, args), truth = rest[1:]
        if truth:
            wm.assert_fact(name, *args)
        else:
            wm.retract_fact(name, *args)
    elif kind == "unset":
        name, args = rest[1]
        wm.unset(name, *args)
    elif kind == "add":
        wm.add_to_set(rest[1], rest[2])
    elif kind == "object":
        wm.add_object(rest[2], rest[1])
