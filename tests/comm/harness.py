"""Transports under test, behind one small interface the contract tests use.

A harness makes the transports of one team and injects faults. The contract
tests (``test_contract.py``) see only this interface: the simulated network
advances a manual clock; the zenoh harness runs real sessions on loopback,
makes partitions by cutting the TCP relays between them
(:class:`alica.comm.relay.LinkRelay`) and waits in real time.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import Protocol

from alica.clock import ManualClock
from alica.comm import Delay, Envelope, QoS, SimNetwork, Transport
from alica.comm.relay import LinkRelay
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints


class Harness(Protocol):
    """One team's transports plus fault injection."""

    lease: float
    """The liveliness lease of the transports, in seconds."""
    lossless: bool
    """True when best-effort messages are never lost on a healthy link."""
    settle_time: float
    """Long enough for every message in flight to arrive (reliable ones retransmitted)."""
    by_reference: bool
    """True when a payload arrives as the very object published (no serialisation)."""
    liveness: str
    """``"heard"``: peers are the agents heard within the lease; ``"token"``: the agents whose liveliness token is up."""

    def now(self) -> float:
        """The transports' clock now."""
        ...

    def attach(self, agent_id: str) -> Transport:
        """A transport for a new agent."""
        ...

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` of (simulated or real) time pass."""
        ...

    def partition(self, groups: Iterable[Iterable[str]]) -> None:
        """Cut the team into groups from now on."""
        ...

    def heal(self) -> None:
        """Undo every partition."""
        ...

    def crash(self, agent_id: str) -> None:
        """Kill an agent now."""
        ...

    def recover(self, agent_id: str) -> None:
        """Restart a crashed agent."""
        ...

    def close(self) -> None:
        """Close every transport and release what the harness holds."""
        ...


class SimHarness:
    """The simulated network, driven by a :class:`ManualClock`.

    Args:
        delay: delay of every link.
        loss: loss probability of every link.
        seed: the network's seed.
        lease: the liveliness lease.
    """

    def __init__(self, delay: Delay, loss: float = 0.0, seed: int = 7, lease: float = 2.0) -> None:
        self.clock = ManualClock()
        self.network = SimNetwork(self.clock, seed=seed, loss=loss, delay=delay, lease=lease)
        self.lease = lease
        self.lossless = loss == 0.0
        self.settle_time = 5.0
        self.by_reference = True
        self.liveness = "heard"

    def now(self) -> float:
        return self.clock.now()

    def attach(self, agent_id: str) -> Transport:
        return self.network.attach(agent_id)

    def wait(self, seconds: float) -> None:
        self.clock.advance(seconds)

    def partition(self, groups: Iterable[Iterable[str]]) -> None:
        self.network.partition(groups)

    def heal(self) -> None:
        self.network.heal()

    def crash(self, agent_id: str) -> None:
        self.network.crash(agent_id)

    def recover(self, agent_id: str) -> None:
        self.network.recover(agent_id)

    def close(self) -> None:
        pass


class _Restartable(Transport):
    """A zenoh transport that the harness can crash (close) and restart (a new session, same id and topics)."""

    def __init__(self, agent_id: str, make: Callable[[], ZenohTransport]) -> None:
        self._id = agent_id
        self._make = make
        self.inner: ZenohTransport | None = make()
        self._topics: list[str] = []
        self._closed = False

    @property
    def agent_id(self) -> str:
        return self._id

    def crash(self) -> None:
        if self.inner is not None:
            self.inner.close()
            self.inner = None

    def recover(self) -> None:
        self.inner = self._make()
        for topic in self._topics:
            self.inner.subscribe(topic)

    def publish(self, topic: str, payload: object, qos: QoS = QoS.BEST_EFFORT) -> None:
        if self.inner is not None or self._closed:
            self._live().publish(topic, payload, qos)

    def subscribe(self, topic: str) -> None:
        if self.inner is not None or self._closed:
            self._live().subscribe(topic)
        if topic not in self._topics:
            self._topics.append(topic)

    def poll(self) -> list[Envelope]:
        return self._live().poll() if self.inner is not None or self._closed else []

    def peers(self) -> frozenset[str]:
        return self.inner.peers() if self.inner is not None else frozenset()

    def close(self) -> None:
        self._closed = True
        if self.inner is not None:
            self.inner.close()

    def _live(self) -> ZenohTransport:
        if self.inner is None:
            raise ValueError(f"transport of {self._id!r} is closed; it can no longer work")
        return self.inner


class ZenohHarness:
    """Zenoh sessions in this process on loopback, every pair linked through its own relay.

    Agent ``j`` listens on its own port and connects to each earlier agent
    ``i`` through relay ``(i, j)``; a partition cuts the relays between groups.
    """

    def __init__(self) -> None:
        self.lease = 2.0
        self.lossless = True
        self.settle_time = 0.6
        self.by_reference = False
        self.liveness = "token"
        self._endpoints: dict[str, str] = {}
        self._relays: dict[tuple[str, str], LinkRelay] = {}
        self._transports: dict[str, _Restartable] = {}

    def now(self) -> float:
        return time.time()

    def attach(self, agent_id: str) -> Transport:
        [listen] = free_endpoints(1)
        earlier = list(self._endpoints.items())
        self._endpoints[agent_id] = listen
        relays = []
        for other, endpoint in earlier:
            relay = self._relays[(other, agent_id)] = LinkRelay(endpoint)
            relays.append(relay.endpoint)

        def make() -> ZenohTransport:
            return ZenohTransport(agent_id, listen=[listen], connect=relays, lease=self.lease, team="contract")

        transport = self._transports[agent_id] = _Restartable(agent_id, make)
        self._wait_linked(agent_id)
        return transport

    def _wait_linked(self, agent_id: str, timeout: float = 5.0) -> None:
        """Until the new agent sees every live earlier one (tokens are up), at most ``timeout`` seconds."""
        transport = self._transports[agent_id]
        others = {n for n, t in self._transports.items() if n != agent_id and t.inner is not None}
        end = time.monotonic() + timeout
        while time.monotonic() < end and not others <= transport.peers():
            time.sleep(0.01)

    def wait(self, seconds: float) -> None:
        time.sleep(seconds)

    def partition(self, groups: Iterable[Iterable[str]]) -> None:
        group_of = {name: i for i, group in enumerate(groups) for name in group}
        rest = len(group_of) + 1
        for (a, b), relay in self._relays.items():
            if group_of.get(a, rest) != group_of.get(b, rest):
                relay.cut()

    def heal(self) -> None:
        for relay in self._relays.values():
            relay.heal()
        for name in self._transports:
            if self._transports[name].inner is not None:
                self._wait_linked(name)  # zenoh reconnects by itself within its retry period

    def crash(self, agent_id: str) -> None:
        self._transports[agent_id].crash()

    def recover(self, agent_id: str) -> None:
        self._transports[agent_id].recover()
        self._wait_linked(agent_id)

    def close(self) -> None:
        for transport in self._transports.values():
            transport.close()
        for relay in self._relays.values():
            relay.close()


FACTORIES: dict[str, Callable[[], Harness]] = {
    "sim": lambda: SimHarness(Delay(0.005, 0.01)),
    "sim-instant": lambda: SimHarness(Delay(0.0)),
    "sim-lossy": lambda: SimHarness(Delay(0.002, 0.02, "exponential"), loss=0.3, seed=11),
    "zenoh": ZenohHarness,
}
"""Transport factories the contract suite runs against."""
