"""Transports under test, behind one small interface the contract tests use.

A harness makes the transports of one team and injects faults. The contract
tests (``test_contract.py``) see only this interface, so a zenoh harness
(real processes, ``ip link`` partitions, sleeping instead of advancing a
clock) can be added to ``FACTORIES`` later without touching them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Protocol

from alica.clock import ManualClock
from alica.comm import Delay, SimNetwork, Transport


class Harness(Protocol):
    """One team's transports plus fault injection."""

    lease: float
    """The liveliness lease of the transports, in seconds."""
    lossless: bool
    """True when best-effort messages are never lost on a healthy link."""
    settle_time: float
    """Long enough for every message in flight to arrive (reliable ones retransmitted)."""

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


FACTORIES: dict[str, Callable[[], Harness]] = {
    "sim": lambda: SimHarness(Delay(0.005, 0.01)),
    "sim-instant": lambda: SimHarness(Delay(0.0)),
    "sim-lossy": lambda: SimHarness(Delay(0.002, 0.02, "exponential"), loss=0.3, seed=11),
}
"""Transport factories the contract suite runs against; a zenoh one joins later."""
