"""The Franka Panda arm and gripper mounted on a robot base.

The arm is ``franka_panda/panda.urdf`` from ``pybullet_data``, loaded with a
fixed base and moved kinematically: after every physics step its base is put
at the mount on the robot and its joints at the commanded configuration
(exact tracking; the joint motors are off). A held object is an attachment:
kinematic (massless) while held and re-posed with the end-effector, dynamic
again after :meth:`Arm.detach`.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import pybullet_data

from worldsim._quiet import quiet_stdout
from worldsim.errors import WorldError
from worldsim.geometry import pose_inverse, pose_multiply, yaw_to_quat
from worldsim.objects import ARM_GROUP, MOVABLE_GROUP, WorldObject

if TYPE_CHECKING:
    from worldsim.robots import Robot

__all__ = ["GRASP_TOLERANCE", "GRIP_FORCE", "PANDA_URDF", "Arm"]

logger = logging.getLogger(__name__)

#: The arm model, relative to ``pybullet_data.getDataPath()``.
PANDA_URDF = "franka_panda/panda.urdf"
#: How far (m) the point between the fingers may be from an object's bounding box for :meth:`Arm.attach`.
GRASP_TOLERANCE = 0.015
#: The finger force (N) that :meth:`Arm.grip_force` reports while holding.
GRIP_FORCE = 20.0

_ARM_JOINTS = (0, 1, 2, 3, 4, 5, 6)
_FINGER_JOINTS = (9, 10)
_EE_LINK = 11  # panda_grasptarget, between the fingertips
_FINGER_OPEN = 0.04
_RELEASE_GAP = 0.005
_HOME_Q = (0.0, -1.1, 0.0, -2.75, 0.0, 1.75, 0.785)


class Arm:
    """A Panda arm with a parallel gripper on a robot (``robot.arm``).

    Attributes:
        robot: the robot that carries it.
        body_id: the pybullet body of the arm.
        urdf_path: the URDF file (for planners that load their own copy).
        mount_offset: ``(x, y, z)`` of the arm base in the robot base frame (z from the ground).
        joint_indices: the seven arm joints.
        finger_indices: the two finger joints.
        ee_link: the link index of ``panda_grasptarget``, between the fingertips.
        joint_limits: ``(lower, upper)`` arrays of the seven joints.
        max_velocity: the joint speed limits in rad/s.
        home_q: the transport pose (folded above the base).
    """

    __slots__ = (
        "_all_joints",
        "_base_dirty",
        "_client",
        "_fingers",
        "_grasp",
        "_held",
        "_inertial",
        "_joints_dirty",
        "_moved",
        "_path",
        "_q",
        "_reset_joints",
        "_seg",
        "_slip_at",
        "_t",
        "_times",
        "body_id",
        "ee_link",
        "finger_indices",
        "home_q",
        "joint_indices",
        "joint_limits",
        "max_velocity",
        "mount_offset",
        "robot",
        "urdf_path",
    )

    def __init__(self, robot: Robot, mount_offset: Sequence[float]) -> None:
        world = robot.world
        c = world.client
        self.robot = robot
        self._client = c
        self.urdf_path = os.path.join(pybullet_data.getDataPath(), PANDA_URDF)
        self.mount_offset: tuple[float, float, float] = (
            float(mount_offset[0]),
            float(mount_offset[1]),
            float(mount_offset[2]),
        )
        with quiet_stdout(world.quiet):
            self.body_id: int = c.loadURDF(self.urdf_path, useFixedBase=True, flags=c.URDF_USE_INERTIA_FROM_FILE)
        self.joint_indices: tuple[int, ...] = _ARM_JOINTS
        self.finger_indices: tuple[int, ...] = _FINGER_JOINTS
        self.ee_link = _EE_LINK
        info = [c.getJointInfo(self.body_id, j) for j in _ARM_JOINTS]
        self.joint_limits: tuple[np.ndarray, np.ndarray] = (
            np.array([i[8] for i in info]),
            np.array([i[9] for i in info]),
        )
        self.max_velocity = np.array([i[11] for i in info])
        self.home_q = np.array(_HOME_Q)
        dyn = c.getDynamicsInfo(self.body_id, -1)
        self._inertial = (tuple(dyn[3]), tuple(dyn[4]))
        # Kinematic arm: no motors, massless links (gravity cannot move it between our re-poses),
        # and contacts only with movable objects (which it pushes like a moving static body).
        n = c.getNumJoints(self.body_id)
        c.setJointMotorControlArray(self.body_id, list(range(n)), c.VELOCITY_CONTROL, forces=[0.0] * n)
        for link in range(-1, n):
            c.changeDynamics(self.body_id, link, mass=0.0)
            c.setCollisionFilterGroupMask(self.body_id, link, ARM_GROUP, MOVABLE_GROUP)
        self._reset_joints = c.resetJointStatesMultiDof
        self._all_joints = list(_ARM_JOINTS + _FINGER_JOINTS)
        self._q = self.home_q.copy()
        self._fingers = _FINGER_OPEN
        self._path: np.ndarray | None = None
        self._times: np.ndarray | None = None
        self._t = 0.0
        self._seg = 0
        self._held: WorldObject | None = None
        self._grasp: tuple[Any, Any] | None = None
        self._slip_at: float | None = None
        self._base_dirty = True
        self._moved = True
        self._joints_dirty = True
        self._sync()

    # ----------------------------------------------------------------- poses
    def base_pose(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """World position and quaternion of the arm base frame (``panda_link0``)."""
        x, y, yaw = self.robot.pose
        ox, oy, oz = self.mount_offset
        c, s = math.cos(yaw), math.sin(yaw)
        return (x + c * ox - s * oy, y + s * ox + c * oy, oz), yaw_to_quat(yaw)

    def q(self) -> np.ndarray:
        """The seven joint positions (a copy)."""
        return self._q.copy()

    def ee_pose(self) -> tuple[np.ndarray, tuple[float, float, float, float]]:
        """World position and quaternion ``(x, y, z, w)`` of the end-effector (between the fingertips)."""
        state = self._client.getLinkState(self.body_id, self.ee_link, computeForwardKinematics=1)
        return np.asarray(state[4], dtype=float), tuple(state[5])  # type: ignore[return-value]

    def finger_opening(self) -> float:
        """The gap between the fingers in metres."""
        return 2.0 * self._fingers

    # -------------------------------------------------------------- commands
    def _check_q(self, q: Any, what: str) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.ndim != 2 or q.shape[1] != 7 or len(q) == 0:
            raise WorldError(
                f"{what} of robot '{self.robot.name}' needs an (N x 7) array of joint positions, got shape {q.shape}"
            )
        if not np.all(np.isfinite(q)):
            raise WorldError(f"{what} of robot '{self.robot.name}' has non-finite joint positions")
        lo, hi = self.joint_limits
        bad = np.argwhere((q < lo - 1e-6) | (q > hi + 1e-6))
        if len(bad):
            row, joint = (int(v) for v in bad[0])
            raise WorldError(
                f"{what} of robot '{self.robot.name}': joint {joint + 1} = {q[row, joint]:.4f} at row {row} is outside "
                f"its limits [{lo[joint]:.4f}, {hi[joint]:.4f}]; clip or re-plan the path"
            )
        return np.clip(q, lo, hi)

    def set_q(self, q: Sequence[float] | np.ndarray) -> None:
        """Put the joints at ``q`` at once (stops a running :meth:`follow`).

        Raises:
            WorldError: not 7 finite values within the joint limits.
        """
        self._q = self._check_q(np.reshape(np.asarray(q, dtype=float), (1, -1)), "set_q")[0]
        self._path = None
        self._moved = True
        self._joints_dirty = True
        self._sync()

    def min_duration(self, path: np.ndarray) -> float:
        """The shortest time to follow ``path`` from the current configuration at the joint speed limits."""
        path = self._check_q(np.reshape(np.asarray(path, dtype=float), (-1, 7)), "min_duration")
        points = np.vstack([self._q, path])
        return float((np.abs(np.diff(points, axis=0)) / self.max_velocity).max(axis=1).sum())

    def follow(self, path: np.ndarray, duration: float | None = None) -> float:
        """Move along a joint path over the coming ``world.step`` calls.

        The arm goes from its current configuration through every row of
        ``path`` with timing proportional to each segment's slowest joint.
        A ``duration`` shorter than the joint speed limits allow is stretched.
        A crashed robot ignores the call.

        Args:
            path: an (N x 7) array of joint positions (one row is allowed).
            duration: seconds for the whole path; ``None`` moves at the speed limits.

        Returns:
            The duration actually used.

        Raises:
            WorldError: a malformed path, joints outside their limits, or a negative duration.
        """
        if self.robot.crashed:
            return 0.0
        path = self._check_q(
            np.reshape(np.asarray(path, dtype=float), (-1, 7)) if np.ndim(path) == 1 else path, "follow"
        )
        if duration is not None and not (duration >= 0.0 and math.isfinite(duration)):
            raise WorldError(f"follow of robot '{self.robot.name}' needs a duration >= 0 seconds, got {duration}")
        points = np.vstack([self._q, path])
        seg = (np.abs(np.diff(points, axis=0)) / self.max_velocity).max(axis=1)
        fastest = float(seg.sum())
        if fastest <= 1e-12:
            self._q = points[-1].copy()
            self._path = None
            self._moved = True
            self._joints_dirty = True
            return 0.0
        used = fastest if duration is None else max(float(duration), fastest)
        if duration is not None and duration < fastest - 1e-9:
            logger.debug(
                "robot %s: path needs %.3f s at the joint speed limits, not %.3f s", self.robot.name, fastest, duration
            )
        self._path = points
        self._times = np.concatenate([[0.0], np.cumsum(seg)]) * (used / fastest)
        self._t = 0.0
        self._seg = 0
        return used

    @property
    def busy(self) -> bool:
        """Whether a :meth:`follow` is under way."""
        return self._path is not None

    def stop(self) -> None:
        """Stop where the arm is."""
        self._path = None

    # --------------------------------------------------------------- gripper
    def open(self) -> None:
        """Open the fingers; a held object is released (as :meth:`detach`)."""
        if self.robot.crashed:
            return
        if self._held is not None:
            self.detach()
        self._fingers = _FINGER_OPEN
        self._moved = True
        self._joints_dirty = True

    def close(self) -> None:
        """Close the fingers, on the object between them if there is one (this does not attach it)."""
        if self.robot.crashed:
            return
        target = self._held or self._between_fingers()
        self._fingers = 0.0 if target is None else min(_FINGER_OPEN, _half_width(target))
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
        """The sensed finger force: :data:`GRIP_FORCE` while holding, 0 otherwise."""
        return GRIP_FORCE if self._held is not None else 0.0

    def attach(self, obj: WorldObject | str) -> bool:
        """Grasp ``obj`` (an object or its name) if the point between the fingers is at it.

        On success the object moves with the end-effector (kinematic, massless
        in physics) and the fingers close on it. With a grasp slip set (see
        :mod:`worldsim.faults`) the grasp may fail a short time later.

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
            if other.arm is not None and other.arm._held is obj:
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
        self._grasp = pose_multiply(inv[0], inv[1], pos, quat)
        self._held = obj
        self._grip_physics(obj, True)
        self._fingers = min(_FINGER_OPEN, _half_width(obj))
        self._moved = True
        self._joints_dirty = True
        self._slip_at = world.faults._draw_slip(world.now())
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
        self._fingers = max(self._fingers, min(_FINGER_OPEN, _half_width(obj) + _RELEASE_GAP))
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
        if not held:
            c.changeDynamics(obj.body_id, -1, activationState=c.ACTIVATION_STATE_WAKE_UP)

    # ------------------------------------------------------------- internals
    def _base_moved(self) -> None:
        self._base_dirty = True
        self._moved = True

    def _sync(self) -> None:
        """Put the pybullet bodies where the kinematic state says (arm base, joints, held object)."""
        c = self._client
        if self._base_dirty:
            pos, quat = self.base_pose()
            com = pose_multiply(pos, quat, *self._inertial)
            c.resetBasePositionAndOrientation(self.body_id, com[0], com[1])
            self._base_dirty = False
        if not self._moved:
            return
        if self._joints_dirty:
            q = self._q.tolist()
            f = self._fingers
            self._reset_joints(
                self.body_id, self._all_joints, [[q[0]], [q[1]], [q[2]], [q[3]], [q[4]], [q[5]], [q[6]], [f], [f]]
            )
            self._joints_dirty = False
        if self._held is not None and self._grasp is not None:
            state = c.getLinkState(self.body_id, self.ee_link, computeForwardKinematics=1)
            pos, quat = pose_multiply(state[4], state[5], *self._grasp)
            c.resetBasePositionAndOrientation(self._held.body_id, pos, quat)
        self._moved = False

    def _update(self, dt: float, now: float) -> None:
        """One physics step: advance the path, re-pose everything, let a slipping object go."""
        path = self._path
        if path is not None and self._times is not None:
            self._t += dt
            times = self._times
            if self._t >= times[-1]:
                self._q = path[-1].copy()
                self._path = None
            else:
                k = self._seg
                while times[k + 1] <= self._t:
                    k += 1
                self._seg = k
                a = (self._t - times[k]) / (times[k + 1] - times[k])
                self._q = path[k] + a * (path[k + 1] - path[k])
            self._moved = True
            self._joints_dirty = True
        self._sync()
        if self._slip_at is not None and now >= self._slip_at and self._held is not None:
            logger.info("robot %s: '%s' slipped out of the gripper", self.robot.name, self._held.name)
            self.detach()

    def _state(self) -> dict[str, Any]:
        return {
            "q": self._q.copy(),
            "fingers": self._fingers,
            "path": self._path,
            "times": self._times,
            "t": self._t,
            "seg": self._seg,
            "held": self._held,
            "grasp": self._grasp,
            "slip_at": self._slip_at,
        }

    def _restore(self, state: dict[str, Any]) -> None:
        """Take a saved kinematic state (the world has released every held object first)."""
        self._q = state["q"].copy()
        self._fingers = state["fingers"]
        self._path, self._times, self._t, self._seg = state["path"], state["times"], state["t"], state["seg"]
        self._held, self._grasp, self._slip_at = state["held"], state["grasp"], state["slip_at"]
        if self._held is not None:
            self._grip_physics(self._held, True)
        self._base_dirty = True
        self._moved = True
        self._joints_dirty = True
        self._sync()

    def __repr__(self) -> str:
        held = self._held.name if self._held else None
        return f"Arm(robot={self.robot.name!r}, busy={self.busy}, held={held!r})"


def _half_width(obj: WorldObject) -> float:
    if obj.half_extents[0] > 0.0:
        return min(obj.half_extents[0], obj.half_extents[1])
    return obj.radius


def _aabb_distance(point: Sequence[float], lo: np.ndarray, hi: np.ndarray) -> float:
    """Distance from a point to a box (0 inside)."""
    p = np.asarray(point, dtype=float)
    return float(np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0)))
