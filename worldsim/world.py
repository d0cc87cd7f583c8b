"""The simulated world: one pybullet client, its robots and objects, simulated time.

Every pybullet call goes through the world's own
:class:`pybullet_utils.bullet_client.BulletClient` (DIRECT unless a GUI is asked
for and a display exists), so several worlds in one process do not interfere.
Time is simulated: :meth:`World.step` runs whole physics steps and advances
the world's :class:`~alica.clock.ManualClock`.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Sequence
from types import TracebackType
from typing import Any, Self

import numpy as np

from alica.clock import ManualClock
from alica.worldsim import bodies as _bodies
from alica.worldsim._quiet import quiet_stdout
from alica.worldsim.errors import WorldError
from alica.worldsim.faults import Faults, SensorNoise
from alica.worldsim.field import Field
from alica.worldsim.geometry import Footprints
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.objects import WorldObject
from alica.worldsim.queries import blocker, blocks_facts, contacts, obstacles
from alica.worldsim.resting import SETTLE_STEPS, Resting
from alica.worldsim.robots import ROBOT_KINDS, Robot, RobotSpec
from alica.worldsim.snapshots import Snapshots

with quiet_stdout():
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

__all__ = ["SETTLE_STEPS", "Obstacle2D", "World", "WorldError", "WorldObject"]

logger = logging.getLogger(__name__)


class World:
    """A pybullet world with kinematic robots, objects, sensors' ground truth and faults.

    Args:
        seed: seeds :attr:`rng` (sensor noise, faults); same seed and same calls give the same state.
        gui: open the pybullet GUI if a display is available (``DISPLAY`` set); DIRECT otherwise.
        time_step: the physics step in seconds.
        clock: the simulated clock to advance (a new one at 0 when omitted).
        bounds: the field ``(xmin, ymin, xmax, ymax)`` in metres.
        ground: add a flat ground plane named ``"ground"``.
        solver_iterations: pybullet's constraint solver iterations (its default when omitted).
        quiet: hide pybullet's C-level prints while connecting and loading models.
        rest_when_still: skip pybullet's step while nothing can move a body: no arm follows a
            path, nothing was added, removed, grasped or released, and every free object has
            been still for :data:`~alica.worldsim.resting.SETTLE_STEPS` steps. Robots, arms and the clock go on as usual;
            resting bodies stay where they are (as pybullet's own sleeping would keep them), and
            the run stays deterministic. Off by default: code that pushes bodies through
            :attr:`client` directly needs every step.
        arm_visuals: load the arms' detailed visual meshes. Without them pybullet draws the arms
            (in the GUI, pictures and the robots' cameras) from their collision hulls, and each
            arm costs about 1 MB instead of about 48 MB in pybullet's renderer; physics is the same.

    Attributes:
        field: the :class:`~alica.worldsim.field.Field` (its bounds) that robots and objects stay in.
        faults: the fault settings (:class:`~alica.worldsim.faults.Faults`); ``noise`` the sensors' noise.
        snapshots: saved states to go back to (:class:`~alica.worldsim.snapshots.Snapshots`).

    Raises:
        WorldError: a non-positive time step or empty bounds.
    """

    def __init__(
        self,
        seed: int = 0,
        *,
        gui: bool = False,
        time_step: float = 1.0 / 240.0,
        clock: ManualClock | None = None,
        bounds: Sequence[float] = (-10.0, -10.0, 10.0, 10.0),
        ground: bool = True,
        solver_iterations: int | None = None,
        quiet: bool = True,
        rest_when_still: bool = False,
        arm_visuals: bool = True,
    ) -> None:
        if not (time_step > 0.0 and math.isfinite(time_step)) or time_step > 0.1:
            raise WorldError(f"time_step must be in (0, 0.1] seconds, got {time_step}; 1/240 is pybullet's default")
        if len(bounds) != 4 or not (bounds[2] > bounds[0] and bounds[3] > bounds[1]):
            raise WorldError(
                f"bounds must be (xmin, ymin, xmax, ymax) with xmax > xmin and ymax > ymin, got {tuple(bounds)}"
            )
        self.seed = int(seed)
        self.rng: np.random.Generator = np.random.default_rng(self.seed)
        self.clock: ManualClock = clock if clock is not None else ManualClock()
        self.quiet = bool(quiet)
        self.arm_visuals = bool(arm_visuals)
        self._time_step = float(time_step)
        xmin, ymin, xmax, ymax = (float(b) for b in bounds)
        self.field = Field((xmin, ymin, xmax, ymax))
        self.robots: dict[str, Robot] = {}
        self.objects: dict[str, WorldObject] = {}
        self.faults = Faults(self)
        self.noise = SensorNoise()
        self._static_footprints = Footprints()
        self._version = 0
        self._steps = 0
        self._pending = 0.0
        self.rest_when_still = bool(rest_when_still)
        self.physics_steps = 0
        self._closed = False
        self._client = _connect(gui, self.quiet)
        self.snapshots = Snapshots(self)
        self._resting = Resting(self._client, self.objects, self._held_bodies)
        c = self._client
        c.setGravity(0.0, 0.0, -9.81)
        c.setTimeStep(self._time_step)
        c.setPhysicsEngineParameter(deterministicOverlappingPairs=1)
        if solver_iterations is not None:
            c.setPhysicsEngineParameter(numSolverIterations=int(solver_iterations))
        self._reset_base = c.resetBasePositionAndOrientation
        self._step_simulation = c.stepSimulation
        if ground:
            self.add_terrain()

    # ------------------------------------------------------------ properties
    @property
    def client(self) -> Any:
        """The world's own pybullet client (a ``BulletClient``); use it for every pybullet call."""
        return self._client

    @property
    def time_step(self) -> float:
        """The physics step in seconds."""
        return self._time_step

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The field ``(xmin, ymin, xmax, ymax)``."""
        return self.field.bounds

    @property
    def steps(self) -> int:
        """Physics steps run so far."""
        return self._steps

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._closed

    def now(self) -> float:
        """The simulated time (the clock's)."""
        return self.clock.now()

    # --------------------------------------------------------------- stepping
    def step(self, seconds: float) -> int:
        """Simulate ``seconds``: whole physics steps, robot motion and attachments per step, the clock advanced.

        Fractions of a step are carried over to the next call, so many small
        calls add up to the same number of steps as one large one.

        Returns:
            The number of physics steps run.

        Raises:
            WorldError: a negative or non-finite duration, or a closed world.
        """
        self._check_open()
        if not (seconds >= 0.0 and math.isfinite(seconds)):
            raise WorldError(f"step needs a duration >= 0 seconds, got {seconds}")
        dt = self._time_step
        self._pending += seconds
        n = int(self._pending / dt + 1e-6)
        self._pending = max(0.0, self._pending - n * dt)
        robots = list(self.robots.values())
        arms = [r.arm for r in robots if r.arm is not None]
        step_simulation = self._step_simulation
        t = self.clock.now()
        rest = self.rest_when_still
        for _ in range(n):
            if not rest or self._resting.needed(self._version, arms):
                step_simulation()
                self.physics_steps += 1
            t += dt
            for robot in robots:
                if robot._v != 0.0 or robot._w != 0.0:  # a robot without a command does not move
                    robot._advance(dt)
            for arm in arms:
                if (
                    arm._path is not None or arm._moved or arm._base_dirty or arm._slip_at is not None
                ):  # else nothing to do
                    arm._update(dt, t)
        self._steps += n
        if n:
            self.clock.advance(n * dt)
        return n

    # ------------------------------------------------------------- building
    def add_robot(self, kind: str | RobotSpec, name: str, pose: Sequence[float] = (0.0, 0.0, 0.0)) -> Robot:
        """Add a robot of a kind of :data:`~alica.worldsim.robots.ROBOT_KINDS` (or a custom spec) at ``(x, y, yaw)``.

        Raises:
            WorldError: an unknown kind, a name taken, a pose off the field or overlapping something.
        """
        self._check_open()
        if isinstance(kind, RobotSpec):
            spec = kind
        elif kind in ROBOT_KINDS:
            spec = ROBOT_KINDS[kind]
        else:
            raise WorldError(f"unknown robot kind {kind!r}; use one of {', '.join(ROBOT_KINDS)} or pass a RobotSpec")
        self._check_name(name)
        if len(pose) != 3 or not all(math.isfinite(float(v)) for v in pose):
            raise WorldError(f"the pose of robot '{name}' is (x, y, yaw) of finite numbers, got {tuple(pose)}")
        x, y, yaw = (float(v) for v in pose)
        self.field.check(x, y, f"robot '{name}'", spec.radius)
        blocker = self.blocker(x, y, spec.radius)
        if blocker is not None:
            raise WorldError(f"robot '{name}' at ({x:.2f}, {y:.2f}) would overlap {blocker}; choose a free pose")
        with quiet_stdout(self.quiet):
            robot = Robot(self, name, spec, (x, y, yaw))
        self.robots[name] = robot
        self._version += 1
        return robot

    def add_block(
        self,
        name: str,
        position: Sequence[float],
        size: float = 0.05,
        colour: str | Sequence[float] | None = None,
        mass: float = 0.1,
    ) -> WorldObject:
        """Add a cube of edge ``size`` (a 2-D position puts it on the ground)."""
        return self._register(name, _bodies.make_block, position, size=size, colour=colour, mass=mass)

    def add_sample(self, name: str, kind: str, position: Sequence[float]) -> WorldObject:
        """Add an IMPERA sample container of a kind of :data:`~alica.worldsim.objects.SAMPLE_KINDS`."""
        return self._register(name, _bodies.make_sample, kind, position)

    def add_collection_point(self, name: str, position: Sequence[float], radius: float = 0.5) -> WorldObject:
        """Add a flat marker disc (not an obstacle)."""
        return self._register(name, _bodies.make_collection_point, position, radius=radius)

    def add_table(
        self,
        name: str,
        position: Sequence[float],
        size: Sequence[float] = (1.0, 0.6),
        height: float = 0.4,
        yaw: float = 0.0,
    ) -> WorldObject:
        """Add a solid table ``size = (length, width)`` of ``height`` (a static obstacle)."""
        obj = self._register(name, _bodies.make_table, position, size=size, height=height, yaw=yaw)
        pos = obj.pose()[0]
        self._static_footprints.add_box(name, pos[0], pos[1], obj.half_extents[0], obj.half_extents[1], float(yaw))
        return obj

    def add_rock(
        self, name: str, position: Sequence[float], radius: float, seed: int = 0, height_ratio: float = 0.7
    ) -> WorldObject:
        """Add a static convex rock whose footprint is a circle of ``radius``."""
        obj = self._register(name, _bodies.make_rock, position, radius, seed=seed, height_ratio=height_ratio)
        pos = obj.pose()[0]
        self._static_footprints.add_circle(name, pos[0], pos[1], obj.radius)
        return obj

    def add_terrain(self, name: str = "ground", friction: float = 0.8) -> WorldObject:
        """Add a flat ground plane at z = 0."""
        return self._register(name, _bodies.make_terrain, friction=friction)

    def _register(self, name: str, maker: Any, *args: Any, **kwargs: Any) -> WorldObject:
        self._check_open()
        self._check_name(name)
        obj = maker(self, name, *args, **kwargs)
        self.objects[name] = obj
        self._version += 1
        return obj

    def remove(self, name: str) -> None:
        """Remove a robot (with its arm) or an object; saved states are dropped.

        Raises:
            WorldError: no robot or object of that name.
        """
        self._check_open()
        c = self._client
        if name in self.robots:
            robot = self.robots.pop(name)
            if robot.arm is not None:
                robot.arm.detach()
                c.removeBody(robot.arm.body_id)
            c.removeBody(robot.body_id)
        elif name in self.objects:
            obj = self.objects[name]
            for robot in self.robots.values():
                if robot.arm is not None and robot.arm.held is obj:
                    robot.arm.detach()
            del self.objects[name]
            self._static_footprints.remove(name)
            c.removeBody(obj.body_id)
        else:
            raise WorldError(
                f"remove: no robot or object named '{name}' (robots: {', '.join(sorted(self.robots)) or '-'}; "
                f"objects: {', '.join(sorted(self.objects)) or '-'})"
            )
        self.snapshots.discard_all()
        self._version += 1

    # ----------------------------------------------------------- ground truth
    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        """Footprints of the obstacles: rocks as circles, tables and blocks as rectangles.

        Held objects are left out; samples only with ``include_samples``.
        """
        return obstacles(self, include_samples=include_samples)

    def blocker(self, x: float, y: float, radius: float) -> str | None:
        """What a circle at ``(x, y)`` would overlap (``"rock 'r3'"``), or ``None`` (held objects do not count)."""
        return blocker(self, x, y, radius)

    def blocks_facts(self) -> set[tuple[str, ...]]:
        """The IPC blocks facts of the simulated state (:func:`~alica.worldsim.queries.blocks_facts`): perfect perception."""
        return blocks_facts(self)

    def is_free(self, x: float, y: float, radius: float, *, margin: float = 0.0) -> bool:
        """Whether a circle fits in the field without touching obstacles, movable objects or robots."""
        return self.field.inside(x, y, radius + margin) and self.blocker(x, y, radius + margin) is None

    def contacts(self, robot: Robot | str, *, margin: float = 0.0, include_ground: bool = False) -> set[str]:
        """Names of the robots and objects that the robot's base, arm or held object touches (within ``margin``).

        The ground counts only with ``include_ground``.
        """
        robot = self.robots[robot] if isinstance(robot, str) else robot
        return contacts(self, robot, margin=margin, include_ground=include_ground)

    # -------------------------------------------------------------- lifecycle
    def close(self) -> None:
        """Disconnect the pybullet client (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self.snapshots.forget()
        try:
            self._client.disconnect()
        except pybullet.error:
            pass

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"World(seed={self.seed}, t={self.now():.3f}, robots={sorted(self.robots)}, objects={len(self.objects)})"

    # -------------------------------------------------------------- internals
    def _check_open(self) -> None:
        if self._closed:
            raise WorldError("the world is closed; make a new World")

    def _check_name(self, name: str) -> None:
        if not isinstance(name, str) or not name:
            raise WorldError(f"a name must be a non-empty string, got {name!r}")
        if name in self.robots or name in self.objects:
            what = "robot" if name in self.robots else self.objects[name].kind
            raise WorldError(f"the name '{name}' is taken by a {what}; choose another name or remove('{name}') first")

    def _held_bodies(self) -> set[int]:
        return {r.arm.held.body_id for r in self.robots.values() if r.arm is not None and r.arm.held is not None}


def _connect(gui: bool, quiet: bool) -> Any:
    """A new pybullet client: DIRECT, or a GUI when asked for and possible."""
    mode = pybullet.DIRECT
    if gui:
        if os.environ.get("DISPLAY"):
            mode = pybullet.GUI
        else:
            logger.warning(
                "gui=True but DISPLAY is not set; running without a GUI (pybullet would exit without an X server)"
            )
    with quiet_stdout(quiet):
        client = BulletClient(connection_mode=mode)
        if client._client < 0 and mode == pybullet.GUI:
            logger.warning("could not open a pybullet GUI (only one per process); running without one")
            client = BulletClient(connection_mode=pybullet.DIRECT)
    return client
