"""The robot interface: what a skill may use of a world, its robots and its objects.

Skills (:mod:`alica.skills`) act on a world through these Protocols, never on
pybullet directly. :class:`~alica.worldsim.world.World` satisfies
:class:`RobotWorld` (its robots :class:`MobileRobot`, its objects
:class:`WorldThing`; checked by mypy in :mod:`alica.worldsim` and by a test); a
real robot's driver satisfies them too by offering the same members.

The interface imports only plain data of the world and re-exports it, so a
skill needs no other module of the world for it: :class:`CameraImage` (what
``robot.camera()`` returns), :class:`RobotSpec` (``robot.spec``) and the
vocabularies :data:`SAMPLE_KINDS` and :data:`OBJECT_KINDS`.

Every object has a ``kind`` (one of :data:`OBJECT_KINDS`),
a ``radius`` and ``half_extents`` (zeros when they do not apply), so a skill
reads ``obj.kind`` instead of probing for it. Arms and their planning scenes
have an interface of their own (:mod:`alica.worldsim.arm_interface`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from alica.worldsim.camera_image import CameraImage
from alica.worldsim.kinds import OBJECT_KINDS, SAMPLE_KINDS
from alica.worldsim.robot_specs import RobotSpec

if TYPE_CHECKING:
    import numpy as np
    import trimesh

    from alica.worldsim.arm_interface import RobotArm
    from alica.worldsim.grid import Obstacle2D

__all__ = ["OBJECT_KINDS", "SAMPLE_KINDS", "CameraImage", "MobileRobot", "RobotSpec", "RobotWorld", "WorldThing"]

Position = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]


class WorldThing(Protocol):
    """An object of the world that is not a robot: a block, a sample, a rock, a table, a marker, the terrain."""

    @property
    def name(self) -> str:
        """Unique name in the world."""
        ...

    @property
    def kind(self) -> str:
        """``block``, ``sample``, ``rock``, ``table``, ``collection_point`` or ``terrain``."""
        ...

    @property
    def size(self) -> float:
        """Edge of a block, height of a sample or table, radius of a rock or marker."""
        ...

    @property
    def radius(self) -> float:
        """Footprint radius (samples, rocks, markers); 0 for boxes."""
        ...

    @property
    def half_extents(self) -> tuple[float, ...]:
        """Box half extents (blocks, tables); zeros otherwise."""
        ...

    def pose(self) -> tuple[Position, Quaternion]:
        """Position and quaternion ``(x, y, z, w)``."""
        ...

    def position(self) -> np.ndarray:
        """The position as an array of 3."""
        ...

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box ``(lower, upper)``."""
        ...

    def footprint(self) -> Obstacle2D | None:
        """The 2-D footprint now (``None`` for markers and terrain)."""
        ...

    def world_mesh(self) -> trimesh.Trimesh | None:
        """The rock's mesh at its pose (``None`` for other objects)."""
        ...


class MobileRobot(Protocol):
    """A robot base a skill drives, with its arm when it has one.

    ``bumped`` is true when the last drive command was stopped by a collision; a skill may reset it.
    """

    bumped: bool

    @property
    def name(self) -> str:
        """Unique name in the world (the agent's name)."""
        ...

    @property
    def spec(self) -> RobotSpec:
        """Radius, speeds and capabilities of its kind."""
        ...

    @property
    def arm(self) -> RobotArm | None:
        """The arm, or ``None``."""
        ...

    @property
    def pose(self) -> Position:
        """``(x, y, yaw)``."""
        ...

    @property
    def estimate(self) -> Position:
        """``(x, y, yaw)`` the robot believes it has (odometry corrected by localization); skills drive by it."""
        ...

    def set_estimate(self, pose: tuple[float, float, float]) -> None:
        """Correct the pose estimate (a localization's result)."""
        ...

    def lidar(self, n_rays: int, max_range: float | None = None) -> np.ndarray:
        """One 2-D lidar scan: ``n_rays`` ranges (m) over the full circle from the heading on; no hit reads ``max_range``."""
        ...

    def lidar_angles(self, n_rays: int) -> np.ndarray:
        """The angles of a scan's ``n_rays`` rays relative to the heading, in the order :meth:`lidar` gives them."""
        ...

    @property
    def lidar_noise(self) -> float:
        """Standard deviation in metres of the lidar's range noise."""
        ...

    def camera_pose(
        self, pose: tuple[float, float, float] | None = None, pan: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Where the camera is and how it is turned, ``(position, rotation world-from-camera)``, with the base
        at ``pose`` (default the true pose; pass :attr:`estimate` for what the robot believes), panned ``pan``."""
        ...

    def camera(
        self,
        *,
        width: int = 320,
        height: int = 240,
        fov: float | None = None,
        far: float | None = None,
        pan: float = 0.0,
        believed: bool = False,
        window: tuple[int, int, int, int] | None = None,
    ) -> CameraImage:
        """One picture of the camera (``pan`` radians left of the heading; ``believed``: its pose from the estimate;
        ``window``: only these pixels ``(u0, v0, u1, v1)`` of the frame)."""
        ...

    @property
    def crashed(self) -> bool:
        """Whether the robot is out (it no longer moves)."""
        ...

    def drive(self, v: float, w: float) -> None:
        """Drive at ``v`` m/s and turn at ``w`` rad/s until told otherwise."""
        ...

    def stop(self) -> None:
        """Stand still."""
        ...


@runtime_checkable
class RobotWorld(Protocol):
    """The world a skill acts on: its robots and objects by name, its bounds, its time, its obstacles."""

    @property
    def robots(self) -> Mapping[str, MobileRobot]:
        """Robots by name."""
        ...

    @property
    def objects(self) -> Mapping[str, WorldThing]:
        """Objects by name."""
        ...

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the field."""
        ...

    @property
    def seed(self) -> int:
        """The seed the world was built with (skills seed their own planners from it)."""
        ...

    def now(self) -> float:
        """The world's (simulated) time in seconds."""
        ...

    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        """Footprints of the obstacles lying in the world (held objects left out)."""
        ...

    def blocker(self, x: float, y: float, radius: float) -> str | None:
        """What a circle at ``(x, y)`` would overlap (``"robot 'r2'"``, ``"block 'a'"``), or ``None``.

        Robots, rocks, tables, blocks and samples count; held objects do not.
        """
        ...

    def blocks_facts(self) -> set[tuple[str, ...]]:
        """The IPC blocks-world facts now: ``on``, ``ontable``, ``clear``, ``holding``, ``handempty``.

        The simulator's perfect perception stands in here for what a robot
        would sense (an overhead camera, in effect); a real robot's driver
        answers from its own perception.
        """
        ...
