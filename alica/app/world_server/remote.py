"""The robots, arms and objects of a :class:`~alica.app.world_server.client.RemoteWorld`.

Each reads what the world last heard from the server and calls the server
for the rest (see :mod:`alica.app.world_server.client`): a
:class:`RemoteRobot` is a :class:`~alica.worldsim.interface.MobileRobot`, a
:class:`RemoteArm` a :class:`~alica.worldsim.arm_interface.RobotArm` (its
planning scene a local kinematic model), a :class:`RemoteThing` a
:class:`~alica.worldsim.interface.WorldThing`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.app.world_server import wire
from alica.app.world_server.wire import BadPayload, RobotState, ThingState
from alica.worldsim.camera_image import CameraImage
from alica.worldsim.errors import WorldError
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.robot_specs import RobotSpec

if TYPE_CHECKING:
    import trimesh

    from alica.app.world_server.client import RemoteWorld
    from alica.worldsim.arm_scene import ArmScene

__all__ = ["RemoteArm", "RemoteRobot", "RemoteThing"]

Position = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]


class RemoteRobot:
    """A robot of a :class:`RemoteWorld` (a :class:`~alica.worldsim.interface.MobileRobot`)."""

    def __init__(self, world: RemoteWorld, name: str, spec: RobotSpec, entry: Mapping[str, Any]) -> None:
        self._world = world
        self._name = name
        self._spec = spec
        self._key = wire.robot_key(world.prefix, name)
        self._lidar_noise = wire.number(entry.get("lidar_noise", 0.0), "lidar_noise", 0.0, 100.0)
        mount = entry.get("mount_offset")
        self._arm = None if mount is None else RemoteArm(self, wire.triple(mount, "mount_offset"))

    def call(
        self,
        call: str,
        what: str,
        args: Mapping[str, Any] | None = None,
        arrays: Mapping[str, np.ndarray] | None = None,
    ) -> wire.Frame:
        """Call ``call`` on this robot (only its own agent's calls are served).

        Raises:
            WorldError: see :meth:`RemoteWorld._call`.
        """
        return self._world._call(self._key, call, args or {}, arrays, what=f"{what} of robot '{self._name}'")

    @property
    def name(self) -> str:
        """The robot's (and its agent's) name."""
        return self._name

    @property
    def spec(self) -> RobotSpec:
        """Its kind's radius, speeds and capabilities."""
        return self._spec

    @property
    def arm(self) -> RemoteArm | None:
        """The arm, or ``None``."""
        return self._arm

    @property
    def pose(self) -> Position:
        """``(x, y, yaw)`` as last heard."""
        return self._world._robot_state(self._name).pose

    @property
    def estimate(self) -> Position:
        """The robot's own belief of its pose, as last heard."""
        return self._world._robot_state(self._name).estimate

    @property
    def crashed(self) -> bool:
        """Whether the robot is out."""
        return self._world._robot_state(self._name).crashed

    @property
    def bumped(self) -> bool:
        """Whether the last drive command was stopped by a collision (setting it tells the server)."""
        return self._world._robot_state(self._name).bumped

    @bumped.setter
    def bumped(self, value: bool) -> None:
        self.call("set_bumped", "resetting bumped", {"value": bool(value)})

    def set_estimate(self, pose: tuple[float, float, float]) -> None:
        """Correct the pose estimate.

        Raises:
            WorldError: not three finite numbers, or the server does not answer.
        """
        try:
            x, y, yaw = (float(v) for v in pose)
        except (TypeError, ValueError):
            raise WorldError(f"set_estimate of robot '{self._name}' takes (x, y, yaw), got {pose!r}") from None
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise WorldError(f"set_estimate of robot '{self._name}' needs finite numbers, got {pose!r}")
        self.call("set_estimate", "set_estimate", {"pose": [x, y, yaw]})

    def drive(self, v: float, w: float) -> None:
        """Drive at ``v`` m/s turning at ``w`` rad/s until told otherwise."""
        v, w = float(v), float(w)
        if not (math.isfinite(v) and math.isfinite(w)):
            raise WorldError(f"drive of robot '{self._name}' needs finite v and w, got ({v}, {w})")
        self.call("drive", "drive", {"v": v, "w": w})

    def stop(self) -> None:
        """Stand still."""
        self.call("stop", "stop")

    def lidar(self, n_rays: int, max_range: float | None = None) -> np.ndarray:
        """One lidar scan: the one the server cast at the last step (its lidar streams at the world's rate once
        asked), or, when there is none with these settings yet, one cast on request."""
        max_range = None if max_range is None else float(max_range)
        streamed = self._world._scan(self._name, int(n_rays), max_range)
        if streamed is not None:
            return streamed
        frame = self.call("lidar", "a lidar scan", {"n_rays": int(n_rays), "max_range": max_range})
        try:
            ranges = wire.array(frame.arrays, "ranges", "lidar", ndim=1)
        except BadPayload as exc:
            raise WorldError(f"the lidar scan of robot '{self._name}' is malformed: {exc}") from None
        if len(ranges) != int(n_rays):
            raise WorldError(f"the lidar scan of robot '{self._name}' has {len(ranges)} rays, not {n_rays}")
        return ranges.copy()

    @staticmethod
    def lidar_angles(n_rays: int) -> np.ndarray:
        """The ray angles of a scan of ``n_rays`` relative to the heading."""
        from alica.worldsim.sensors import lidar_angles

        return lidar_angles(n_rays)

    @property
    def lidar_noise(self) -> float:
        """Standard deviation of the lidar's range noise, metres."""
        return self._lidar_noise

    def camera_pose(
        self, pose: tuple[float, float, float] | None = None, pan: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Where the camera is and how it is turned (asked of the server)."""
        args = {"pose": None if pose is None else [float(v) for v in pose], "pan": float(pan)}
        frame = self.call("camera_pose", "the camera's pose", args)
        try:
            position = wire.array(frame.arrays, "position", "camera pose", ndim=1, width=3)
            rotation = wire.array(frame.arrays, "rotation", "camera pose", ndim=2, width=3)
        except BadPayload as exc:
            raise WorldError(f"the camera pose of robot '{self._name}' is malformed: {exc}") from None
        return position.copy(), rotation.copy()

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
        """One picture of the robot's camera, rendered by the server."""
        args = {
            "width": int(width),
            "height": int(height),
            "fov": fov,
            "far": far,
            "pan": float(pan),
            "believed": bool(believed),
            "window": None if window is None else [int(v) for v in window],
        }
        frame = self.call("camera", "a picture", args)
        h = frame.header
        try:
            rgb = wire.array(frame.arrays, "rgb", "picture", ndim=3, width=3)
            depth = frame.arrays.get("depth")
            if depth is None or depth.ndim != 2 or depth.shape != rgb.shape[:2] or np.isnan(depth).any():
                raise BadPayload("array", "the depth image does not match the colour image")
            position = wire.array(frame.arrays, "position", "picture", ndim=1, width=3)
            rotation = wire.array(frame.arrays, "rotation", "picture", ndim=2, width=3)
            fx, fy, cx, cy = wire.numbers(h.get("intrinsics"), "intrinsics", 4)
            offset = h.get("offset", [0, 0])
            frame_size = h.get("frame")
            if not isinstance(offset, list) or len(offset) != 2:
                raise BadPayload("type", "offset must be [u0, v0]")
            u0, v0 = (wire.integer(v, "offset", 0, 1 << 16) for v in offset)
            fs: tuple[int, int] | None = None
            if frame_size is not None:
                if not isinstance(frame_size, list) or len(frame_size) != 2:
                    raise BadPayload("type", "frame must be [width, height]")
                fw, fh = (wire.integer(v, "frame", 1, 1 << 16) for v in frame_size)
                fs = (fw, fh)
            image = CameraImage(
                rgb=rgb.copy(),
                depth=depth.copy(),
                intrinsics=(fx, fy, cx, cy),
                position=position.copy(),
                rotation=rotation.copy(),
                time=wire.number(h.get("time"), "time", 0.0, 1e12),
                pan=wire.number(h.get("pan", 0.0), "pan"),
                offset=(u0, v0),
                frame=fs,
            )
        except BadPayload as exc:
            raise WorldError(f"the picture of robot '{self._name}' is malformed: {exc}") from None
        return image

    def __repr__(self) -> str:
        return f"RemoteRobot({self._name!r})"


class RemoteArm:
    """The arm of a :class:`RemoteRobot` (a :class:`~alica.worldsim.arm_interface.RobotArm`)."""

    def __init__(self, robot: RemoteRobot, mount_offset: tuple[float, float, float]) -> None:
        self._robot = robot
        self._mount = mount_offset
        self._scene: ArmScene | None = None

    @property
    def mount_offset(self) -> tuple[float, float, float]:
        """``(x, y, z)`` of the arm's base in the robot's base frame."""
        return self._mount

    def _state(self) -> RobotState:
        return self._robot._world._robot_state(self._robot.name)

    @property
    def held(self) -> RemoteThing | None:
        """The object in the gripper, or ``None``."""
        held = self._state().arm_held
        return None if held is None else self._robot._world.objects.get(held)

    @property
    def busy(self) -> bool:
        """Whether the arm is still following a path."""
        return self._state().arm_busy

    def q(self) -> np.ndarray:
        """The 7 joint values as last heard."""
        q = self._state().arm_q
        if q is None:
            raise WorldError(f"the world server did not tell the arm joints of robot '{self._robot.name}'")
        return np.array(q, dtype=float)

    def base_pose(self) -> tuple[Position, Quaternion]:
        """World pose of the arm's base frame now."""
        result = self._robot.call("arm_base_pose", "the arm's base pose").header.get("result")
        try:
            return wire.pose(result, "arm base pose")
        except BadPayload as exc:
            raise WorldError(f"the arm base pose of robot '{self._robot.name}' is malformed: {exc}") from None

    def follow(self, path: np.ndarray, duration: float | None = None) -> float:
        """Follow a joint path; returns its duration (s)."""
        array = np.asarray(path, dtype=np.float64)
        if array.ndim != 2 or array.shape[1] != 7 or not np.isfinite(array).all():
            raise WorldError(f"arm path of robot '{self._robot.name}' must be finite (n, 7), got shape {array.shape}")
        frame = self._robot.call("arm_follow", "an arm path", {"duration": duration}, {"path": array})
        return wire.number(frame.header.get("result"), "duration", 0.0)

    def stop(self) -> None:
        """Stop where the arm is."""
        self._robot.call("arm_stop", "stopping the arm")

    def open(self) -> None:
        """Open the fingers."""
        self._robot.call("arm_open", "opening the gripper")

    def close(self, force: float | None = None) -> None:
        """Close the fingers with ``force`` newtons."""
        self._robot.call("arm_close", "closing the gripper", {"force": None if force is None else float(force)})

    def attach(self, obj: str) -> bool:
        """Take ``obj`` between the fingers as held; whether it was there."""
        result = self._robot.call("arm_attach", f"attaching '{obj}'", {"object": obj}).header.get("result")
        return wire.flag(result, "attached")

    def detach(self) -> RemoteThing | None:
        """Let the held object go; returns it."""
        result = self._robot.call("arm_detach", "detaching").header.get("result")
        if result is None:
            return None
        world = self._robot._world
        thing = world.objects.get(wire.name(result, "detached"))
        return thing if thing is not None else RemoteThing(world, result)

    def grip_force(self) -> float:
        """The finger force on the held object, newtons."""
        return wire.number(self._robot.call("arm_grip_force", "the grip force").header.get("result"), "grip force")

    def planning_scene(self) -> ArmScene:
        """A local kinematic model of the arm, its base where the arm's is now (built on first use)."""
        from alica.worldsim.arm_scene import ArmScene

        base = self.base_pose()
        if self._scene is None:
            self._scene = ArmScene(None, base, seed=self._robot._world.seed)
        self._scene.set_base_pose(base)
        return self._scene

    def close_scene(self) -> None:
        """Close the planning scene (its pybullet client)."""
        if self._scene is not None:
            self._scene.close()
            self._scene = None


class RemoteThing:
    """An object of a :class:`RemoteWorld` (a :class:`~alica.worldsim.interface.WorldThing`), as last heard."""

    def __init__(self, world: RemoteWorld, name: str) -> None:
        self._world = world
        self._name = name

    @property
    def name(self) -> str:
        """Unique name in the world."""
        return self._name

    @property
    def _s(self) -> ThingState:
        return self._world._thing_state(self._name)

    @property
    def kind(self) -> str:
        """``block``, ``sample``, ``rock``, ``table``, ``collection_point`` or ``terrain``."""
        return self._s.kind

    @property
    def size(self) -> float:
        """Edge of a block, height of a sample or table, radius of a rock or marker."""
        return self._s.size

    @property
    def radius(self) -> float:
        """Footprint radius; 0 for boxes."""
        return self._s.radius

    @property
    def half_extents(self) -> tuple[float, ...]:
        """Box half extents; zeros otherwise."""
        return self._s.half_extents

    def pose(self) -> tuple[Position, Quaternion]:
        """Position and quaternion ``(x, y, z, w)``."""
        return self._s.pose

    def position(self) -> np.ndarray:
        """The position as an array of 3."""
        return np.array(self._s.pose[0], dtype=float)

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box ``(lower, upper)``."""
        lo, hi = self._s.aabb
        return np.array(lo, dtype=float), np.array(hi, dtype=float)

    def footprint(self) -> Obstacle2D | None:
        """The 2-D footprint now (``None`` for markers and terrain)."""
        fp = self._s.footprint
        if fp is None:
            return None
        return Obstacle2D(
            fp["kind"], fp["x"], fp["y"], fp["radius"], fp["half_x"], fp["half_y"], fp["yaw"], name=self._name
        )

    def world_mesh(self) -> trimesh.Trimesh | None:
        """The rock's mesh at its pose (``None`` for other objects)."""
        if self._name not in self._world._info.get("meshes", ()):
            return None
        mesh = self._world._mesh(self._name)
        if mesh is None:
            return None
        import trimesh

        vertices, faces = mesh
        (px, py, pz), (x, y, z, w) = self._s.pose
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        moved = vertices @ rotation.T + np.array([px, py, pz])
        return trimesh.Trimesh(vertices=moved, faces=faces.copy(), process=False)

    def __repr__(self) -> str:
        return f"RemoteThing({self._name!r})"
