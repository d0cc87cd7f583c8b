"""The planning scene of one arm: a pybullet DIRECT client with the arm, the ground and box obstacles.

The scene is a *planning* copy of the world, built from plain data (a URDF,
the base pose, boxes). It never simulates: every query sets the joint values
it needs, so no state has to be saved or restored between queries, and the
world that simulates is never touched.

Collision margin: pybullet reports contact points only for shapes closer than
about 1 mm, so a distance margin cannot be read off ``getContactPoints``.
Instead every obstacle box is inflated by ``margin`` and the ground plane is
raised by ``margin``; a state is in collision if any contact point has a
negative distance. Self-collision and the held object are not inflated.

Sharing: a pybullet client with a loaded arm costs about 40 MB, whatever the
scene. The scenes of several arms of the same kind can share one
:class:`ArmPlanningModel` (the client, the arm body with its collision meshes
and kinematics, the ground, box and held-object bodies): each
:class:`ArmScene` keeps its own base pose, obstacles and joint values and
puts them into the shared client whenever it is used after another scene.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterable, Sequence
from typing import Self

import numpy as np
import pybullet
import pybullet_data
from pybullet_utils.bullet_client import BulletClient

from alica.worldsim._quiet import quiet_stdout
from alica.worldsim.arm_model import ArmModel, read_arm_model
from alica.worldsim.geometry import (
    IDENTITY_QUAT,
    Box,
    Pose,
    Vec3,
    as_configuration,
    as_pose,
    pose_inverse,
    pose_multiply,
)
from alica.worldsim.geometry import yaw_to_quat as quat_from_yaw

__all__ = ["ArmPlanningModel", "ArmScene", "Box", "default_urdf"]

log = logging.getLogger(__name__)

#: Where parked (unused) held-object bodies wait, far above everything.
_PARK_Z = 1000.0
#: Half size of the ground slab around the arm base, metres.
_GROUND_HALF = 5.0


def default_urdf() -> str:
    """Path of the Franka Panda URDF shipped with pybullet_data."""
    return os.path.join(pybullet_data.getDataPath(), "franka_panda", "panda.urdf")


class ArmPlanningModel:
    """The planning model of one kind of arm: a pybullet DIRECT client with the arm, shared by :class:`ArmScene` s.

    Holds what is the same for every arm of that kind (the client, the arm body
    with its collision meshes, self-collision filter and kinematics, the
    ground slab, the obstacle and held-object bodies and their shapes). The
    scenes using it take turns: a scene puts its base pose, obstacles and
    joint values into the client when it is used after another one. Scenes
    sharing a model must not be used concurrently (they are not thread-safe).

    Args:
        urdf_path: arm URDF; default the pybullet_data Franka Panda.
        margin: safety distance in metres by which obstacles and the ground are inflated.

    Raises:
        ValueError: a margin outside [0, 0.1) m, a missing URDF, or an arm with fewer than 7 movable joints.
    """

    def __init__(self, urdf_path: str | None = None, *, margin: float = 0.003) -> None:
        if not (math.isfinite(margin) and 0.0 <= margin < 0.1):
            raise ValueError(f"margin must be in [0, 0.1) m, got {margin!r}")
        path = urdf_path if urdf_path is not None else default_urdf()
        if not os.path.isfile(path):
            raise ValueError(f"URDF not found: {path}")
        self.urdf_path = path
        self.margin = float(margin)
        #: The scene whose base pose, obstacles and joints the client holds (None: none yet).
        self.owner: ArmScene | None = None
        with quiet_stdout():  # pybullet prints 'argv[0]=' for every client it connects
            self._c: BulletClient | None = BulletClient(connection_mode=pybullet.DIRECT)
        try:
            self._build(path)
        except BaseException:
            self.close()
            raise

    def _build(self, path: str) -> None:
        c = self.client
        # No visual meshes: a planning scene never renders, and the Panda's cost pybullet about 48 MB.
        flags = (
            pybullet.URDF_USE_SELF_COLLISION
            | pybullet.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
            | pybullet.URDF_IGNORE_VISUAL_SHAPES
        )
        self.robot = c.loadURDF(path, (0.0, 0.0, 0.0), IDENTITY_QUAT, useFixedBase=True, flags=flags)
        self.model: ArmModel = read_arm_model(c, self.robot)
        for a, b in self.model.allowed_self_pairs:
            c.setCollisionFilterPair(self.robot, self.robot, a, b, 0)
        # The ground: a wide thin slab (not an infinite plane, whose bounding box would pair it with
        # every link in Bullet's broad phase) kept centred under the base; its top is at z = margin.
        slab = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(_GROUND_HALF, _GROUND_HALF, 0.5))
        self.ground = c.createMultiBody(0.0, slab, basePosition=self.ground_center((0.0, 0.0, 0.0)))
        for link in self.model.base_links:
            c.setCollisionFilterPair(self.robot, self.ground, link, -1, 0)
        # Bound client functions, looked up once: BulletClient's attribute lookup costs ~2 us per call.
        self.reset_joints = c.resetJointStatesMultiDof
        self.detect = c.performCollisionDetection
        self.contacts = c.getContactPoints
        self.link_state = c.getLinkState
        self.reset_base = c.resetBasePositionAndOrientation
        self.arm_joints = list(self.model.arm_joints)
        self.gripper_value = float("nan")
        self.set_gripper(self.model.gripper_open)
        # The bodies in the client: obstacles (of the scene that last used it) and held objects.
        self.obstacles: dict[Box, int] = {}
        self._box_shapes: dict[Vec3, int] = {}
        self.held_bodies: dict[Vec3, int] = {}
        self.active_held: int | None = None
        self.last_held: Box | None = None
        self.held_local: Pose = ((0.0, 0.0, 0.0), IDENTITY_QUAT)
        self.held_grip = self.model.gripper_open

    @property
    def client(self) -> BulletClient:
        """The model's pybullet client (DIRECT)."""
        if self._c is None:
            raise ValueError("the arm planning model is closed")
        return self._c

    def close(self) -> None:
        """Disconnect the client (idempotent); the scenes using the model cannot be used any more."""
        if self._c is not None:
            try:
                self._c.disconnect()
            except pybullet.error:  # already disconnected
                pass
            self._c = None
        self.owner = None

    # ----------------------------------------------------------------- client state
    def ground_center(self, base_position: Sequence[float]) -> Vec3:
        """Centre of the ground slab under a base at ``base_position`` (its top at z = margin)."""
        return (float(base_position[0]), float(base_position[1]), self.margin - 0.5)

    def place_base(self, frame: Pose) -> None:
        """Put the arm's base link frame (and the ground under it) at ``frame``."""
        # pybullet places a body by its centre of mass; the caller gives the URDF frame.
        position, orientation = pose_multiply(*frame, *self.model.base_inertial)
        self.reset_base(self.robot, position, orientation)
        self.reset_base(self.ground, self.ground_center(frame[0]), IDENTITY_QUAT)

    def place_obstacles(self, boxes: Sequence[Box]) -> None:
        """Make ``boxes`` the client's obstacle bodies; boxes already there keep their bodies."""
        c = self.client
        keep = set(boxes)
        for box in [b for b in self.obstacles if b not in keep]:
            c.removeBody(self.obstacles.pop(box))
        for box in boxes:
            if box not in self.obstacles:
                hx, hy, hz = box.half_extents
                half: Vec3 = (hx + self.margin, hy + self.margin, hz + self.margin)
                shape = self._box_shapes.get(half)
                if shape is None:  # one shape per size: pybullet keeps a shape after its body is removed
                    shape = self._box_shapes[half] = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
                self.obstacles[box] = c.createMultiBody(
                    0.0, shape, basePosition=box.center, baseOrientation=quat_from_yaw(box.yaw)
                )

    def set_gripper(self, value: float) -> None:
        """Put the finger joints at ``value``."""
        joints = self.model.gripper_joints
        if joints:
            self.client.resetJointStatesMultiDof(self.robot, joints, [[value]] * len(joints))
        self.gripper_value = value

    def joint_values(self) -> list[float]:
        """The current values of the movable joints (arm, then gripper)."""
        return [s[0] for s in self.client.getJointStates(self.robot, list(self.model.movable_joints))]

    def held_body(self, half_extents: Vec3) -> int:
        """The (parked or active) body of a held object of this size."""
        body = self.held_bodies.get(half_extents)
        if body is None:
            c = self.client
            shape = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=list(half_extents))
            # A (never simulated) mass makes the body dynamic, so Bullet checks it against static boxes.
            body = c.createMultiBody(0.1, shape, basePosition=(0.0, 0.0, _PARK_Z + 10.0 * len(self.held_bodies)))
            for link in self.model.gripper_links:
                c.setCollisionFilterPair(body, self.robot, -1, link, 0)
            self.held_bodies[half_extents] = body
        return body

    def park_held(self) -> None:
        """Move the active held-object body back to its place far above everything."""
        body = self.active_held
        if body is not None:
            index = list(self.held_bodies.values()).index(body)
            self.reset_base(body, (0.0, 0.0, _PARK_Z + 10.0 * index), (0.0, 0.0, 0.0, 1.0))
        self.active_held = None


class ArmScene:
    """A fixed-base arm in a pybullet DIRECT client, for IK, collision checks and planning.

    Args:
        urdf_path: arm URDF; default the pybullet_data Franka Panda (or that of ``model``).
        base_pose: ``((x, y, z), quat_xyzw)`` of the arm's base link.
        obstacles: static boxes (see :meth:`set_obstacles`).
        seed: seed of :attr:`rng`, used by :meth:`random_configuration` when no generator is given.
        margin: safety distance in metres by which obstacles and the ground are inflated.
        rest_q: IK seed / rest configuration; default the Panda "ready" pose.
        home_q: transport configuration; default the Panda folded over its base.
        model: an :class:`ArmPlanningModel` to share with other scenes of the same arm (its URDF and
            margin must match ``urdf_path`` and ``margin``); default a model of the scene's own,
            closed with it.

    Raises:
        ValueError: bad arguments, or a ``model`` of another URDF or margin.
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
        model: ArmPlanningModel | None = None,
    ) -> None:
        if not (math.isfinite(margin) and 0.0 <= margin < 0.1):
            raise ValueError(f"margin must be in [0, 0.1) m, got {margin!r}")
        path = urdf_path if urdf_path is not None else (model.urdf_path if model is not None else default_urdf())
        if not os.path.isfile(path):
            raise ValueError(f"URDF not found: {path}")
        if model is not None and (
            os.path.realpath(path) != os.path.realpath(model.urdf_path) or float(margin) != model.margin
        ):
            raise ValueError(
                f"the shared arm model is of {model.urdf_path} with margin {model.margin}, "
                f"the scene asks for {path} with margin {margin}"
            )
        self._base_frame: Pose = as_pose(base_pose, "base_pose")
        self._margin = float(margin)
        self.rng = np.random.default_rng(seed)
        self._owns_model = model is None
        self._m: ArmPlanningModel | None = ArmPlanningModel(path, margin=margin) if model is None else model
        self._boxes: tuple[Box, ...] = ()
        self._joints: list[float] | None = None  # the joint values while another scene uses the model
        try:
            m = self._model_in_use()
            self._model: ArmModel = m.model
            self.rest_q = _default_q(self._model, rest_q, self._model.rest_q, "rest_q")
            self.home_q = _default_q(self._model, home_q, self._model.home_q, "home_q")
            self.set_obstacles(obstacles)
        except BaseException:
            self.close()
            raise

    # ----------------------------------------------------------------- sharing
    def _model_in_use(self) -> ArmPlanningModel:
        """The model, holding this scene's base pose, obstacles and joint values."""
        m = self._m
        if m is None:
            raise ValueError("the arm scene is closed")
        if m.owner is not self:
            self._take_over(m)
        return m

    def _take_over(self, m: ArmPlanningModel) -> None:
        previous = m.owner
        if previous is not None:  # it finds its joints as it left them when it comes back
            previous._joints = m.joint_values()
        m.owner = self
        m.place_base(self._base_frame)
        m.place_obstacles(self._boxes)
        if self._joints is None:  # a new scene: the URDF's zeros, the gripper open
            joints = [0.0] * len(m.model.arm_joints) + [m.model.gripper_open] * len(m.model.gripper_joints)
        else:
            joints = self._joints
        m.reset_joints(m.robot, list(m.model.movable_joints), [[v] for v in joints])
        m.gripper_value = joints[-1] if m.model.gripper_joints else m.gripper_value
        self._joints = None

    @property
    def model(self) -> ArmPlanningModel:
        """The (possibly shared) planning model: client, arm body and collision bodies."""
        if self._m is None:
            raise ValueError("the arm scene is closed")
        return self._m

    # ----------------------------------------------------------------- properties
    @property
    def client(self) -> BulletClient:
        """The scene's pybullet client (DIRECT), holding this scene's state (shared with the model's other scenes)."""
        return self._model_in_use().client

    @property
    def robot_id(self) -> int:
        """Body id of the arm in :attr:`client`."""
        return self._model_in_use().robot

    @property
    def arm_model(self) -> ArmModel:
        """The arm's joint and link facts in :attr:`client`: ``arm_joints`` (the 7 arm joints), ``movable_joints``
        (arm then gripper, the order of pybullet's IK results), ``ee_link`` (the tool frame, ``panda_grasptarget``
        if present, else ``panda_hand``), ``gripper_links`` (the fingers, which may touch a held object)."""
        return self._model

    @property
    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` arrays of the arm joints' limits in radians (copies)."""
        return self._model.lower.copy(), self._model.upper.copy()

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
        return self._boxes

    @property
    def reach(self) -> float:
        """Upper bound of the distance from the shoulder to the tool frame."""
        return self._model.reach

    def shoulder_position(self) -> Vec3:
        """World position of the shoulder (the second joint's axis), the centre of the reach sphere."""
        return pose_multiply(*self.base_pose(), self._model.shoulder_offset, IDENTITY_QUAT)[0]

    def base_pose(self) -> Pose:
        """Current world pose of the base link's URDF frame (as ``loadURDF``'s ``basePosition``)."""
        m = self._model_in_use()
        pos, quat = m.client.getBasePositionAndOrientation(m.robot)  # centre of mass frame
        return pose_multiply(tuple(pos), tuple(quat), *pose_inverse(*self._model.base_inertial))

    # ----------------------------------------------------------------- world edits
    def set_base_pose(self, pose: Pose) -> None:
        """Move the arm's base (e.g. after the mobile base drove)."""
        frame = as_pose(pose, "base_pose")
        m = self._model_in_use()
        self._base_frame = frame
        m.place_base(frame)

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
        m = self._model_in_use()
        self._boxes = tuple(new)  # the order of the request (for :attr:`obstacles`)
        m.place_obstacles(self._boxes)

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
        m = self._m
        if m is None or m.owner is not self:
            m = self._model_in_use()
        m.reset_joints(m.robot, m.arm_joints, [[float(v)] for v in q])
        if held is None:
            if m.active_held is not None:
                m.park_held()
            if m.gripper_value != self._model.gripper_open:
                m.set_gripper(self._model.gripper_open)
        else:
            body = m.held_body(held.half_extents)
            if m.active_held is not None and m.active_held != body:
                m.park_held()
            m.active_held = body
            if held is not m.last_held:
                m.last_held = held
                m.held_local = (held.center, quat_from_yaw(held.yaw))
                m.held_grip = _grip_value(self._model, held)
            if m.held_grip != m.gripper_value:
                m.set_gripper(m.held_grip)
            state = m.link_state(m.robot, self._model.ee_link, computeForwardKinematics=True)
            pos, quat = pose_multiply(state[4], state[5], *m.held_local)
            m.reset_base(body, pos, quat)
        m.detect()
        # Only pairs with a moving body (arm links, held object) are ever in contact: static boxes
        # and the ground are not tested against each other, so one query covers everything.
        return any(cp[8] < 0.0 for cp in m.contacts())

    def set_joints(self, q: Sequence[float] | np.ndarray) -> None:
        """Set the 7 arm joints of the planning body (no checks; for inner loops)."""
        m = self._m
        if m is None or m.owner is not self:
            m = self._model_in_use()
        m.reset_joints(m.robot, m.arm_joints, [[float(v)] for v in q])

    def current_tool_pose(self) -> Pose:
        """World pose of :attr:`ee_link` at the joint values last set (forward kinematics recomputed)."""
        m = self._model_in_use()
        state = m.link_state(m.robot, self._model.ee_link, computeForwardKinematics=True)
        return tuple(state[4]), tuple(state[5])

    def ik_round(
        self, position: Vec3, orientation: tuple[float, float, float, float], *, damping: float, iterations: int
    ) -> np.ndarray:
        """A few iterations of pybullet's damped least squares IK from the joint values last set.

        Returns the 7 arm joint values it reached (not clipped, not checked: see
        :func:`alica.skills.manipulation.solve_ik`, which verifies them).
        """
        m = self._model_in_use()
        solution = m.client.calculateInverseKinematics(
            m.robot,
            self._model.ee_link,
            position,
            orientation,
            jointDamping=[damping] * len(self._model.movable_joints),
            maxNumIterations=iterations,
            residualThreshold=1e-7,
        )
        return np.array(solution[:7])

    def close(self) -> None:
        """Leave the shared model, or disconnect the scene's own one (idempotent)."""
        m = self._m
        if m is not None:
            if self._owns_model:
                m.close()
            elif m.owner is self:
                m.owner = None
            self._m = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _default_q(model: ArmModel, given: Sequence[float] | None, model_q: np.ndarray, name: str) -> np.ndarray:
    """``given`` (checked: 7 values inside the joint limits), else the model's ``model_q``."""
    q = model_q.copy() if given is None else as_configuration(given, 7, name)
    if not (np.all(q >= model.lower) and np.all(q <= model.upper)):
        raise ValueError(f"{name} lies outside the joint limits: {q.tolist()}")
    return q


def _grip_value(model: ArmModel, held: Box) -> float:
    """Finger joint value closing the gripper on ``held`` (width across the tool y axis)."""
    hx, hy, _ = held.half_extents
    half_width = abs(math.sin(held.yaw)) * hx + abs(math.cos(held.yaw)) * hy
    return float(min(model.gripper_open, max(model.gripper_closed, half_width)))
