"""What the steps of the Pickup and Putdown plans hand on in the agent's scratch space, typed.

Each record has its slot (:class:`~alica.skills.scratch.ScratchSlot`) under the
key the steps (:mod:`alica.skills.arm_steps`) always used, so a type checker sees
who writes what and who reads it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from alica.skills.scratch import ScratchSlot

__all__ = [
    "ALIGNED",
    "ARM_RETREAT",
    "GRASP",
    "HELD",
    "NAMES",
    "PLACED",
    "TRIED_SIDES",
    "Aligned",
    "GraspCount",
    "GraspedNames",
    "Held",
    "Placed",
    "Retreat",
    "TriedSides",
]


@dataclass(slots=True)
class GraspCount:
    """The grasp attempts on an object: Grasp counts them, OpenGripper marks the next one a retry."""

    object: str
    attempts: int
    retry: bool = False


@dataclass(frozen=True, slots=True)
class Held:
    """What Grasp took: the plan's name for it and the world's."""

    object: str
    world: str


@dataclass(frozen=True, slots=True)
class Retreat:
    """The rest of the last arm plan of ``robot`` (the lift after a grasp, the retreat after a placement)."""

    robot: str
    paths: list[np.ndarray]


@dataclass(frozen=True, slots=True)
class TriedSides:
    """Stand-off points from which Grasp found no arm plan for ``object``."""

    object: str
    sides: list[tuple[float, float]]


@dataclass(frozen=True, slots=True)
class Aligned:
    """Where AlignWithObject left the robot: facing ``object`` at ``site``, at the estimated ``pose``."""

    object: str
    site: tuple[float, float]
    pose: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Placed:
    """Where MoveArmToPlace set ``object`` down (the arm's place point, as the robot believes it)."""

    object: str
    place: tuple[float, float]


@dataclass(slots=True)
class GraspedNames:
    """The world object each name a plan gave Grasp stands for (perception's names for samples)."""

    names: dict[str, str] = field(default_factory=dict)


GRASP: ScratchSlot[GraspCount] = ScratchSlot("grasp", GraspCount, "Grasp")
HELD: ScratchSlot[Held] = ScratchSlot("held", Held, "Grasp")
ARM_RETREAT: ScratchSlot[Retreat] = ScratchSlot("arm_retreat", Retreat, "Grasp or MoveArmToPlace")
TRIED_SIDES: ScratchSlot[TriedSides] = ScratchSlot("tried_sides", TriedSides, "Grasp")
ALIGNED: ScratchSlot[Aligned] = ScratchSlot("aligned", Aligned, "AlignWithObject")
NAMES: ScratchSlot[GraspedNames] = ScratchSlot("names", GraspedNames, "Grasp")
PLACED: ScratchSlot[Placed] = ScratchSlot("placed", Placed, "MoveArmToPlace")
