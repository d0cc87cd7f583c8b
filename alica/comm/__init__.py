"""Team communication: the transport interface, an in-memory simulated network, and zenoh.

The engine talks to a :class:`Transport` only; :class:`SimNetwork` gives every
agent a :class:`SimTransport` on a seeded, simulated-time network with loss,
delay, partitions and crashes; :class:`alica.comm.zenoh_transport.ZenohTransport`
connects agents in separate processes or hosts over eclipse-zenoh (imported
on demand, so the simulation does not load zenoh). See ``docs/comm.md``.
"""

from __future__ import annotations

from alica.comm.delay import Delay, Link
from alica.comm.faults import PartitionHandle
from alica.comm.simnet import SimNetwork
from alica.comm.simtransport import SimTransport
from alica.comm.stats import NetStats
from alica.comm.trace import Observer
from alica.comm.transport import Envelope, QoS, Transport

__all__ = [
    "Delay",
    "Envelope",
    "Link",
    "NetStats",
    "Observer",
    "PartitionHandle",
    "QoS",
    "SimNetwork",
    "SimTransport",
    "Transport",
]
