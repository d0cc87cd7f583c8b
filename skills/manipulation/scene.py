"""The planning scene of one arm: its own pybullet DIRECT client, the arm, the ground and box obstacles.

The scene is a *planning* copy of the world, built from plain data (a URDF,
the base pose, boxes). It never simulates: every query sets the joint values
it needs, so no state has to be saved or restored between queries, and the
world that simulates is never touched.

Collision margin: pybullet reports contact points only for shapes closer than
about 1 mm, so a distance margin cannot be read off ``getContactPoints``.
Instead every obstacle box is inflated by ``margin`` and the ground plane is
raised by ``margin``; a state is in collision if any contact point has a
negative distance. Self-collision and the held object are not inflated.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Self

import numpy as np
import pybullet
import pybullet_data
from pybullet_utils.bullet_client import BulletClient

from alica.skills.manipulation.geometry import (
    IDENTITY_QUAT,
    Pose,
    Vec3,
    as_configuration,
    as_pose,
    as_vec3,
    pose_inverse,
    pose_multiply,
    quat_from_yaw,
)
from alica.skills.manipulation.robot_model import ArmModel, read_arm_model
from alica.worldsim._quiet import quiet_stdout

log = logging.getLogger(__name__)

#: Where parked (unused) held-object bodies wait, far above everything.
_PARK_Z = 1000.0
#: Half size of the ground slab around the arm base, metres.
_GROUND_HALF = 5.0


@dataclass(frozen=True, slots=True)
class Box:
    """A box: world obstacle, object to pick, or (for a held object) a box in the tool frame.

    Attributes:
        name: unique name among a scene's obstacles.
        center: centre (x, y, z) in metres.
        half_extents: half sizes (hx, hy, hz) in metres, all > 0.
        yaw: rotation about the z axis in radians.
    """

    name: str
    center: Vec3
    half_extents: Vec3
    yaw: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Box name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "center", as_vec3(self.center, f"Box {self.name!r} center"))
        half = as_vec3(self.half_extents, f"Box {self.name!r} half_extents")
        if min(half) <= 0.0:
            raise ValueError(f"Box {self.name!r} half_extents must be > 0, got {half}")
        object.__setattr__(self, "half_extents", half)
        yaw = float(self.yaw)
        if not math.isfinite(yaw):
            raise ValueError(f"Box {self.name!r} yaw must be finite, got {self.yaw!r}")
        object.__setattr__(self, "yaw", yaw)

    @property
    def pose(self) -> Pose:
        """The box's pose ``(center, quat_xyzw)``."""
        return self.center, quat_from_yaw(self.yaw)

    @property
    def top(self) -> float:
        """Height of the top face (for an upright box in the world)."""
        return self.center[2] + self.half_extents[2]


def default_urdf() -> str:
    """Path of the Franka Panda URDF shipped with pybullet_data."""
    return os.path.join(pybullet_data.getDataPath(), "franka_panda", "panda.urdf")


class ArmScene:
    """A fixed-base arm in its own pybullet DIRECT client, for IK, collision checks and planning.

    Args:
        urdf_path: arm URDF; default the pybullet_data Franka Panda.
        base_pose: ``((x, y, z), quat_xyzw)`` of the arm's base link.
        obstacles: static boxes (see :meth:`set_obstacles`).
        seed: seed of :attr:`rng`, used by :meth:`random_configuration` when no generator is given.
        margin: safety distance in metres by which obstacles and the ground are inflated.
        rest_q: IK seed / rest configuration; default the Panda "ready" pose.
        home_q: transport configuration; default the Panda folded over its base.
    """

    def __init__(
        self,
        urdf_path: str | None = None,
        base_pose: Pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
        obstacles: Iterable[Box] = (),
        seed: int = 0,
        *,
        margin: float = 0.003,
        rest_q: Sequence[float] | None = None,
        home_q: Sequence[float] | None = None,
    ) -> None:
        if not (math.isfinite(margin) and 0.0 <= margin < 0.1):
            raise ValueError(f"margin must be in [0, 0.1) m, got {margin!r}")
        path = urdf_path if urdf_path is not None else default_urdf()
        if not os.path.isfile(path):
            raise ValueError(f"URDF not found: {path}")
        position, orientation = as_pose(base_pose, "base_pose")
        self._margin = float(margin)
        self.rng = np.random.default_rng(seed)
        with quiet_stdout():  # pybullet prints 'argv[0]=' for every client it connects
            self._c = BulletClient(connection_mode=pybullet.DIRECT)
        try:
            self._build(path, position, orientation, obstacles, rest_q, home_q)
        except BaseException:
            self.close()
            raise

    def _build(
        self,
        path: str,
        position: Vec3,
        orientation: tuple[float, float, float, float],
        obstacles: Iterable[Box],
        rest_q: Sequence[float] | None,
        home_q: Sequence[float] | None,
    ) -> None:
        flags = pybullet.URDF_USE_SELF_COLLISION | pybullet.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        self._robot = self._c.loadURDF(path, position, orientation, useFixedBase=True, flags=flags)
        self._model: ArmModel = read_arm_model(self._c, self._robot)
        for a, b in self._model.allowed_self_pairs:
            self._c.setCollisionFilterPair(self._robot, self._robot, a, b, 0)
        # The ground: a wide thin slab (not an infinite plane, whose bounding box would pair it with
        # every link in Bullet's broad phase) kept centred under the base; its top is at z = margin.
        slab = self._c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(_GROUND_HALF, _GROUND_HALF, 0.5))
        self._ground = self._c.createMultiBody(0.0, slab, basePosition=self._ground_center(position))
        for link in self._model.base_links:
            self._c.setCollisionFilterPair(self._robot, self._ground, link, -1, 0)
        # Bound client functions, looked up once: BulletClient's attribute lookup costs ~2 us per call.
        self._reset_joints = self._c.resetJointStatesMultiDof
        self._detect = self._c.performCollisionDetection
        self._contacts = self._c.getContactPoints
        self._link_state = self._c.getLinkState
        self._reset_base = self._c.resetBasePositionAndOrientation
        self._arm_joints = list(self._model.arm_joints)
        self._gripper_value = float("nan")
        self._set_gripper(self._model.gripper_open)
        self._obstacles: dict[Box, int] = {}
        self._held_bodies: dict[Vec3, int] = {}
        self._active_held: int | None = None
        self._last_held: Box | None = None
        self._held_local: Pose = ((0.0, 0.0, 0.0), IDENTITY_QUAT)
        self._held_grip = self._model.gripper_open
        self.rest_q = self._default_q(rest_q, self._model.rest_q, "rest_q")
        self.home_q = self._default_q(home_q, self._model.home_q, "home_q")
        self.set_obstacles(obstacles)

    # ----------------------------------------------------------------- properties
    @property
    def client(self) -> BulletClient:
        """The scene's own pybullet client (DIRECT)."""
        return self._c

    @property
    def robot_id(self) -> int:
        """Body id of the arm in :attr:`client`."""
        return self._robot

    @property
    def joint_indices(self) -> tuple[int, ...]:
        """pybullet joint indices of the 7 arm joints."""
        return self._model.arm_joints

    @property
    def movable_joints(self) -> tuple[int, ...]:
        """All non-fixed joints (arm then gripper), the order of pybullet's IK results."""
        return self._model.movable_joints

    @property
    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` arrays of the arm joints' limits in radians (copies)."""
        return self._model.lower.copy(), self._model.upper.copy()

    @property
    def ee_link(self) -> int:
        """Link index of the tool frame (``panda_grasptarget`` if present, else ``panda_hand``)."""
        return self._model.ee_link

    @property
    def gripper_links(self) -> tuple[int, ...]:
        """Links moved by the gripper joints (the fingers); they may touch a held object."""
        return self._model.gripper_links

    @property
    def max_grasp_width(self) -> float:
        """Largest object width the open gripper can straddle, in metres."""
        return self._model.max_opening

    @property
    def margin(self) -> float:
        """Safety distance by which obstacles and the ground are inflated."""
        return self._margin

    @property
    def obstacles(self) -> tuple[Box, ...]:
        """The current obstacle boxes (as given, not inflated)."""
        return tuple(self._obstacles)

    @property
    def reach(self) -> float:
        """Upper bound of the distance from the shoulder to the tool frame."""
        return self._model.reach

    def shoulder_position(self) -> Vec3:
        """World position of the shoulder (the second joint's axis), the centre of the reach sphere."""
        return pose_multiply(self.base_pose(), (self._model.shoulder_offset, IDENTITY_QUAT))[0]

    def base_pose(self) -> Pose:
        """Current world pose of the base link's URDF frame (as ``loadURDF``'s ``basePosition``)."""
        pos, quat = self._c.getBasePositionAndOrientation(self._robot)  # centre of mass frame
        return pose_multiply((tuple(pos), tuple(quat)), pose_inverse(self._model.base_inertial))

    # ----------------------------------------------------------------- world edits
    def set_base_pose(self, pose: Pose) -> None:
        """Move the arm's base (e.g. after the mobile base drove)."""
        frame = as_pose(pose, "base_pose")
        # pybullet places a body by its centre of mass; the caller gives the URDF frame.
        position, orientation = pose_multiply(frame, self._model.base_inertial)
        self._c.resetBasePositionAndOrientation(self._robot, position, orientation)
        self._c.resetBasePositionAndOrientation(self._ground, self._ground_center(frame[0]), IDENTITY_QUAT)

    def set_obstacles(self, boxes: Iterable[Box]) -> None:
        """Replace the static obstacles; boxes equal to current ones keep their bodies.

        Raises:
            TypeError: an entry is not a Box.
            ValueError: two boxes with the same name.
        """
        new = list(boxes)
        names: set[str] = set()
        for box in new:
            if not isinstance(box, Box):
                raise TypeError(f"obstacles must be Box values, got {box!r}")
            if box.name in names:
                raise ValueError(f"duplicate obstacle name {box.name!r}")
            names.add(box.name)
        keep = set(new)
        for box in [b for b in self._obstacles if b not in keep]:
            self._c.removeBody(self._obstacles.pop(box))
        for box in new:
            if box not in self._obstacles:
                half = [h + self._margin for h in box.half_extents]
                shape = self._c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
                self._obstacles[box] = self._c.createMultiBody(
                    0.0, shape, basePosition=box.center, baseOrientation=quat_from_yaw(box.yaw)
                )
        # Keep the insertion order of the request (for :attr:`obstacles`).
        self._obstacles = {box: self._obstacles[box] for box in new}

    # ----------------------------------------------------------------- queries
    def within_limits(self, q: Sequence[float] | np.ndarray) -> bool:
        """True if every joint value lies inside its limits."""
        arr = as_configuration(q, 7)
        return bool(np.all(arr >= self._model.lower) and np.all(arr <= self._model.upper))

    def random_configuration(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """A uniformly random configuration inside the joint limits (not checked for collisions)."""
        gen = self.rng if rng is None else rng
        return gen.uniform(self._model.lower, self._model.upper)

    def fk(self, q: Sequence[float] | np.ndarray) -> Pose:
        """World pose ``(pos, quat_xyzw)`` of :attr:`ee_link` at configuration ``q``."""
        self.set_joints(as_configuration(q, 7))
        return self.current_tool_pose()

    def in_collision(self, q: Sequence[float] | np.ndarray, held: Box | None = None) -> bool:
        """Whether ``q`` collides (arm vs obstacles/ground, self-collision, held object vs the rest).

        Args:
            q: 7 joint values.
            held: the object in the gripper, as a box in the tool frame (centre in
                tool coordinates, yaw about the tool z axis). The fingers may touch it.

        Raises:
            ValueError: ``q`` is not 7 finite numbers.
            TypeError: ``held`` is neither a Box nor None.
        """
        arr = as_configuration(q, 7)
        if held is not None and not isinstance(held, Box):
            raise TypeError(f"held must be a Box or None, got {held!r}")
        return self.collides(arr, held)

    def collides(self, q: Sequence[float] | np.ndarray, held: Box | None = None) -> bool:
        """:meth:`in_collision` without argument checks (for planners' inner loops)."""
        self._reset_joints(self._robot, self._arm_joints, [[float(v)] for v in q])
        if held is None:
            if self._active_held is not None:
                self._park_held()
            if self._gripper_value != self._model.gripper_open:
                self._set_gripper(self._model.gripper_open)
        else:
            body = self._held_body(held.half_extents)
            if self._active_held is not None and self._active_held != body:
                self._park_held()
            self._active_held = body
            if held is not self._last_held:
                self._last_held = held
                self._held_local = (held.center, quat_from_yaw(held.yaw))
                self._held_grip = self._grip_value(held)
            if self._held_grip != self._gripper_value:
                self._set_gripper(self._held_grip)
            state = self._link_state(self._robot, self._model.ee_link, computeForwardKinematics=True)
            pos, quat = pose_multiply((state[4], state[5]), self._held_local)
            self._reset_base(body, pos, quat)
        self._detect()
        # Only pairs with a moving body (arm links, held object) are ever in contact: static boxes
        # and the ground are not tested against each other, so one query covers everything.
        return any(cp[8] < 0.0 for cp in self._contacts())

    def set_joints(self, q: Sequence[float] | np.ndarray) -> None:
        """Set the 7 arm joints of the planning body (no checks; for inner loops)."""
        self._reset_joints(self._robot, self._model.arm_joints, [[float(v)] for v in q])

    def current_tool_pose(self) -> Pose:
        """World pose of :attr:`ee_link` at the joint values last set (forward kinematics recomputed)."""
        state = self._link_state(self._robot, self._model.ee_link, computeForwardKinematics=True)
        return tuple(state[4]), tuple(state[5])

    def close(self) -> None:
        """Disconnect the scene's client (idempotent)."""
        if self._c is not None:
            try:
                self._c.disconnect()
            except pybullet.error:  # already disconnected
                pass
            self._c = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ----------------------------------------------------------------- internals
    def _ground_center(self, base_position: Sequence[float]) -> Vec3:
        return (float(base_position[0]), float(base_position[1]), self._margin - 0.5)

    def _default_q(self, given: Sequence[float] | None, model_q: np.ndarray, name: str) -> np.ndarray:
        q = model_q.copy() if given is None else as_configuration(given, 7, name)
        if not self.within_limits(q):
            raise ValueError(f"{name} lies outside the joint limits: {q.tolist()}")
        return q

    def _set_gripper(self, value: float) -> None:
        joints = self._model.gripper_joints
        if joints:
            self._c.resetJointStatesMultiDof(self._robot, joints, [[value]] * len(joints))
        self._gripper_value = value

    def _grip_value(self, held: Box) -> float:
        """Finger joint value closing the gripper on ``held`` (width across the tool y axis)."""
        hx, hy, _ = held.half_extents
        half_width = abs(math.sin(held.yaw)) * hx + abs(math.cos(held.yaw)) * hy
        return float(min(self._model.gripper_open, max(self._model.gripper_closed, half_width)))

    def _held_body(self, half_extents: Vec3) -> int:
        body = self._held_bodies.get(half_extents)
        if body is None:
            shape = self._c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=list(half_extents))
            # A (never simulated) mass makes the body dynamic, so Bullet checks it against static boxes.
            body = self._c.createMultiBody(0.1, shape, basePosition=(0.0, 0.0, _PARK_Z + 10.0 * len(self._held_bodies)))
            for link in self._model.gripper_links:
                self._c.setCollisionFilterPair(body, self._robot, -1, link, 0)
            self._held_bodies[half_extents] = body
        return body

    def _park_held(self) -> None:
        body = self._active_held
        if body is not None:
            index = list(self._held_bodies.values()).index(body)
            self._c.resetBasePositionAndOrientation(body, (0.0, 0.0, _PARK_Z + 10.0 * index), (0.0, 0.0, 0.0, 1.0))
        self._active_held = None
