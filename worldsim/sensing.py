"""What a robot's sensors, camera and odometry read of their robot and its world.

:mod:`alica.worldsim.sensors`, :mod:`alica.worldsim.robot_camera` and
:mod:`alica.worldsim.odometry` work on a :class:`SensingRobot`, not on the
concrete :class:`~alica.worldsim.robots.Robot` and
:class:`~alica.worldsim.world.World` (which satisfy these Protocols, checked
by mypy where the robot hands itself to its odometry): so the sensors depend
on the robot's members they read, and the robot and world import the sensors
without the sensors importing them back.

These are the simulator's own seams (pybullet bodies and the world's seeded
draws); skills see robots through :mod:`alica.worldsim.interface` instead.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    import numpy as np

    from alica.worldsim.noise import SensorNoise
    from alica.worldsim.objects import WorldObject
    from alica.worldsim.robot_specs import RobotSpec

__all__ = ["SensingRobot", "SensingWorld"]


class SensingWorld(Protocol):
    """The world as a robot's sensors read it: its pybullet client, objects, noise, seeded draws and time."""

    @property
    def client(self) -> Any:
        """The world's own pybullet client."""
        ...

    @property
    def closed(self) -> bool:
        """Whether the world was closed (nothing can be rendered any more)."""
        ...

    @property
    def noise(self) -> SensorNoise:
        """The sensors' noise now."""
        ...

    @property
    def rng(self) -> np.random.Generator:
        """The world's seeded generator: every noise draw comes from it."""
        ...

    @property
    def objects(self) -> Mapping[str, WorldObject]:
        """The objects by name."""
        ...

    @property
    def _version(self) -> int:
        """A number that changes whenever bodies are added, removed, grasped or released (a cache key)."""
        ...

    def _held_bodies(self) -> set[int]:
        """The bodies of the objects the arms hold now."""
        ...

    def now(self) -> float:
        """The simulated time in seconds."""
        ...


class _Hand(Protocol):
    """A robot's arm as its sensors see it: a body, and perhaps a held object's."""

    @property
    def body_id(self) -> int:
        """The arm's pybullet body."""
        ...

    @property
    def held(self) -> WorldObject | None:
        """The object in the gripper, or ``None``."""
        ...


class SensingRobot(Protocol):
    """A robot as its sensors, camera and odometry see it: its spec, its poses, its own bodies, its world."""

    @property
    def name(self) -> str:
        """Unique name in the world."""
        ...

    @property
    def spec(self) -> RobotSpec:
        """Radius, heights, ranges and capabilities of its kind."""
        ...

    @property
    def pose(self) -> tuple[float, float, float]:
        """The true ``(x, y, yaw)``."""
        ...

    @property
    def estimate(self) -> tuple[float, float, float]:
        """The ``(x, y, yaw)`` the robot believes it has."""
        ...

    @property
    def body_id(self) -> int:
        """The pybullet body of the base."""
        ...

    @property
    def arm(self) -> _Hand | None:
        """The arm, or ``None``."""
        ...

    @property
    def world(self) -> SensingWorld:
        """The world the robot lives in."""
        ...
