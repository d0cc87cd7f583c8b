"""The robots: heterogeneous kinematic bases (IMPERA Section 2), some with a Panda arm.

Bases are cylinders built in code; they move kinematically: every physics step
the commanded velocity ``(v, w)`` is integrated (unicycle model) and the base
body re-posed. A step that would push the footprint into a static obstacle
(rock, table), a movable object (block, sample), another robot or the field
border is refused: the robot stops and :attr:`Robot.bumped` becomes true.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.worldsim.arm import Arm
from alica.worldsim.camera_image import CameraImage
from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import Footprints, wrap_angle, yaw_to_quat
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.odometry import Odometry
from alica.worldsim.robot_specs import ROBOT_KINDS, RobotSpec

if TYPE_CHECKING:
    from alica.worldsim.world import World

__all__ = ["ROBOT_KINDS", "Arm", "Robot", "RobotSpec"]

logger = logging.getLogger(__name__)

# How far a robot may travel before its list of nearby obstacles is refreshed,
# and the longest time between refreshes (movable objects may have moved).
_NEAR_MARGIN = 0.5
_NEAR_STEPS = 60


class _Nearby:
    """What a moving robot may bump into: the obstacles within reach, and how far it may go without touching them.

    The list is refreshed as the robot goes (:meth:`refresh`: when it moved :data:`_NEAR_MARGIN`,
    after :data:`_NEAR_STEPS` steps, when bodies changed); the field border and other robots are
    checked at every step.

    Attributes:
        near: footprints of the static and movable obstacles within reach at the last refresh.
        at: where the robot was at the last refresh (``inf`` to force one).
        free: how far from ``at`` the footprint cannot touch anything in ``near``.
        age: steps since the last refresh.
        version: the world's body version at the last refresh.
    """

    __slots__ = ("_robot", "age", "at", "free", "near", "version")

    def __init__(self, robot: Robot) -> None:
        self._robot = robot
        self.near: list[tuple[float, ...]] = []
        self.at = (math.inf, math.inf)
        self.age = 0
        self.version = -1
        self.free = 0.0

    def refresh(self) -> None:
        """List what lies within reach of the robot now, and how far it may go before it can touch any of it."""
        robot = self._robot
        world = robot._world
        x, y, radius = robot._x, robot._y, robot.spec.radius
        reach = radius + _NEAR_MARGIN + robot.spec.max_speed * _NEAR_STEPS * world.time_step
        near = world._static_footprints.near(x, y, reach)
        held = world._held_bodies()
        movable = Footprints()
        for obj in world.objects.values():
            if obj.movable and obj.body_id not in held:
                fp = obj.footprint()
                if fp is None:
                    continue
                if fp.kind == "circle":
                    movable.add_circle(obj.name, fp.x, fp.y, fp.radius)
                else:
                    movable.add_box(obj.name, fp.x, fp.y, fp.half_x, fp.half_y, fp.yaw)
        near.extend(movable.near(x, y, reach))
        self.near = near
        # Within this distance of the refresh point the footprint cannot touch anything in ``near``
        # (nor what lies beyond ``reach``), so the per-step check skips them.
        clearance = reach - radius
        if near:
            gap = -Footprints.depth(x, y, radius, near)
            clearance = min(clearance, gap)
        self.free = max(0.0, clearance)
        self.at = (x, y)
        self.age = 0
        self.version = world._version

    def depth(self, x: float, y: float) -> float:
        """Deepest penetration of the robot's footprint at ``(x, y)`` into anything it must not touch."""
        robot = self._robot
        r = robot.spec.radius
        xmin, ymin, xmax, ymax = robot._world.bounds
        worst = max(xmin - (x - r), (x + r) - xmax, ymin - (y - r), (y + r) - ymax)
        if math.hypot(x - self.at[0], y - self.at[1]) >= self.free:
            worst = max(worst, Footprints.depth(x, y, r, self.near))
        for other in robot._world.robots.values():
            if other is not robot:
                d = r + other.spec.radius - math.hypot(x - other._x, y - other._y)
                worst = max(worst, d)
        return worst


class Robot:
    """One robot in a :class:`~alica.worldsim.world.World` (make it with ``world.add_robot``).

    Attributes:
        name: unique name in the world.
        spec: the :class:`RobotSpec` of its kind.
        body_id: the pybullet body of the base.
        arm: the :class:`~alica.worldsim.arm.Arm` (``None`` for robots without one).
        bumped: true when the last drive command was stopped by a collision;
            cleared by the next :meth:`drive` (callers may also reset it).
    """

    __slots__ = (
        "_crashed",
        "_nearby",
        "_odometry",
        "_v",
        "_w",
        "_world",
        "_x",
        "_y",
        "_yaw",
        "arm",
        "body_id",
        "bumped",
        "name",
        "spec",
    )

    def __init__(self, world: World, name: str, spec: RobotSpec, pose: Sequence[float]) -> None:
        self._world = world
        self.name = name
        self.spec = spec
        self._x, self._y, self._yaw = float(pose[0]), float(pose[1]), wrap_angle(float(pose[2]))
        self._v = 0.0
        self._w = 0.0
        self._crashed = False
        self.bumped = False
        self._nearby = _Nearby(self)
        c = world.client
        half = 0.5 * spec.height
        self.body_id: int = c.createMultiBody(
            baseMass=0.0,
            baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_CYLINDER, radius=spec.radius, height=spec.height),
            baseVisualShapeIndex=c.createVisualShape(
                c.GEOM_CYLINDER, radius=spec.radius, length=spec.height, rgbaColor=spec.colour
            ),
            basePosition=(self._x, self._y, half),
            baseOrientation=yaw_to_quat(self._yaw),
            useMaximalCoordinates=True,
        )
        self.arm: Arm | None = Arm(self, mount_offset=(spec.radius - 0.12, 0.0, spec.height)) if spec.has_arm else None
        self._odometry = Odometry(self, world.seed)

    # ------------------------------------------------------------------ state
    @property
    def world(self) -> World:
        """The world the robot lives in."""
        return self._world

    @property
    def pose(self) -> tuple[float, float, float]:
        """``(x, y, yaw)`` of the base."""
        return (self._x, self._y, self._yaw)

    @property
    def estimate(self) -> tuple[float, float, float]:
        """``(x, y, yaw)`` the robot believes it has: its odometry, corrected by localization.

        The true :attr:`pose` while ``world.noise.odometry_drift`` is 0 and nothing corrected it
        (see :mod:`alica.worldsim.odometry`).
        """
        return self._odometry.pose

    def lidar(self, n_rays: int, max_range: float | None = None) -> np.ndarray:
        """One scan of the 2-D lidar: ``n_rays`` ranges in metres over the full circle, from the heading on.

        See :func:`alica.worldsim.sensors.lidar_scan` (seeded range noise; a ray without a hit reads ``max_range``).

        Raises:
            WorldError: fewer than 1 ray or a range inside the robot.
        """
        from alica.worldsim.sensors import lidar_scan

        return lidar_scan(self, n_rays, max_range)

    @staticmethod
    def lidar_angles(n_rays: int) -> np.ndarray:
        """The angles of a scan's ``n_rays`` rays relative to the heading (:func:`alica.worldsim.sensors.lidar_angles`)."""
        from alica.worldsim.sensors import lidar_angles

        return lidar_angles(n_rays)

    @property
    def lidar_noise(self) -> float:
        """Standard deviation in metres of the lidar's range noise (the world's seeded sensor noise)."""
        return float(self.world.noise.lidar_sigma)

    def camera_pose(
        self, pose: tuple[float, float, float] | None = None, pan: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Where the camera is and how it is turned, ``(position, rotation world-from-camera)``, for the base
        at ``pose`` (default the true pose) panned ``pan`` radians left (:func:`alica.worldsim.robot_camera.camera_pose`)."""
        from alica.worldsim.robot_camera import camera_pose

        return camera_pose(self, pose, pan)

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
        """One picture of the robot's camera (colour, depth, intrinsics, pose): see :func:`alica.worldsim.robot_camera.robot_camera`.

        Raises:
            WorldError: no camera, a bad size, field of view, range or a pan beyond the limit.
        """
        from alica.worldsim.robot_camera import robot_camera

        return robot_camera(
            self, width=width, height=height, fov=fov, far=far, pan=pan, believed=believed, window=window
        )

    def set_estimate(self, pose: Sequence[float]) -> None:
        """Overwrite the pose estimate ``(x, y, yaw)`` (a localization's correction); odometry continues from it.

        Raises:
            WorldError: not three finite numbers.
        """
        try:
            x, y, yaw = (float(v) for v in pose)
        except (TypeError, ValueError):
            raise WorldError(f"set_estimate of robot '{self.name}' takes (x, y, yaw), got {pose!r}") from None
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise WorldError(f"set_estimate of robot '{self.name}' needs finite numbers, got {pose!r}")
        self._odometry.set((x, y, yaw))

    @property
    def odometry(self) -> Odometry:
        """The robot's :class:`~alica.worldsim.odometry.Odometry` (distance driven, drift bias)."""
        return self._odometry

    @property
    def velocity(self) -> tuple[float, float]:
        """The current command ``(v, w)`` after clipping (zero when stopped)."""
        return (self._v, self._w)

    @property
    def crashed(self) -> bool:
        """A crashed robot ignores every command (see :func:`alica.worldsim.faults.crash`)."""
        return self._crashed

    @property
    def gripper(self) -> Arm | None:
        """The arm, which carries the gripper methods (``open``, ``close``, ``attach``, ...)."""
        return self.arm

    @property
    def capabilities(self) -> frozenset[str]:
        """The capability words of the robot's kind."""
        return self.spec.capabilities

    def footprint(self) -> Obstacle2D:
        """The base footprint as a circle."""
        return Obstacle2D("circle", self._x, self._y, radius=self.spec.radius, name=self.name)

    def set_pose(self, x: float | Sequence[float], y: float | None = None, yaw: float | None = None) -> None:
        """Put the robot at ``(x, y, yaw)`` (also ``set_pose((x, y, yaw))``), arm and held object with it.

        The pose is checked against the field only; overlaps are allowed (the
        robot may drive out of them).

        Raises:
            WorldError: a pose off the field or not three numbers.
        """
        if y is None:
            try:
                x, y, yaw = (float(v) for v in x)  # type: ignore[union-attr]
            except (TypeError, ValueError):
                raise WorldError(f"set_pose of robot '{self.name}' takes (x, y, yaw), got {x!r}") from None
        x, y = float(x), float(y)  # type: ignore[arg-type]
        yaw = self._yaw if yaw is None else float(yaw)
        self._world.field.check(x, y, f"robot '{self.name}'", self.spec.radius)
        self._x, self._y, self._yaw = x, y, wrap_angle(yaw)
        self._nearby.at = (math.inf, math.inf)
        self._apply_pose()
        self._odometry.reset()

    # --------------------------------------------------------------- commands
    def drive(self, v: float, w: float) -> None:
        """Command forward speed ``v`` (m/s) and turn rate ``w`` (rad/s), clipped to the spec.

        The command holds until changed; it clears :attr:`bumped`. A crashed robot ignores it.
        """
        if self._crashed:
            logger.debug("robot %s is crashed; drive(%s, %s) ignored", self.name, v, w)
            return
        v, w = float(v), float(w)
        if not (math.isfinite(v) and math.isfinite(w)):
            raise WorldError(f"drive of robot '{self.name}' needs finite v and w, got ({v}, {w})")
        s, r = self.spec.max_speed, self.spec.max_yaw_rate
        self._v = min(s, max(-s, v))
        self._w = min(r, max(-r, w))
        self.bumped = False

    def stop(self) -> None:
        """Stop the base (the arm keeps following its path)."""
        self._v = 0.0
        self._w = 0.0

    def crash(self) -> None:
        """Lose power: base and arm stop, the gripper lets go of what it holds, later commands are ignored.

        The released object falls where it is (physics); :meth:`recover` powers the robot up again.
        """
        self._crashed = True
        self.stop()
        if self.arm is not None:
            self.arm.stop()
            dropped = self.arm.detach()
            if dropped is not None:
                logger.info("robot %s crashed and dropped '%s'", self.name, dropped.name)
        logger.info("robot %s crashed", self.name)

    def recover(self) -> None:
        """Power up after a crash: the robot stands where it stopped and takes commands again."""
        if not self._crashed:
            return
        self._crashed = False
        self.stop()
        logger.info("robot %s recovered", self.name)

    # --------------------------------------------------------------- internals
    def _apply_pose(self) -> None:
        yaw = self._yaw
        quat = (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))
        self._world._reset_base(self.body_id, (self._x, self._y, 0.5 * self.spec.height), quat)
        if self.arm is not None:
            self.arm._base_moved()

    def _advance(self, dt: float) -> bool:
        """Integrate the command over one physics step; returns whether the base moved."""
        v, w = self._v, self._w
        if v == 0.0 and w == 0.0:
            return False
        yaw = self._yaw
        ds = 0.0
        if v != 0.0:
            mid = yaw + 0.5 * w * dt
            nx = self._x + v * math.cos(mid) * dt
            ny = self._y + v * math.sin(mid) * dt
            nearby = self._nearby
            nearby.age += 1
            if (
                nearby.version != self._world._version
                or nearby.age >= _NEAR_STEPS
                or math.hypot(nx - nearby.at[0], ny - nearby.at[1]) > _NEAR_MARGIN
            ):
                nearby.refresh()
            new = nearby.depth(nx, ny)
            if new > 0.0 and new > nearby.depth(self._x, self._y) + 1e-12:
                self._v = 0.0
                self._w = 0.0
                self.bumped = True
                logger.debug("robot %s bumped at (%.3f, %.3f)", self.name, self._x, self._y)
                return False
            self._x, self._y = nx, ny
            ds = v * dt
        self._yaw = wrap_angle(yaw + w * dt)
        self._apply_pose()
        self._odometry.advance(ds, w * dt)
        return True

    def _state(self) -> dict[str, Any]:
        return {
            "pose": self.pose,
            "v": self._v,
            "w": self._w,
            "bumped": self.bumped,
            "crashed": self._crashed,
            "odometry": self._odometry._state(),
        }

    def _restore(self, state: dict[str, Any]) -> None:
        self._x, self._y, self._yaw = state["pose"]
        self._v, self._w = state["v"], state["w"]
        self.bumped = state["bumped"]
        self._crashed = state["crashed"]
        self._nearby.at = (math.inf, math.inf)
        self._apply_pose()
        if "odometry" in state:
            self._odometry._restore(state["odometry"])

    def __repr__(self) -> str:
        return f"Robot({self.name!r}, {self.spec.kind!r}, pose=({self._x:.3f}, {self._y:.3f}, {self._yaw:.3f}))"
