"""An in-memory network in simulated time, deterministic from a seed.

Every agent gets a :class:`~alica.comm.simtransport.SimTransport` from
:meth:`SimNetwork.attach`. Links lose and delay messages as configured;
partitions, heals, crashes and recoveries happen now or at given simulated
times. The same seed and the same sequence of calls give the same deliveries
in any process (see :mod:`alica.comm.delivery` for how).
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable

from alica.clock import Clock
from alica.comm.delay import Delay, Link, check_probability
from alica.comm.delivery import Delivery
from alica.comm.faults import Partition, PartitionHandle, check_time, group_map
from alica.comm.simtransport import AgentState, SimTransport
from alica.comm.stats import NetStats
from alica.comm.trace import Observer, Tracer
from alica.comm.transport import Envelope


def _positive(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number of seconds > 0, got {value!r}")
    return float(value)


class SimNetwork(Delivery):
    """A simulated network for a team of agents.

    Args:
        clock: the simulated clock (a :class:`~alica.clock.ManualClock` in tests).
        seed: seed of the network's random generator.
        loss: default probability that one transmission is lost, in [0, 1).
        delay: default one-way delay of every link.
        lease: seconds after the last message from a peer until
            :meth:`SimTransport.peers` forgets it.
        observer: called with one JSON-able dict per trace event; fault
            events (partition, heal, crash, recover) always, message events
            (send, deliver, drop) only with ``trace_messages``.
        trace_messages: also report every message event to the observer.
        retransmit: seconds until a lost reliable transmission is sent again.

    Raises:
        ValueError: an argument out of range; the message says which.
    """

    def __init__(
        self,
        clock: Clock,
        seed: int = 0,
        loss: float = 0.0,
        delay: Delay = Delay(0.0),  # noqa: B008 (a frozen value)
        lease: float = 2.0,
        observer: Observer | None = None,
        *,
        trace_messages: bool = False,
        retransmit: float = 0.1,
    ) -> None:
        if not callable(getattr(clock, "now", None)):
            raise ValueError(f"clock must have a now() method, e.g. alica.clock.ManualClock(), got {clock!r}")
        if isinstance(seed, bool) or not isinstance(seed, int):
            raise ValueError(f"seed must be an int, got {seed!r}")
        if observer is not None and not callable(observer):
            raise ValueError(f"observer must be a function of one dict, or None, got {observer!r}")
        super().__init__(
            clock,
            random.Random(seed),
            Link(check_probability("loss", loss), delay),
            _positive("lease", lease),
            _positive("retransmit", retransmit),
            Tracer(observer, bool(trace_messages)),
        )
        self._partition_count = 0

    # ------------------------------------------------------------------ set-up

    def attach(self, agent_id: str) -> SimTransport:
        """Connect an agent and return its transport.

        Args:
            agent_id: a non-empty id, unique in this network.

        Returns:
            The agent's transport.

        Raises:
            ValueError: the id is empty or already attached.
        """
        if not isinstance(agent_id, str) or not agent_id:
            raise ValueError(f"agent id must be a non-empty string, got {agent_id!r}")
        if agent_id in self._agents:
            raise ValueError(
                f"agent {agent_id!r} is already attached to this network; each agent gets one transport, "
                "so reuse it or attach a different id"
            )
        state = AgentState(agent_id, len(self._agents))
        self._agents[agent_id] = state
        return SimTransport(self, state)

    def set_link(
        self,
        a: str,
        b: str,
        loss: float | None = None,
        delay: Delay | None = None,
        *,
        symmetric: bool = False,
    ) -> None:
        """Override loss and/or delay of the directed link ``a -> b``.

        Args:
            a: the sending agent.
            b: the receiving agent.
            loss: the new loss probability, or ``None`` to keep the current one.
            delay: the new delay, or ``None`` to keep the current one.
            symmetric: set ``b -> a`` the same way.

        Raises:
            ValueError: an unknown agent, ``a == b``, neither loss nor delay
                given, or a value out of range.
        """
        self._agent(a)
        self._agent(b)
        if a == b:
            raise ValueError(f"a link joins two different agents, got {a!r} twice")
        if loss is None and delay is None:
            raise ValueError("set_link needs loss=... or delay=... (or both)")
        for src, dst in ((a, b), (b, a)) if symmetric else ((a, b),):
            current = self.link(src, dst)
            new_loss = current.loss if loss is None else check_probability("loss", loss)
            self._links.setdefault(src, {})[dst] = Link(new_loss, current.delay if delay is None else delay)

    def link(self, a: str, b: str) -> Link:
        """The loss and delay of the directed link ``a -> b``.

        Args:
            a: the sending agent.
            b: the receiving agent.

        Returns:
            The link's override, or the network's default.
        """
        return self._links.get(a, {}).get(b, self._default)

    # ------------------------------------------------------------------ faults

    def partition(
        self,
        groups: Iterable[Iterable[str]],
        start: float | None = None,
        end: float | None = None,
    ) -> PartitionHandle:
        """Cut the network into groups that cannot talk to each other.

        Best-effort messages across the cut are dropped; reliable ones are
        held and delivered in order, each after its delay counted from the
        moment the link is back.

        Args:
            groups: groups of agent ids; the agents not listed form one more
                group together.
            start: when the cut begins; ``None`` for now.
            end: when it ends by itself; ``None`` for "until healed".

        Returns:
            A handle for :meth:`heal`.

        Raises:
            ValueError: bad groups, a start in the past, or ``end <= start``.
        """
        self._advance()
        now = self._clock.now()
        mapping = group_map(groups, self._agents)
        begin = now if start is None else check_time("start", start, now)
        if end is not None and check_time("end", end, now) <= begin:
            raise ValueError(f"partition end={end} must come after its start={begin}")
        self._partition_count += 1
        handle = PartitionHandle(self._partition_count)
        cut = Partition(handle, mapping, begin, None if end is None else float(end))
        self._partitions.append(cut)
        if begin <= now:
            self._tracer.partition(cut, now)
        else:
            self._schedule_cut_start(cut)
        if cut.end is not None:
            self._schedule_cut_end(cut)
        return handle

    def heal(self, handle: PartitionHandle | None = None) -> None:
        """End one partition now (or cancel it if it has not begun), or all of them.

        Healing a partition that is already over does nothing.

        Args:
            handle: the partition to end; ``None`` for every partition.

        Raises:
            ValueError: ``handle`` does not name a partition of this network.
        """
        if handle is not None and not (isinstance(handle, PartitionHandle) and 1 <= handle.id <= self._partition_count):
            raise ValueError(f"{handle!r} is not a partition of this network; pass what partition() returned")
        self._advance()
        now = self._clock.now()
        for cut in list(self._partitions):
            if (handle is None or cut.handle == handle) and not cut.over(now):
                started = cut.start <= now
                cut.end = now
                if started:
                    self._tracer.fault({"t": now, "event": "heal", "id": cut.handle.id})
        self._wake(now)
        self._prune(now)

    def crash(self, agent_id: str, at: float | None = None) -> None:
        """Crash an agent now or at a future time.

        From then on its publish calls do nothing, it receives nothing, and
        everything in flight to it or unpolled in its inbox is dropped,
        reliable messages included. Messages it published before are already
        on the network and still arrive.

        Args:
            agent_id: the agent.
            at: when it crashes; ``None`` for now.

        Raises:
            ValueError: an unknown agent, a time in the past, or the agent is
                already crashed or has a crash scheduled.
        """
        state = self._agent(agent_id)
        self._advance()
        now = self._clock.now()
        when = now if at is None else check_time("at", at, now)
        if state.crash_at is not None:
            raise ValueError(
                f"agent {agent_id!r} is already crashed or has a crash at t={state.crash_at}; recover() it first"
            )
        state.crash_at = when
        if when <= now:
            self._go_down(state, now)
        else:
            self._schedule_crash(state)

    def recover(self, agent_id: str) -> None:
        """Bring a crashed agent back with an empty inbox, or cancel its scheduled crash.

        Its subscriptions stay; it receives what is published from now on.

        Args:
            agent_id: the agent.

        Raises:
            ValueError: an unknown agent, or one that is neither crashed nor
                scheduled to crash.
        """
        state = self._agent(agent_id)
        self._advance()
        if state.crash_at is None:
            raise ValueError(f"agent {agent_id!r} is not crashed and has no crash scheduled; nothing to recover")
        now = self._clock.now()
        was_down = state.down_at(now)
        state.crash_at = None
        state.crash_token = None
        self._tracer.fault({"t": now, "event": "recover", "agent": agent_id, "cancelled": not was_down})

    def crashed(self, agent_id: str) -> bool:
        """True when the agent is crashed now.

        Args:
            agent_id: the agent.

        Returns:
            Whether it is down at the clock's current time.

        Raises:
            ValueError: an unknown agent.
        """
        return self._agent(agent_id).down_at(self._clock.now())

    @property
    def stats(self) -> NetStats:
        """What the network did so far, up to now."""
        self._advance()
        buffered = sum(len(held.sender.outgoing[held.receiver.name]) for held in self._held.values())
        return self._counts.snapshot(buffered, {name: state.sent for name, state in self._agents.items()})

    # ------------------------------------------------------------------ transport calls (from SimTransport)

    def _subscribe(self, state: AgentState, topic: str) -> None:
        if state.closed:
            raise ValueError(f"transport of {state.name!r} is closed; it can no longer subscribe")
        if not isinstance(topic, str) or not topic:
            raise ValueError(f"topic must be a non-empty string, got {topic!r}")
        subscribers = self._subscribers.setdefault(topic, [])
        if state not in subscribers:
            subscribers.append(state)
            subscribers.sort(key=lambda s: s.index)

    def _poll(self, state: AgentState) -> list[Envelope]:
        if state.closed:
            raise ValueError(f"transport of {state.name!r} is closed; it can no longer poll")
        self._advance()
        if not state.inbox:
            return []
        delivered = state.take_inbox()
        self._counts.delivered += len(delivered)
        return delivered

    def _peers(self, state: AgentState) -> frozenset[str]:
        self._advance()
        now = self._clock.now()
        lease = self._lease
        return frozenset(name for name, last in state.heard.items() if now - last <= lease)

    def _close(self, state: AgentState) -> None:
        if state.closed:
            return
        self._advance()
        state.closed = True
        for subscribers in self._subscribers.values():
            if state in subscribers:
                subscribers.remove(state)
        self._counts.dropped_closed += self._purge(state, self._clock.now(), "closed")
