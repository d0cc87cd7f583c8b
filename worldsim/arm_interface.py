"""The arm interface: what a skill may use of a robot's arm and of the arm's planning scene.

Skills (:mod:`alica.skills`) reach an arm as ``robot.arm`` (a :class:`RobotArm`,
see :class:`~alica.worldsim.interface.MobileRobot`) and plan its motion in the
scene the arm gives them (:meth:`RobotArm.planning_scene`, an
:class:`ArmPlanningScene`), never on pybullet directly. The simulator's
:class:`~alica.worldsim.arm.Arm` and :class:`~alica.worldsim.arm_scene.ArmScene`
satisfy these Protocols (checked by mypy below); a real arm's driver offers the
same members, with a planning scene of its own.

The values crossing this seam are plain data of :mod:`alica.worldsim.geometry`:
poses ``((x, y, z), (qx, qy, qz, qw))``, :class:`~alica.worldsim.geometry.Box`
for obstacles and held objects, joint configurations as arrays of 7.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from alica.worldsim.geometry import Box, Pose, Quat, Vec3
    from alica.worldsim.interface import WorldThing

__all__ = ["ArmPlanningScene", "RobotArm"]


class ArmPlanningScene(Protocol):
    """A planning copy of one arm among box obstacles: joint limits, kinematics and collision checks.

    Every query sets the joint values it needs; the world that simulates is
    never touched. Not thread-safe: one planner at a time.
    """

    @property
    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` arrays of the 7 arm joints' limits in radians."""
        ...

    @property
    def rest_q(self) -> np.ndarray:
        """The IK seed and rest configuration."""
        ...

    @property
    def home_q(self) -> np.ndarray:
        """The transport configuration."""
        ...

    @property
    def reach(self) -> float:
        """Upper bound of the distance from the shoulder to the tool frame, metres."""
        ...

    @property
    def max_grasp_width(self) -> float:
        """Largest object width the open gripper can straddle, metres."""
        ...

    @property
    def margin(self) -> float:
        """Safety distance (m) by which obstacles and the ground are inflated in collision checks."""
        ...

    @property
    def obstacles(self) -> tuple[Box, ...]:
        """The current obstacle boxes (as given, not inflated)."""
        ...

    def set_obstacles(self, boxes: Iterable[Box]) -> None:
        """Replace the obstacles (names unique)."""
        ...

    def base_pose(self) -> Pose:
        """World pose of the arm's base frame."""
        ...

    def set_base_pose(self, pose: Pose) -> None:
        """Move the arm's base (after the mobile base drove)."""
        ...

    def shoulder_position(self) -> Vec3:
        """World position of the shoulder, the centre of the reach sphere."""
        ...

    def random_configuration(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """A uniformly random configuration inside the joint limits (not checked for collisions)."""
        ...

    def fk(self, q: Sequence[float] | np.ndarray) -> Pose:
        """World pose of the tool frame at configuration ``q``."""
        ...

    def in_collision(self, q: Sequence[float] | np.ndarray, held: Box | None = None) -> bool:
        """Whether ``q`` collides (arguments checked); ``held``: the object in the gripper as a box in the tool frame."""
        ...

    def collides(self, q: Sequence[float] | np.ndarray, held: Box | None = None) -> bool:
        """:meth:`in_collision` without argument checks (for planners' inner loops)."""
        ...

    def set_joints(self, q: Sequence[float] | np.ndarray) -> None:
        """Set the 7 arm joints of the planning copy (no checks)."""
        ...

    def current_tool_pose(self) -> Pose:
        """World pose of the tool frame at the joint values last set."""
        ...

    def ik_round(self, position: Vec3, orientation: Quat, *, damping: float, iterations: int) -> np.ndarray:
        """A few iterations of damped least squares IK from the joint values last set: 7 joint values, unchecked."""
        ...


class RobotArm(Protocol):
    """A robot's arm with a parallel gripper, as a skill drives it."""

    @property
    def mount_offset(self) -> tuple[float, float, float]:
        """``(x, y, z)`` of the arm's base in the robot's base frame (z from the ground)."""
        ...

    @property
    def held(self) -> WorldThing | None:
        """The object attached to the gripper, or ``None``."""
        ...

    @property
    def busy(self) -> bool:
        """Whether the arm is still following a path."""
        ...

    def q(self) -> np.ndarray:
        """The 7 joint values now."""
        ...

    def base_pose(self) -> Pose:
        """World pose of the arm's base frame now."""
        ...

    def follow(self, path: np.ndarray, duration: float | None = None) -> float:
        """Follow a joint path over the coming simulated time; returns its duration (s)."""
        ...

    def stop(self) -> None:
        """Stop where the arm is."""
        ...

    def open(self) -> None:
        """Open the fingers."""
        ...

    def close(self, force: float | None = None) -> None:
        """Close the fingers with ``force`` newtons (None: the gripper's default)."""
        ...

    def attach(self, obj: str) -> bool:
        """Take the object named ``obj`` between the fingers as held; whether it was there to take."""
        ...

    def detach(self) -> WorldThing | None:
        """Let the held object go; returns it (None when nothing was held)."""
        ...

    def grip_force(self) -> float:
        """The finger force on the held object, newtons (0 when nothing is held)."""
        ...

    def planning_scene(self) -> ArmPlanningScene:
        """The arm's planning scene, its base at the arm's base now (obstacles as the last planner left them)."""
        ...


if TYPE_CHECKING:
    from alica.worldsim.arm import Arm
    from alica.worldsim.arm_scene import ArmScene

    def _arm_is_a_robot_arm(arm: Arm) -> RobotArm:
        return arm  # mypy proves that the simulator's Arm satisfies the arm interface

    def _scene_is_a_planning_scene(scene: ArmScene) -> ArmPlanningScene:
        return scene  # and that its planning scene satisfies the scene interface
