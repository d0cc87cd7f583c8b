"""putdown_spots reads only the robot interface, so it works on any RobotWorld, not just the simulator.

The driver below answers the interface's ``blocker`` with :func:`alica.worldsim.queries.blocker`, which reads only
the interface itself (as a real robot's driver may).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from alica.skills.arm_world import REACH
from alica.skills.blocks_rules import PUTDOWN_TURNS, putdown_spots
from alica.worldsim.arm_interface import RobotArm
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.interface import Position, Quaternion, RobotWorld
from alica.worldsim.queries import blocker
from alica.worldsim.robots import ROBOT_KINDS, RobotSpec


@dataclass
class _Robot:
    name: str
    pose: Position
    spec: RobotSpec = ROBOT_KINDS["scout"]
    arm: RobotArm | None = None
    crashed: bool = False
    bumped: bool = False

    def drive(self, v: float, w: float) -> None:
        pass

    def stop(self) -> None:
        pass


@dataclass
class _Rock:
    name: str
    x: float
    y: float
    radius: float = 0.1
    kind: str = "rock"
    size: float = 0.1
    half_extents: tuple[float, ...] = (0.0, 0.0, 0.0)

    def pose(self) -> tuple[Position, Quaternion]:
        return (self.x, self.y, 0.0), (0.0, 0.0, 0.0, 1.0)

    def position(self) -> np.ndarray:
        return np.array([self.x, self.y, 0.0])

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        r = self.radius
        return np.array([self.x - r, self.y - r, 0.0]), np.array([self.x + r, self.y + r, 2 * r])

    def footprint(self) -> Obstacle2D:
        return Obstacle2D("circle", self.x, self.y, radius=self.radius, name=self.name)

    def world_mesh(self) -> None:
        return None


@dataclass
class _Driver:
    """A robot world that is not the simulator (as a real robot's driver would offer it)."""

    robots: Mapping[str, _Robot]
    objects: Mapping[str, _Rock] = field(default_factory=dict)
    bounds: tuple[float, float, float, float] = (-5.0, -5.0, 5.0, 5.0)
    seed: int = 0

    def now(self) -> float:
        return 0.0

    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        return [o.footprint() for o in self.objects.values()]

    def blocker(self, x: float, y: float, radius: float) -> str | None:
        return blocker(self, x, y, radius)

    def blocks_facts(self) -> set[tuple[str, ...]]:
        return set()


def test_putdown_spots_on_a_robot_world_that_is_not_the_simulator() -> None:
    robot = _Robot("r1", (0.0, 0.0, 0.0))
    world = _Driver({"r1": robot}, {"rock": _Rock("rock", REACH, 0.0)})
    assert isinstance(world, RobotWorld)
    spots = putdown_spots(world, robot)
    # the rock straight ahead rules out the first spot; every turned one is free
    expected = [(REACH * math.cos(t), REACH * math.sin(t)) for t in PUTDOWN_TURNS[1:]]
    assert spots == expected
