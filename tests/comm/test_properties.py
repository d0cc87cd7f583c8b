"""Properties over random runs: publishes, polls, partitions, heals, crashes and recoveries."""

from __future__ import annotations

from dataclasses import dataclass, field

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.clock import ManualClock
from alica.comm import Delay, QoS, SimNetwork

AGENTS = ("a", "b", "c", "d")
TOPICS = ("x", "y")

agent = st.sampled_from(AGENTS)
offset = st.floats(0.0, 2.0, allow_nan=False)
publish = st.tuples(st.just("publish"), agent, st.sampled_from(TOPICS), st.sampled_from(list(QoS)), st.integers(1, 4))
advance = st.tuples(st.just("advance"), st.floats(0.0, 0.6, allow_nan=False))
partition = st.tuples(
    st.just("partition"),
    st.lists(st.lists(agent, min_size=1, max_size=3, unique=True), min_size=1, max_size=3),
    st.none() | offset,
    st.none() | offset,
)
operation = st.one_of(  # publishes and time steps repeated: drawn more often
    publish,
    publish,
    publish,
    advance,
    advance,
    st.tuples(st.just("poll"), agent),
    partition,
    partition,
    st.tuples(st.just("heal"), st.none() | st.integers(1, 6)),
    st.tuples(st.just("crash"), agent, st.none() | offset),
    st.tuples(st.just("recover"), agent),
)
delays = st.builds(
    Delay,
    st.floats(0.0, 0.2, allow_nan=False),
    st.floats(0.0, 0.3, allow_nan=False),
    st.sampled_from(["uniform", "exponential"]),
)
subscriptions = st.fixed_dictionaries({name: st.sets(st.sampled_from(TOPICS), min_size=1) for name in AGENTS})


@dataclass
class Run:
    """What a run published and what each agent received."""

    expected: dict[tuple[str, str], list[tuple[str, int]]] = field(default_factory=dict)
    received: dict[tuple[str, str], list[tuple[str, int]]] = field(default_factory=dict)
    best_effort: dict[tuple[str, str, str], list[int]] = field(default_factory=dict)
    ever_crashed: set[str] = field(default_factory=set)
    after_last_recovery: dict[tuple[str, str], list[tuple[str, int]]] = field(default_factory=dict)
    log: list[tuple[float, str, str, str, int]] = field(default_factory=list)


def disjoint(groups: list[list[str]]) -> list[list[str]]:
    seen: set[str] = set()
    out = []
    for group in groups:
        kept = [name for name in group if name not in seen]
        seen.update(kept)
        if kept:
            out.append(kept)
    return out


def execute(seed: int, loss: float, delay: Delay, subscribed: dict[str, set[str]], operations: list) -> Run:
    clock = ManualClock()
    network = SimNetwork(clock, seed=seed, loss=loss, delay=delay)
    transports = {name: network.attach(name) for name in AGENTS}
    for name in AGENTS:
        for topic in sorted(subscribed[name]):
            transports[name].subscribe(topic)
    run = Run()
    crash_at: dict[str, float | None] = dict.fromkeys(AGENTS)
    seq: dict[tuple[str, str], int] = {}
    handles = []

    def down(name: str) -> bool:
        when = crash_at[name]
        return when is not None and when <= clock.now()

    def poll(name: str) -> None:
        for envelope in transports[name].poll():
            assert envelope.sender != name
            assert envelope.topic in subscribed[name]
            run.log.append((clock.now(), name, envelope.sender, envelope.topic, envelope.seq))
            if envelope.qos is QoS.RELIABLE:
                run.received.setdefault((envelope.sender, name), []).append((envelope.topic, envelope.seq))
            else:
                run.best_effort.setdefault((envelope.sender, name, envelope.topic), []).append(envelope.seq)

    for op in operations:
        kind = op[0]
        if kind == "publish":
            _, sender, topic, qos, burst = op
            for _ in range(burst):
                transports[sender].publish(topic, None, qos)
                if down(sender):
                    continue
                number = seq[(sender, topic)] = seq.get((sender, topic), 0) + 1
                for receiver in AGENTS:
                    if receiver != sender and topic in subscribed[receiver] and qos is QoS.RELIABLE:
                        run.expected.setdefault((sender, receiver), []).append((topic, number))
                        if crash_at[receiver] is None:
                            run.after_last_recovery.setdefault((sender, receiver), []).append((topic, number))
        elif kind == "advance":
            clock.advance(op[1])
        elif kind == "poll":
            poll(op[1])
        elif kind == "partition":
            _, groups, start, length = op
            begin = None if start is None else clock.now() + start
            end = None if length is None else (begin or clock.now()) + length + 0.01
            handles.append(network.partition(disjoint(groups), start=begin, end=end))
        elif kind == "heal":
            index = op[1]
            network.heal(handles[index - 1] if index is not None and index <= len(handles) else None)
        elif kind == "crash" and crash_at[op[1]] is None:
            _, name, later = op
            crash_at[name] = clock.now() + (later or 0.0)
            network.crash(name, at=None if later is None else crash_at[name])
            run.ever_crashed.add(name)
            for key in [key for key in run.after_last_recovery if key[1] == name]:
                del run.after_last_recovery[key]
        elif kind == "recover" and crash_at[op[1]] is not None:
            network.recover(op[1])
            crash_at[op[1]] = None
    network.heal()
    clock.advance(60.0)
    for name in AGENTS:
        poll(name)
    return run


def is_subsequence(small: list, big: list) -> bool:
    items = iter(big)
    return all(item in items for item in small)


@settings(max_examples=300)
@given(
    seed=st.integers(0, 2**16),
    loss=st.sampled_from([0.0, 0.2, 0.5]),
    delay=delays,
    subscribed=subscriptions,
    operations=st.lists(operation, min_size=5, max_size=80),
)
def test_reliable_is_exactly_once_and_in_order_after_the_final_heal(
    seed: int, loss: float, delay: Delay, subscribed: dict[str, set[str]], operations: list
) -> None:
    run = execute(seed, loss, delay, subscribed, operations)
    for link in set(run.expected) | set(run.received):
        sender, receiver = link
        expected = run.expected.get(link, [])
        received = run.received.get(link, [])
        if receiver in run.ever_crashed:
            assert len(set(received)) == len(received), link  # no duplicates
            assert is_subsequence(received, expected), link  # in order, nothing invented
            tail = run.after_last_recovery.get(link, [])
            assert received[len(received) - len(tail) :] == tail, link  # all since the last recovery
        else:
            assert received == expected, link
    for (sender, receiver, topic), seqs in run.best_effort.items():
        assert seqs == sorted(set(seqs)), (sender, receiver, topic)  # latest value only, never older


@given(seed=st.integers(0, 2**16), delay=delays, subscribed=subscriptions, operations=st.lists(operation, max_size=40))
def test_same_seed_and_calls_give_the_same_deliveries(
    seed: int, delay: Delay, subscribed: dict[str, set[str]], operations: list
) -> None:
    first = execute(seed, 0.3, delay, subscribed, operations)
    second = execute(seed, 0.3, delay, subscribed, operations)
    assert first.log == second.log
