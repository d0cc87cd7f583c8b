"""What an arm and its gripper read of the robot that carries them and of its world.

:mod:`alica.worldsim.arm` and :mod:`alica.worldsim.gripper` work on an
:class:`ArmMount`, not on the concrete :class:`~alica.worldsim.robots.Robot`
and :class:`~alica.worldsim.world.World` (which satisfy these Protocols,
checked by mypy where the robot hands itself to its arm): so the arm depends
on the members it reads, and the robot imports the arm without the arm
importing the robot or the world back.

These are the simulator's own seams (pybullet bodies, the world's bookkeeping);
skills see an arm through :mod:`alica.worldsim.arm_interface` instead.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from alica.worldsim.arm_scene import ArmPlanningModel
    from alica.worldsim.objects import WorldObject

__all__ = ["ArmMount", "ArmWorld"]


class _PeerArm(Protocol):
    """Another arm of the world, as an arm sees it: its model file, its planning model, what it holds."""

    @property
    def urdf_path(self) -> str:
        """The arm's URDF file."""
        ...

    @property
    def planning_model(self) -> ArmPlanningModel | None:
        """The planning model its scene uses, or ``None`` before its first planning scene."""
        ...

    @property
    def held(self) -> WorldObject | None:
        """The object in its gripper, or ``None``."""
        ...


class _PeerRobot(Protocol):
    """A robot of the world, as an arm sees it: its name and its arm."""

    @property
    def name(self) -> str:
        """Unique name in the world."""
        ...

    @property
    def arm(self) -> _PeerArm | None:
        """Its arm, or ``None``."""
        ...


class _GraspSlips(Protocol):
    """The world's fault settings, as a grasp sees them."""

    def draw_slip(self, now: float) -> float | None:
        """The time a new grasp will slip, or ``None``."""
        ...


class ArmWorld(Protocol):
    """The world as an arm reads it: its pybullet client and loading options, objects, robots, faults and time."""

    #: A number that changes whenever bodies are added, removed, grasped or released (a cache key);
    #: a grasp and a release count it up.
    _version: int

    @property
    def client(self) -> Any:
        """The world's own pybullet client."""
        ...

    @property
    def arm_visuals(self) -> bool:
        """Whether the arms' detailed visual meshes are loaded."""
        ...

    @property
    def quiet(self) -> bool:
        """Whether pybullet's prints are hidden while loading models."""
        ...

    @property
    def seed(self) -> int:
        """The world's seed (it seeds the arms' planning scenes)."""
        ...

    @property
    def objects(self) -> Mapping[str, WorldObject]:
        """The objects by name."""
        ...

    @property
    def robots(self) -> Mapping[str, _PeerRobot]:
        """The robots by name."""
        ...

    @property
    def faults(self) -> _GraspSlips:
        """The fault settings (a grasp may slip)."""
        ...

    def now(self) -> float:
        """The simulated time in seconds."""
        ...


class ArmMount(Protocol):
    """The robot that carries an arm, as the arm sees it: its name, pose, power and world."""

    @property
    def name(self) -> str:
        """Unique name in the world."""
        ...

    @property
    def pose(self) -> tuple[float, float, float]:
        """The true ``(x, y, yaw)`` of the base."""
        ...

    @property
    def crashed(self) -> bool:
        """A crashed robot's arm ignores commands."""
        ...

    @property
    def world(self) -> ArmWorld:
        """The world the robot lives in."""
        ...
