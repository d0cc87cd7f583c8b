"""When a world may skip pybullet's step: nothing can move a body (``World(rest_when_still=True)``).

The world asks :meth:`Resting.needed` before each physics step. A step is
needed while bodies were added, removed, grasped or released since the last
question, while an arm follows a path, and until every free object has been
still for :data:`SETTLE_STEPS` steps in a row.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Protocol

from alica.worldsim.objects import WorldObject

__all__ = ["SETTLE_STEPS", "STILL_SPEED", "STILL_SPIN", "Resting"]

#: Physics steps every free object must be still before a world with ``rest_when_still`` skips pybullet's step.
SETTLE_STEPS = 120
#: Speed (m/s) and spin (rad/s) below which a free object counts as still.
STILL_SPEED = 1e-3
STILL_SPIN = 1e-2


class _Moving(Protocol):
    """An arm as resting sees it: following a path or not."""

    @property
    def _path(self) -> Any: ...


class Resting:
    """Whether the next physics step of one world can change anything.

    Args:
        client: the world's pybullet client.
        objects: the world's objects by name (the world's own dict, read at each question).
        held: the bodies the arms hold now (they move with their arm, not by physics).
    """

    __slots__ = ("_client", "_held", "_objects", "_seen_version", "_still")

    def __init__(self, client: Any, objects: Mapping[str, WorldObject], held: Callable[[], set[int]]) -> None:
        self._client = client
        self._objects = objects
        self._held = held
        self._still = 0
        self._seen_version = -1

    def needed(self, version: int, arms: Sequence[_Moving]) -> bool:
        """Whether to run pybullet's step now, given the world's body ``version`` and its arms."""
        if version != self._seen_version or any(arm._path is not None for arm in arms):
            self._seen_version = version
            self._still = 0
            return True
        if self._still >= SETTLE_STEPS:
            return False
        self._still = 0 if self._anything_moving() else self._still + 1
        return True

    def _anything_moving(self) -> bool:
        held = self._held()
        velocity = self._client.getBaseVelocity
        for obj in self._objects.values():
            if obj.mass > 0.0 and obj.body_id not in held:
                (vx, vy, vz), (wx, wy, wz) = velocity(obj.body_id)
                if vx * vx + vy * vy + vz * vz > STILL_SPEED**2 or wx * wx + wy * wy + wz * wz > STILL_SPIN**2:
                    return True
        return False
