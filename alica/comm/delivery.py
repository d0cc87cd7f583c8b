"""The message machinery of the simulated network: arrivals ordered in simulated time.

Whenever the network is asked something (``poll``, ``peers``, ``stats``, a
fault call) it first moves every arrival and event due by the clock's
``now`` into effect in (time, send counter, push order) order, so each
receiver's inbox is sorted by (delivery time, send counter).

Best-effort copies, the bulk of the traffic, never wait in a heap: a publish
appends one item per distinct arrival time (one item for all its receivers
when the delay has no jitter) to an unsorted list, and the next advance
sorts that list into the waiting list (timsort merges the sorted runs in
linear time) and cuts off the due prefix. Reliable copies wait in one FIFO
queue per directed link, of which only the head sits in a heap, together
with crash and partition events; a reliable message never overtakes an
earlier one on its link. The two streams are interleaved in order.

Random draws happen only in ``publish``, in publish order, from the
network's one ``random.Random``; nothing here iterates over a hash-ordered
set, so a seed and a sequence of calls give the same deliveries in any
process whatever ``PYTHONHASHSEED`` is."""

from __future__ import annotations

import math
import random
from bisect import bisect_right
from collections import deque
from heapq import heapify, heappop, heappush

from alica.clock import Clock
from alica.comm.delay import Link
from alica.comm.faults import Partition
from alica.comm.simtransport import AgentState, Reliable
from alica.comm.stats import Counters
from alica.comm.trace import Tracer
from alica.comm.transport import Envelope, QoS

# Heap items are (time, counter, push id, kind, data); events (counter -1) sort before messages at the same time.
# Best-effort items are (time, counter, push id, envelope, key, receivers) and live in sorted lists, not the heap.
_RELIABLE, _CRASH, _CUT_START, _CUT_END = range(4)
_EVENT = -1


class Delivery:
    """The state and message flow shared by :class:`~alica.comm.simnet.SimNetwork`.

    Args:
        clock: the simulated clock.
        rng: the network's only random generator.
        default: loss and delay of links without an override.
        lease: seconds a peer stays in ``peers()`` after its last message.
        retransmit: seconds until a lost reliable transmission is repeated.
        tracer: reports trace events to the observer.
    """

    def __init__(
        self,
        clock: Clock,
        rng: random.Random,
        default: Link,
        lease: float,
        retransmit: float,
        tracer: Tracer,
    ) -> None:
        self._clock = clock
        self._rng = rng
        self._default = default
        self._lease = lease
        self._retransmit = retransmit
        self._tracer = tracer
        self._trace = tracer.messages
        self._agents: dict[str, AgentState] = {}
        self._subscribers: dict[str, list[AgentState]] = {}
        self._links: dict[str, dict[str, Link]] = {}
        self._heap: list[tuple] = []
        self._incoming: list[tuple] = []
        self._incoming_earliest = math.inf
        self._waiting: list[tuple] = []
        self._due: list[tuple] = []
        self._due_position = 0
        self._counter = 0
        self._pushes = 0
        self._partitions: list[Partition] = []
        self._held: dict[tuple[str, str], Reliable] = {}
        self._counts = Counters()

    # ------------------------------------------------------------------ transport calls

    def _publish(self, sender: AgentState, topic: str, payload: object, qos: QoS) -> None:
        if sender.closed:
            raise ValueError(f"transport of {sender.name!r} is closed; it can no longer publish")
        if not isinstance(topic, str) or not topic:
            raise ValueError(f"topic must be a non-empty string, got {topic!r}")
        if qos is not QoS.BEST_EFFORT and qos is not QoS.RELIABLE:
            raise ValueError(f"qos must be QoS.BEST_EFFORT or QoS.RELIABLE, got {qos!r}")
        now = self._clock.now()
        if sender.crash_at is not None and sender.crash_at <= now:
            return
        seq = sender.seq.get(topic, 0) + 1
        sender.seq[topic] = seq
        self._counter += 1
        envelope = Envelope(topic, sender.name, seq, payload, now, qos)
        self._counts.sent += 1
        sender.sent += 1
        if self._trace:
            self._tracer.message(now, "send", envelope, None, qos=qos.value)
        subscribers = self._subscribers.get(topic)
        if subscribers:
            if qos is QoS.BEST_EFFORT:
                self._send_best_effort(sender, envelope, subscribers, now)
            else:
                self._send_reliable(sender, envelope, subscribers, now)

    def _send_best_effort(
        self, sender: AgentState, envelope: Envelope, subscribers: list[AgentState], now: float
    ) -> None:
        counts = self._counts
        default = self._default
        links = self._links.get(sender.name)
        random_draw = self._rng.random
        partitions = self._partitions
        incoming = self._incoming
        key = (sender.name, envelope.topic)
        counter = self._counter
        batch: list[AgentState] = []
        batch_time = -math.inf
        earliest = math.inf
        for receiver in subscribers:
            if receiver is sender:
                continue
            if receiver.crash_at is not None and receiver.crash_at <= now:
                counts.dropped_crash += 1
                if self._trace:
                    self._tracer.message(now, "drop", envelope, receiver.name, reason="crash")
                continue
            if partitions and self._cut(sender.name, receiver.name, now):
                counts.dropped_partition += 1
                if self._trace:
                    self._tracer.message(now, "drop", envelope, receiver.name, reason="partition")
                continue
            link = default if links is None else links.get(receiver.name, default)
            if link.loss and random_draw() < link.loss:
                counts.dropped_loss += 1
                if self._trace:
                    self._tracer.message(now, "drop", envelope, receiver.name, reason="loss")
                continue
            delay = link.delay
            if delay.jitter == 0.0:
                arrival = now + delay.base
            elif delay.kind == "uniform":
                arrival = now + (delay.base + random_draw() * delay.jitter)
            else:
                arrival = now + delay.sample(self._rng)
            if arrival != batch_time:
                if batch:
                    self._pushes += 1
                    incoming.append((batch_time, counter, self._pushes, envelope, key, batch))
                if arrival < earliest:
                    earliest = arrival
                batch = []
                batch_time = arrival
            batch.append(receiver)
        if batch:
            self._pushes += 1
            incoming.append((batch_time, counter, self._pushes, envelope, key, batch))
            if earliest < self._incoming_earliest:
                self._incoming_earliest = earliest

    def _send_reliable(self, sender: AgentState, envelope: Envelope, subscribers: list[AgentState], now: float) -> None:
        counts = self._counts
        links = self._links.get(sender.name, {})
        rng = self._rng
        for receiver in subscribers:
            if receiver is sender:
                continue
            if receiver.crash_at is not None and receiver.crash_at <= now:
                counts.dropped_crash += 1
                if self._trace:
                    self._tracer.message(now, "drop", envelope, receiver.name, reason="crash")
                continue
            link = links.get(receiver.name, self._default)
            retries = 0
            if link.loss:
                while rng.random() < link.loss:
                    retries += 1
                counts.retransmitted += retries
            delay = link.delay.sample(rng)
            copy = Reliable(now + retries * self._retransmit + delay, self._counter, envelope, delay, sender, receiver)
            queue = sender.outgoing.get(receiver.name)
            if queue is None:
                queue = sender.outgoing[receiver.name] = deque()
            queue.append(copy)
            if len(queue) == 1:
                self._push(copy.nominal, copy.counter, _RELIABLE, copy)

    # ------------------------------------------------------------------ the event loop

    def _advance(self) -> None:
        """Move every arrival and event due by now into effect, in (time, counter) order."""
        now = self._clock.now()
        waiting = self._waiting
        if self._incoming_earliest <= now:  # else nothing new is due yet: merge later, in one sort
            waiting += self._incoming
            self._incoming = []
            self._incoming_earliest = math.inf
            waiting.sort()  # a few sorted runs: timsort merges them in linear time
        heap = self._heap
        due: list[tuple] = []
        if waiting and waiting[0][0] <= now:
            end = bisect_right(waiting, (now, math.inf))
            due = waiting[:end]
            del waiting[:end]
        if heap and heap[0][0] <= now:
            self._merge(due, now)
        elif due:
            self._arrive_best_effort(due)
        if self._partitions:
            self._prune(now)

    def _merge(self, due: list[tuple], now: float) -> None:
        """Interleave the due best-effort items with the heap items due by ``now``, in order."""
        heap = self._heap
        self._due = due
        position = 0
        while heap and heap[0][0] <= now:
            top = heap[0]
            end = bisect_right(due, top, position)
            if end > position:
                self._arrive_best_effort(due[position:end])
                position = end
            self._due_position = position
            t, _, _, kind, data = heappop(heap)
            if kind == _RELIABLE:
                self._arrive_reliable(t, data)
            elif kind == _CRASH:
                state, token = data
                if state.crash_token == token:  # not cancelled by recover()
                    state.crash_token = None
                    self._go_down(state, t)
            elif kind == _CUT_START:
                if not data.over(t):
                    self._tracer.partition(data, t)
            elif data.end == t:  # _CUT_END, not moved by an earlier heal
                self._tracer.fault({"t": t, "event": "heal", "id": data.handle.id})
                self._wake(t)
        if position < len(due):
            self._arrive_best_effort(due[position:])
        self._due = []
        self._due_position = 0

    def _arrive_best_effort(self, run: list[tuple]) -> None:
        """Deliver due best-effort items, each (time, counter, push id, envelope, key, receivers)."""
        counts = self._counts
        partitions = self._partitions
        trace = self._trace
        for t, _, _, envelope, key, receivers in run:
            sender = envelope.sender
            seq = envelope.seq
            for receiver in receivers:
                if partitions and self._cut(sender, receiver.name, t):
                    counts.dropped_partition += 1
                    if trace:
                        self._tracer.message(t, "drop", envelope, receiver.name, reason="partition")
                    continue
                receiver.heard[sender] = t
                latest = receiver.last_best_effort
                if latest.get(key, 0) >= seq:
                    counts.superseded += 1
                    if trace:
                        self._tracer.message(t, "drop", envelope, receiver.name, reason="superseded")
                    continue
                latest[key] = seq
                inbox = receiver.inbox
                older = receiver.pending.get(key)
                if older is not None:
                    if trace:
                        self._tracer.message(t, "drop", inbox[older], receiver.name, reason="superseded")
                    inbox[older] = None
                    receiver.holes += 1
                    counts.superseded += 1
                receiver.pending[key] = len(inbox)
                inbox.append(envelope)
                if trace:
                    self._tracer.message(t, "deliver", envelope, receiver.name)

    def _arrive_reliable(self, t: float, copy: Reliable) -> None:
        sender, receiver = copy.sender, copy.receiver
        if self._partitions and self._cut(sender.name, receiver.name, t):
            self._held[(sender.name, receiver.name)] = copy
            return
        receiver.heard[sender.name] = t
        receiver.inbox.append(copy.envelope)
        if self._trace:
            self._tracer.message(t, "deliver", copy.envelope, receiver.name)
        queue = sender.outgoing[receiver.name]
        queue.popleft()
        if queue:
            following = queue[0]
            self._push(max(following.nominal, t), following.counter, _RELIABLE, following)

    def _wake(self, t: float) -> None:
        """Send again the held reliable copies whose link is back at ``t``."""
        for link, copy in list(self._held.items()):
            if not self._cut(link[0], link[1], t):
                del self._held[link]
                self._push(t + copy.delay, copy.counter, _RELIABLE, copy)

    def _go_down(self, state: AgentState, t: float) -> None:
        dropped = self._purge(state, t, "crash")
        self._counts.dropped_crash += dropped
        self._tracer.fault({"t": t, "event": "crash", "agent": state.name, "dropped": dropped})

    def _purge(self, state: AgentState, t: float, reason: str) -> int:
        """Drop everything in flight to ``state`` and its inbox; returns how many copies."""
        dropped: list[Envelope] = []
        best_effort = self._due[self._due_position :] + self._waiting + self._incoming
        for _, _, _, envelope, _, receivers in best_effort:
            if state in receivers:
                receivers.remove(state)
                dropped.append(envelope)
        kept = [item for item in self._heap if not (item[3] == _RELIABLE and item[4].receiver is state)]
        heapify(kept)
        self._heap[:] = kept  # in place: a running _merge holds the list
        for sender in self._agents.values():
            queue = sender.outgoing.pop(state.name, None)
            if queue:
                dropped.extend(copy.envelope for copy in queue)
                self._held.pop((sender.name, state.name), None)
        unpolled = [envelope for envelope in state.inbox if envelope is not None]
        state.forget()
        if self._trace:
            for envelope in dropped + unpolled:
                self._tracer.message(t, "drop", envelope, state.name, reason=reason)
        return len(dropped) + len(unpolled)

    # ------------------------------------------------------------------ helpers

    def _agent(self, agent_id: str) -> AgentState:
        state = self._agents.get(agent_id) if isinstance(agent_id, str) else None
        if state is None:
            raise ValueError(f"unknown agent {agent_id!r}; attach it to the network first")
        return state

    def _cut(self, a: str, b: str, t: float) -> bool:
        for cut in self._partitions:
            if cut.separates(a, b, t):
                return True
        return False

    def _prune(self, now: float) -> None:
        self._partitions = [cut for cut in self._partitions if not cut.over(now)]

    def _push(self, t: float, counter: int, kind: int, data: object) -> None:
        self._pushes += 1
        heappush(self._heap, (t, counter, self._pushes, kind, data))

    def _push_event(self, t: float, kind: int, data: object) -> None:
        self._pushes += 1
        heappush(self._heap, (t, _EVENT, self._pushes, kind, data))

    def _schedule_crash(self, state: AgentState) -> None:
        """Crash ``state`` at its future ``crash_at``."""
        assert state.crash_at is not None
        state.crash_token = self._pushes + 1
        self._push_event(state.crash_at, _CRASH, (state, state.crash_token))

    def _schedule_cut_start(self, cut: Partition) -> None:
        """Announce ``cut`` when it begins."""
        self._push_event(cut.start, _CUT_START, cut)

    def _schedule_cut_end(self, cut: Partition) -> None:
        """End ``cut`` at its ``end``: announce the heal and send held messages again."""
        assert cut.end is not None
        self._push_event(cut.end, _CUT_END, cut)
