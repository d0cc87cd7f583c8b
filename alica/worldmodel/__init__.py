"""The shared WorldModel: a replicated, converging store of the team's beliefs.

Each agent owns a :class:`WorldModel`; formulas read it directly (it is a
:class:`~alica.lang.BeliefBase`). Replicas converge whatever the order,
duplication or loss of the deltas they exchange, provided they eventually
exchange a :meth:`~WorldModel.snapshot` or answer each other's
:meth:`~WorldModel.digest` with :meth:`~WorldModel.missing_for`::

    scout, rover = WorldModel("scout"), WorldModel("rover")
    scout.set("pos", "scout", value=(1.0, 2.0))
    scout.assert_fact("found", "a")
    rover.merge(scout.take_delta())
    assert rover.holds("found", "a")
"""

from __future__ import annotations

from alica.worldmodel.delta import Add, Delta, Digest, Key, Write
from alica.worldmodel.encoding import order_key
from alica.worldmodel.protocol import ReplicaLike, WorldModelLike
from alica.worldmodel.replica import Replica
from alica.worldmodel.stamp import LamportClock, Stamp
from alica.worldmodel.state import ReplicaState
from alica.worldmodel.store import WorldModel

__all__ = [
    "Add",
    "Delta",
    "Digest",
    "Key",
    "LamportClock",
    "Replica",
    "ReplicaLike",
    "ReplicaState",
    "Stamp",
    "WorldModel",
    "WorldModelLike",
    "Write",
    "order_key",
]
