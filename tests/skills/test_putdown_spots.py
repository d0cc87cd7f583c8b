"""putdown_spots reads only the robot interface, so it works on any RobotWorld, not just the simulator.

The driver below answers the interface's ``blocker`` with :func:`alica.worldsim.queries.blocker`, which reads only
the interface itself (as a real robot's driver may).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.skills.arm_world import REACH
from alica.skills.blocks_rules import EDGE_ROOM, PUTDOWN_TURNS, putdown_spots, spread_spots
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


def _blocks(points: list[tuple[float, float]]) -> dict[str, _Rock]:
    return {f"b{i}": _Rock(f"b{i}", x, y, radius=0.03, kind="block") for i, (x, y) in enumerate(points)}


def test_spread_spots_keep_the_distance_from_blocks_and_reserved_points_nearest_first() -> None:
    robot = _Robot("r1", (0.0, 0.0, 0.0))
    world = _Driver({"r1": robot}, _blocks([(0.3, 0.0), (-1.0, 1.0)]), bounds=(-3.0, -3.0, 3.0, 3.0))
    spots = spread_spots(world, robot, 1.2, taken=[(0.0, -1.5)])
    assert spots
    for x, y in spots:
        assert math.hypot(x - 0.3, y) >= 1.2 and math.hypot(x + 1.0, y - 1.0) >= 1.2
        assert math.hypot(x, y + 1.5) >= 1.2
    # the spots the arm reaches from where the robot stands first (here none is far enough from
    # the block ahead), then the grid's, nearest the point the arm reaches straight ahead
    reach = [spot for spot in putdown_spots(world, robot) if spot in spots]
    assert spots[: len(reach)] == reach
    rest = [math.hypot(x - REACH, y) for x, y in spots[len(reach) :]]
    assert rest == sorted(rest)


def test_spread_spots_take_a_spot_within_the_arms_reach_first() -> None:
    robot = _Robot("r1", (0.0, 0.0, 0.0))
    world = _Driver({"r1": robot}, _blocks([(-0.5, 0.0)]), bounds=(-3.0, -3.0, 3.0, 3.0))
    assert spread_spots(world, robot, 0.4)[0] == (REACH, 0.0)


def test_spread_spots_are_none_where_the_field_has_no_room() -> None:
    robot = _Robot("r1", (0.0, 0.0, 0.0))
    world = _Driver({"r1": robot}, _blocks([(0.0, 0.0)]), bounds=(-1.5, -1.5, 1.5, 1.5))
    assert spread_spots(world, robot, 2.0) == []


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(st.floats(-2.5, 2.5), st.floats(-2.5, 2.5)), max_size=8),
    st.floats(0.2, 2.0),
    st.tuples(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0)),
)
def test_every_spread_spot_is_inside_the_field_clear_of_blocks_and_robots(
    points: list[tuple[float, float]], spread: float, at: tuple[float, float]
) -> None:
    robot = _Robot("r1", (at[0], at[1], 0.0))
    other = _Robot("r2", (1.0, -1.0, 0.0))
    world = _Driver({"r1": robot, "r2": other}, _blocks(points), bounds=(-3.0, -3.0, 3.0, 3.0))
    spots = spread_spots(world, robot, spread)
    for x, y in spots:
        assert -3.0 + EDGE_ROOM - 1e-9 <= x <= 3.0 - EDGE_ROOM + 1e-9
        assert -3.0 + EDGE_ROOM - 1e-9 <= y <= 3.0 - EDGE_ROOM + 1e-9
        assert all(math.hypot(x - bx, y - by) >= spread for bx, by in points)
        assert world.blocker(x, y, 0.15) is None
    assert len(set(spots)) == len(spots)
