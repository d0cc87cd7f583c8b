"""The Panda's parallel gripper: open, close, attach, detach and the sensed grip.

A held object is an *attachment*: massless (kinematic) in physics while held,
re-posed with the end-effector by the arm every step, dynamic again after
:meth:`GripperMixin.detach`. :class:`~alica.worldsim.arm.Arm` inherits these methods.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import pose_inverse, pose_multiply
from alica.worldsim.objects import WorldObject

if TYPE_CHECKING:
    from alica.worldsim.arm_host import ArmMount

__all__ = ["FINGER_OPEN", "GRASP_TOLERANCE", "GRIP_FORCE", "GRIP_SLACK", "GripperMixin"]

logger = logging.getLogger(__name__)

#: How far (m) the point between the fingers may be from an object's bounding box for an attach.
GRASP_TOLERANCE = 0.015
#: How far (m) from the middle between the closed fingers a held object may stay: the fingers centre it
#: along their axis (see :meth:`GripperMixin.attach`) up to the give of their pads.
GRIP_SLACK = 0.001
#: The finger force (N) that :meth:`GripperMixin.grip_force` reports while holding.
GRIP_FORCE = 20.0
#: The opening of each finger (m) when the gripper is open.
FINGER_OPEN = 0.04
_RELEASE_GAP = 0.005
#: Objects within this horizontal distance (m) of one grasped or released are woken in pybullet.
WAKE_RADIUS = 0.3


class GripperMixin:
    """Gripper methods of :class:`~alica.worldsim.arm.Arm`.

    The gripper's own state is in this class's slots; :class:`~alica.worldsim.arm.Arm`
    sets it up and provides the robot, the body and the pose of the end-effector.
    """

    __slots__ = ("_fingers", "_force", "_grasp", "_held", "_joints_dirty", "_moved", "_slip_at")

    #: The opening of each finger (m).
    _fingers: float
    #: The finger force (N) commanded by the last :meth:`close`.
    _force: float
    #: The object in the gripper, or ``None``.
    _held: WorldObject | None
    #: The pose of the held object in the end-effector frame, or ``None``.
    _grasp: tuple[tuple[float, float, float], tuple[float, float, float, float]] | None
    #: The world time at which the grasp slips (see :mod:`alica.worldsim.faults`), or ``None``.
    _slip_at: float | None
    #: Whether the arm moved since the last step (its bodies must be re-posed).
    _moved: bool
    #: Whether the joints must be reset in pybullet.
    _joints_dirty: bool

    if TYPE_CHECKING:
        robot: ArmMount
        body_id: int
        _client: Any

        def ee_pose(self) -> tuple[np.ndarray, tuple[float, float, float, float]]: ...
        def _sync(self) -> None: ...

    def open(self) -> None:
        """Open the fingers; a held object is released (as :meth:`detach`)."""
        if self.robot.crashed:
            return
        if self._held is not None:
            self.detach()
        self._fingers = FINGER_OPEN
        self._moved = True
        self._joints_dirty = True

    def close(self, force: float | None = None) -> None:
        """Close the fingers, on the object between them if there is one (this does not attach it).

        Args:
            force: the finger force in newtons that :meth:`grip_force` senses while holding
                (default :data:`GRIP_FORCE`).

        Raises:
            WorldError: a force that is not a finite number > 0.
        """
        if force is not None and not (isinstance(force, (int, float)) and math.isfinite(force) and force > 0.0):
            raise WorldError(f"close of robot '{self.robot.name}' needs a finger force > 0 newtons, got {force!r}")
        if self.robot.crashed:
            return
        self._force = GRIP_FORCE if force is None else float(force)
        target = self._held or self._between_fingers()
        self._fingers = 0.0 if target is None else min(FINGER_OPEN, _half_width(target))
        self._moved = True
        self._joints_dirty = True

    def _between_fingers(self) -> WorldObject | None:
        ee = self.ee_pose()[0]
        best, best_d = None, GRASP_TOLERANCE
        for obj in self.robot.world.objects.values():
            if obj.movable:
                d = _aabb_distance(ee, *obj.aabb())
                if d <= best_d:
                    best, best_d = obj, d
        return best

    @property
    def held(self) -> WorldObject | None:
        """The object in the gripper, or ``None``."""
        return self._held

    def grip_force(self) -> float:
        """The sensed finger force while holding (the force of the last :meth:`close`, :data:`GRIP_FORCE` by default), 0 otherwise."""
        return self._force if self._held is not None else 0.0

    def attach(self, obj: WorldObject | str) -> bool:
        """Grasp ``obj`` (an object or its name) if the point between the fingers is at it.

        On success the object moves with the end-effector (kinematic, massless
        in physics) and the fingers close on it, centring it between them
        along their axis (to within :data:`GRIP_SLACK`). With a grasp slip set (see
        :mod:`alica.worldsim.faults`) the grasp may fail a short time later.

        Returns:
            Whether the object is now held (``False`` when it is out of the gripper's
            reach, :data:`GRASP_TOLERANCE`, or the robot is crashed).

        Raises:
            WorldError: an unknown, static or already held object, or the hand is not empty.
        """
        world = self.robot.world
        if isinstance(obj, str):
            if obj not in world.objects:
                raise WorldError(
                    f"attach: the world has no object '{obj}' (objects: {', '.join(sorted(world.objects))})"
                )
            obj = world.objects[obj]
        if not isinstance(obj, WorldObject) or world.objects.get(obj.name) is not obj:
            raise WorldError(f"attach: {obj!r} is not an object of this world")
        if not obj.movable:
            raise WorldError(f"attach: {obj.kind} '{obj.name}' is not graspable; only blocks and samples are")
        if self._held is obj:
            return True
        if self._held is not None:
            raise WorldError(f"attach: robot '{self.robot.name}' already holds '{self._held.name}'; detach it first")
        for other in world.robots.values():
            if other.arm is not None and other.arm.held is obj:
                raise WorldError(f"attach: '{obj.name}' is held by robot '{other.name}'")
        if self.robot.crashed:
            return False
        ee_pos, ee_quat = self.ee_pose()
        gap = _aabb_distance(ee_pos, *obj.aabb())
        if gap > GRASP_TOLERANCE:
            logger.info("robot %s: '%s' is %.3f m from the gripper; not grasped", self.robot.name, obj.name, gap)
            return False
        pos, quat = obj.pose()
        inv = pose_inverse(tuple(ee_pos), ee_quat)
        (gx, gy, gz), grasp_quat = pose_multiply(inv[0], inv[1], pos, quat)
        # The fingers close symmetrically (their joints are coupled): the first to touch the object pushes it
        # towards the middle until the other touches too. So it is held centred along the finger (tool y) axis,
        # up to the pads' give (GRIP_SLACK); along the tool x and z axes nothing pushes it.
        self._grasp = ((gx, max(-GRIP_SLACK, min(GRIP_SLACK, gy)), gz), grasp_quat)
        self._held = obj
        self._grip_physics(obj, True)
        self._fingers = min(FINGER_OPEN, _half_width(obj))
        self._moved = True
        self._joints_dirty = True
        self._slip_at = world.faults.draw_slip(world.now())
        world._version += 1
        return True

    def detach(self) -> WorldObject | None:
        """Release the held object: it is dynamic again and falls or rests. Returns it (or ``None``).

        The fingers open by 5 mm on each side so that they no longer touch it.
        """
        obj = self._held
        if obj is None:
            return None
        self._held = None
        self._grasp = None
        self._slip_at = None
        # The fingers ease off a little so that friction does not keep holding the object.
        self._fingers = max(self._fingers, min(FINGER_OPEN, _half_width(obj) + _RELEASE_GAP))
        self._moved = True
        self._joints_dirty = True
        self._sync()
        self._grip_physics(obj, False)
        self.robot.world._version += 1
        return obj

    def _grip_physics(self, obj: WorldObject, held: bool) -> None:
        """Make ``obj`` kinematic (massless, like the arm links, so they do not push each other) or dynamic again.

        Collision filters are left alone: changing them after ``saveState`` breaks ``restoreState``.
        """
        c = self._client
        c.changeDynamics(obj.body_id, -1, mass=0.0 if held else obj.mass)
        c.resetBaseVelocity(obj.body_id, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        # Wake the resting objects around it: one asleep on a block that is lifted away (grasped) would float
        # in mid-air, as pybullet does not wake bodies for a kinematic re-pose of what they rest on. Only
        # those within WAKE_RADIUS: woken ones stay awake for 2 s, and contacts of awake blocks cost steps.
        x, y, _ = obj.position()
        for other in self.robot.world.objects.values():
            if other.movable and other.mass > 0.0 and not (held and other is obj):
                ox, oy, _ = other.position()
                if math.hypot(ox - x, oy - y) <= WAKE_RADIUS:
                    c.changeDynamics(other.body_id, -1, activationState=c.ACTIVATION_STATE_WAKE_UP)


def _half_width(obj: WorldObject) -> float:
    if obj.half_extents[0] > 0.0:
        return min(obj.half_extents[0], obj.half_extents[1])
    return obj.radius


def _aabb_distance(point: Sequence[float] | npt.NDArray[np.float64], lo: np.ndarray, hi: np.ndarray) -> float:
    """Distance from a point to a box (0 inside)."""
    p = np.asarray(point, dtype=float)
    return float(np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0)))
