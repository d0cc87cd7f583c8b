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

from alica.worldsim._quiet import quiet_stdout
from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import pose_multiply, quat_multiply, yaw_to_quat
from alica.worldsim.gripper import FINGER_OPEN, GRASP_TOLERANCE, GRIP_FORCE, GripperMixin
from alica.worldsim.objects import ARM_GROUP, MOVABLE_GROUP

if TYPE_CHECKING:
    from alica.worldsim.arm_host import ArmMount
    from alica.worldsim.arm_scene import ArmPlanningModel, ArmScene

__all__ = ["GRASP_TOLERANCE", "GRIP_FORCE", "PANDA_URDF", "Arm"]

logger = logging.getLogger(__name__)

#: The arm model, relative to ``pybullet_data.getDataPath()``.
PANDA_URDF = "franka_panda/panda.urdf"

_ARM_JOINTS = (0, 1, 2, 3, 4, 5, 6)
_FINGER_JOINTS = (9, 10)
_EE_LINK = 11  # panda_grasptarget, between the fingertips
_HOME_Q = (0.0, -1.1, 0.0, -2.75, 0.0, 1.75, 0.785)


class Arm(GripperMixin):
    """A Panda arm with a parallel gripper on a robot (``robot.arm``).

    Attributes:
        robot: the robot that carries it (an :class:`~alica.worldsim.arm_host.ArmMount`).
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
        "_com_local",
        "_com_quat",
        "_path",
        "_q",
        "_reset_joints",
        "_reset_pose",
        "_scene",
        "_seg",
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

    def __init__(self, robot: ArmMount, mount_offset: Sequence[float]) -> None:
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
        # Without the detailed visual meshes (World(arm_visuals=False)) pybullet draws the collision hulls.
        flags = c.URDF_USE_INERTIA_FROM_FILE | (0 if world.arm_visuals else c.URDF_IGNORE_VISUAL_SHAPES)
        with quiet_stdout(world.quiet):
            self.body_id: int = c.loadURDF(self.urdf_path, useFixedBase=True, flags=flags)
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
        ix, iy, iz = dyn[3]
        ox, oy, oz = self.mount_offset
        self._com_local = (ox + ix, oy + iy, oz + iz)
        self._com_quat = None if tuple(dyn[4]) == (0.0, 0.0, 0.0, 1.0) else tuple(dyn[4])
        # Kinematic arm: no motors, massless links (gravity cannot move it between our re-poses),
        # and contacts only with movable objects (which it pushes like a moving static body).
        n = c.getNumJoints(self.body_id)
        c.setJointMotorControlArray(self.body_id, list(range(n)), c.VELOCITY_CONTROL, forces=[0.0] * n)
        for link in range(-1, n):
            c.changeDynamics(self.body_id, link, mass=0.0)
            c.setCollisionFilterGroupMask(self.body_id, link, ARM_GROUP, MOVABLE_GROUP)
        # Asleep, pybullet skips the arm's articulated-body dynamics (about 26 us per arm and step, most of
        # a step with several arms), which a re-posed massless arm does not need; a re-pose still moves its
        # collision shapes, so it pushes blocks exactly as when awake.
        c.changeDynamics(self.body_id, -1, activationState=c.ACTIVATION_STATE_ENABLE_SLEEPING)
        c.changeDynamics(self.body_id, -1, activationState=c.ACTIVATION_STATE_SLEEP)
        self._reset_joints = c.resetJointStatesMultiDof
        self._reset_pose = c.resetBasePositionAndOrientation
        self._all_joints = list(_ARM_JOINTS + _FINGER_JOINTS)
        self._q = self.home_q.copy()
        self._fingers = FINGER_OPEN
        self._force = GRIP_FORCE
        self._path: np.ndarray | None = None
        self._times: np.ndarray | None = None
        self._t = 0.0
        self._seg = 0
        self._held = None
        self._grasp = None
        self._slip_at = None
        self._base_dirty = True
        self._moved = True
        self._joints_dirty = True
        self._scene: ArmScene | None = None
        self._sync()

    # ----------------------------------------------------------------- poses
    def base_pose(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """World position and quaternion of the arm base frame (``panda_link0``)."""
        x, y, yaw = self.robot.pose
        ox, oy, oz = self.mount_offset
        c, s = math.cos(yaw), math.sin(yaw)
        return (x + c * ox - s * oy, y + s * ox + c * oy, oz), yaw_to_quat(yaw)

    def planning_scene(self) -> ArmScene:
        """The arm's planning scene (:class:`~alica.worldsim.arm_scene.ArmScene`), its base where the arm's is now.

        Made on first use, seeded by the world's seed. The scenes of the arms of one
        world share one planning model per URDF (the pybullet client with the arm,
        about 40 MB): a scene of its own costs only its state.
        """
        from alica.worldsim.arm_scene import ArmPlanningModel, ArmScene  # pybullet, imported quietly by the world first

        scene = self._scene
        if scene is None:
            world = self.robot.world
            model = next(
                (
                    r.arm.planning_model
                    for r in world.robots.values()
                    if r.arm is not None and r.arm.urdf_path == self.urdf_path and r.arm.planning_model is not None
                ),
                None,
            )
            if model is None:
                model = ArmPlanningModel(self.urdf_path)
            scene = self._scene = ArmScene(self.urdf_path, self.base_pose(), seed=world.seed, model=model)
        scene.set_base_pose(self.base_pose())
        return scene

    @property
    def planning_model(self) -> ArmPlanningModel | None:
        """The planning model of the arm's scene (shared by the arms of a world), ``None`` before :meth:`planning_scene`."""
        return None if self._scene is None else self._scene.model

    def q(self) -> np.ndarray:
        """The seven joint positions (a copy)."""
        return self._q.copy()

    def ee_pose(self) -> tuple[np.ndarray, tuple[float, float, float, float]]:
        """World position and quaternion ``(x, y, z, w)`` of the end-effector (between the fingertips)."""
        state = self._client.getLinkState(self.body_id, self.ee_link, computeForwardKinematics=1)
        return np.asarray(state[4], dtype=float), tuple(state[5])

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

    # ------------------------------------------------------------- internals
    def _base_moved(self) -> None:
        self._base_dirty = True
        self._moved = True

    def _sync(self) -> None:
        """Put the pybullet bodies where the kinematic state says (arm base, joints, held object)."""
        if self._base_dirty:
            # pybullet poses a base by its centre of mass: mount offset plus the link's inertial offset.
            x, y, yaw = self.robot.pose
            cy, sy = math.cos(yaw), math.sin(yaw)
            base_quat = yaw_to_quat(yaw)
            lx, ly, lz = self._com_local
            com = (x + cy * lx - sy * ly, y + sy * lx + cy * ly, lz)
            quat = base_quat if self._com_quat is None else quat_multiply(base_quat, self._com_quat)
            self._reset_pose(self.body_id, com, quat)
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
            state = self._client.getLinkState(self.body_id, self.ee_link, computeForwardKinematics=1)
            pos, quat = pose_multiply(state[4], state[5], *self._grasp)
            self._reset_pose(self._held.body_id, pos, quat)
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
            "force": self._force,
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
        self._force = state.get("force", GRIP_FORCE)
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
