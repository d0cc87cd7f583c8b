"""A robot without pybullet: a kinematic unicycle with a simulated 2-D lidar on an occupancy map.

The smallest world that satisfies the robot interface
(:mod:`alica.worldsim.interface`): :class:`UnicycleWorld` is a
:class:`~alica.worldsim.interface.RobotWorld`, its robots
:class:`~alica.worldsim.interface.MobileRobot`. It is the example of a robot
driver of one's own (issue 38): a driver for real hardware offers the same
members, reading its pose from odometry and its scans from its laser instead
of from a map.

* **Map.** :class:`OccupancyMap`: a grid of free and occupied cells
  (``OccupancyMap.from_rows`` reads ``#`` and ``.`` rows, the first row at the top).
* **Motion.** ``drive(v, w)`` sets the command; ``world.step(seconds)`` integrates
  it in small steps (exact arcs). A step that would bring the robot's disc onto
  an occupied cell or another robot is not taken: the robot stops and
  ``bumped`` is set.
* **Lidar.** ``lidar(n)`` casts ``n`` rays over the full circle from the heading
  on, marching at a quarter of a cell, with Gaussian range noise from the
  world's seed; no hit reads ``max_range``.
* **No camera, no arm**: :meth:`UnicycleRobot.camera` raises a clear error,
  ``arm`` is ``None``, and its spec's capabilities are only ``base`` and
  ``lidar2d``; skills that need more refuse such a robot.
* **Plug-in.** :func:`make_robot` is the robot factory of ``--robot unicycle``
  (the entry point of the group ``alica.robots``): one robot in a world of its
  own, from string options (a map file, a pose, a kind).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alica.clock import ManualClock
from alica.worldsim.camera_image import CameraImage
from alica.worldsim.errors import WorldError
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing
from alica.worldsim.robot_specs import ROBOT_KINDS, RobotSpec

__all__ = ["FIELD", "OccupancyMap", "UnicycleRobot", "UnicycleWorld", "make_robot"]

_SUBSTEP = 0.02
"""Seconds of one integration step of :meth:`UnicycleWorld.step`."""


class OccupancyMap:
    """Occupied and free square cells of ``resolution`` metres, cell ``[0, 0]`` at ``origin`` (its lower-left corner).

    Args:
        occupied: booleans, ``occupied[row, col]``; row 0 is the lowest ``y``.
        resolution: cell size in metres (> 0).
        origin: ``(x, y)`` of the lower-left corner of cell ``[0, 0]``.
    """

    def __init__(self, occupied: np.ndarray, resolution: float, origin: tuple[float, float] = (0.0, 0.0)) -> None:
        cells = np.asarray(occupied, dtype=bool)
        if cells.ndim != 2 or cells.size == 0:
            raise ValueError(f"an occupancy map is a non-empty 2-D grid, got shape {cells.shape}")
        if not resolution > 0:
            raise ValueError(f"resolution must be > 0 metres, got {resolution}")
        self.occupied = cells
        self.resolution = float(resolution)
        self.origin = (float(origin[0]), float(origin[1]))

    @classmethod
    def from_rows(
        cls, rows: Sequence[str], resolution: float, origin: tuple[float, float] = (0.0, 0.0)
    ) -> OccupancyMap:
        """A map from text rows of ``#`` (occupied) and ``.`` (free), the first row at the top (the largest ``y``)."""
        if not rows or len({len(row) for row in rows}) != 1 or set("".join(rows)) - {"#", "."}:
            raise ValueError("map rows must be non-empty, of one length, and made of '#' and '.' only")
        return cls(np.array([[ch == "#" for ch in row] for row in reversed(rows)]), resolution, origin)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the map."""
        rows, cols = self.occupied.shape
        x0, y0 = self.origin
        return (x0, y0, x0 + cols * self.resolution, y0 + rows * self.resolution)

    def blocked(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether each point is on an occupied cell or off the map."""
        col = np.floor((np.asarray(x) - self.origin[0]) / self.resolution).astype(int)
        row = np.floor((np.asarray(y) - self.origin[1]) / self.resolution).astype(int)
        rows, cols = self.occupied.shape
        inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
        out = np.ones(np.shape(col), dtype=bool)
        out[inside] = self.occupied[row[inside], col[inside]]
        return out

    def disc_free(self, x: float, y: float, radius: float) -> bool:
        """Whether a disc of ``radius`` at ``(x, y)`` touches no occupied cell and stays on the map."""
        angles = np.linspace(0.0, 2 * math.pi, 16, endpoint=False)
        rings = [0.0, radius / 2, radius]
        xs = np.concatenate([x + r * np.cos(angles) for r in rings])
        ys = np.concatenate([y + r * np.sin(angles) for r in rings])
        return not bool(self.blocked(xs, ys).any())

    def boxes(self) -> list[Obstacle2D]:
        """The occupied cells as boxes, each row's runs of cells merged into one."""
        out: list[Obstacle2D] = []
        half = self.resolution / 2
        for row, line in enumerate(self.occupied):
            col = 0
            while col < len(line):
                if not line[col]:
                    col += 1
                    continue
                end = col
                while end < len(line) and line[end]:
                    end += 1
                x = self.origin[0] + (col + end) * half
                y = self.origin[1] + (row + 0.5) * self.resolution
                out.append(Obstacle2D("box", x, y, half_x=(end - col) * half, half_y=half, name=f"cells {row}:{col}"))
                col = end
        return out


class UnicycleRobot:
    """A kinematic unicycle on an :class:`OccupancyMap` (see the module docstring); made by :meth:`UnicycleWorld.add_robot`."""

    def __init__(self, world: UnicycleWorld, name: str, spec: RobotSpec, pose: tuple[float, float, float]) -> None:
        self._world = world
        self._name = name
        self._spec = spec
        self._pose = (float(pose[0]), float(pose[1]), float(pose[2]))
        self._estimate = self._pose
        self._command = (0.0, 0.0)
        self.bumped = False
        self.crashed = False
        """Whether the robot is out (it no longer moves); a test or a fault sets it."""

    @property
    def name(self) -> str:
        return self._name

    @property
    def spec(self) -> RobotSpec:
        return self._spec

    @property
    def arm(self) -> None:
        return None

    @property
    def pose(self) -> tuple[float, float, float]:
        return self._pose

    @property
    def estimate(self) -> tuple[float, float, float]:
        return self._estimate

    def set_estimate(self, pose: tuple[float, float, float]) -> None:
        self._estimate = (float(pose[0]), float(pose[1]), float(pose[2]))

    @property
    def lidar_noise(self) -> float:
        return self._world.lidar_noise

    def lidar_angles(self, n_rays: int) -> np.ndarray:
        return np.linspace(0.0, 2 * math.pi, int(n_rays), endpoint=False)

    def lidar(self, n_rays: int, max_range: float | None = None) -> np.ndarray:
        reach = self._spec.lidar_range if max_range is None else float(max_range)
        x, y, yaw = self._pose
        angles = yaw + self.lidar_angles(n_rays)
        step = self._world.map.resolution / 4
        distances = np.arange(step, reach + step, step)
        xs = x + np.outer(np.cos(angles), distances)
        ys = y + np.outer(np.sin(angles), distances)
        hit = self._world.map.blocked(xs, ys) | self._world.robot_hits(xs, ys, self._name)
        first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
        ranges = np.where(first >= 0, distances[np.maximum(first, 0)], reach)
        noisy = ranges + self._world.rng.normal(0.0, self._world.lidar_noise, len(ranges)) * (first >= 0)
        return np.clip(noisy, 0.0, reach)

    def camera_pose(
        self, pose: tuple[float, float, float] | None = None, pan: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        raise WorldError(f"robot '{self._name}' is a unicycle without a camera")

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
        raise WorldError(f"robot '{self._name}' is a unicycle without a camera")

    def drive(self, v: float, w: float) -> None:
        spec = self._spec
        self._command = (
            max(-spec.max_speed, min(spec.max_speed, float(v))),
            max(-spec.max_yaw_rate, min(spec.max_yaw_rate, float(w))),
        )

    def stop(self) -> None:
        self._command = (0.0, 0.0)

    def crash(self) -> None:
        """Lose power: stop where it is (a fault; :meth:`recover` powers it up again)."""
        self._command = (0.0, 0.0)
        self.crashed = True

    def recover(self) -> None:
        """Power up again where it stopped."""
        self.crashed = False

    def _advance(self, dt: float) -> None:
        """Integrate the command over ``dt`` seconds (an exact arc); stay and bump instead of hitting something."""
        v, w = self._command
        if self.crashed or (v == 0.0 and w == 0.0):
            return
        x, y, yaw = self._pose
        if abs(w) < 1e-9:
            nx, ny = x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw)
        else:
            nx = x + v / w * (math.sin(yaw + w * dt) - math.sin(yaw))
            ny = y - v / w * (math.cos(yaw + w * dt) - math.cos(yaw))
        nyaw = math.atan2(math.sin(yaw + w * dt), math.cos(yaw + w * dt))
        moved = v != 0.0
        if moved and (
            not self._world.map.disc_free(nx, ny, self._spec.radius)
            or self._world.blocker(nx, ny, self._spec.radius, self._name)
        ):
            self._command = (0.0, 0.0)
            self.bumped = True
            return
        ex, ey, eyaw = self._estimate  # odometry: the same motion applied to the belief
        dx, dy = nx - x, ny - y
        turn = eyaw - yaw
        self._estimate = (
            ex + dx * math.cos(turn) - dy * math.sin(turn),
            ey + dx * math.sin(turn) + dy * math.cos(turn),
            math.atan2(math.sin(eyaw + nyaw - yaw), math.cos(eyaw + nyaw - yaw)),
        )
        self._pose = (nx, ny, nyaw)


class UnicycleWorld:
    """Unicycle robots on an :class:`OccupancyMap`: a :class:`~alica.worldsim.interface.RobotWorld` without pybullet.

    Args:
        occupancy: the map.
        seed: seeds the lidar's noise (the same seed, the same scans).
        lidar_noise: standard deviation of the lidar's range noise in metres.
        clock: the simulated clock :meth:`step` advances (a new one at 0 when omitted).
    """

    def __init__(
        self, occupancy: OccupancyMap, *, seed: int = 0, lidar_noise: float = 0.01, clock: ManualClock | None = None
    ) -> None:
        self.map = occupancy
        self.clock = clock or ManualClock()
        self._seed = int(seed)
        self.rng = np.random.default_rng(self._seed)
        self.lidar_noise = float(lidar_noise)
        self._robots: dict[str, UnicycleRobot] = {}

    def add_robot(self, kind: str | RobotSpec, name: str, pose: Sequence[float] = (0.0, 0.0, 0.0)) -> UnicycleRobot:
        """Put a robot of ``kind`` (a key of :data:`~alica.worldsim.robot_specs.ROBOT_KINDS`, or a spec) at ``pose``.

        Raises:
            WorldError: an unknown kind, a name taken, or a pose where the robot does not fit.
        """
        spec = kind if isinstance(kind, RobotSpec) else ROBOT_KINDS.get(kind)
        if spec is None:
            raise WorldError(f"no robot kind '{kind}'; kinds: {', '.join(sorted(ROBOT_KINDS))}")
        if name in self._robots:
            raise WorldError(f"a robot named '{name}' is already in the world")
        x, y, yaw = (float(v) for v in pose)
        if not self.map.disc_free(x, y, spec.radius) or self.blocker(x, y, spec.radius):
            raise WorldError(f"robot '{name}' does not fit at ({x:g}, {y:g}): an occupied cell or a robot is there")
        spec = dataclasses.replace(spec, capabilities=spec.capabilities & {"base", "lidar2d"})  # what it has
        robot = self._robots[name] = UnicycleRobot(self, name, spec, (x, y, yaw))
        return robot

    @property
    def robots(self) -> Mapping[str, UnicycleRobot]:
        return dict(self._robots)

    @property
    def objects(self) -> Mapping[str, WorldThing]:
        return {}

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        return self.map.bounds

    @property
    def seed(self) -> int:
        return self._seed

    def now(self) -> float:
        return self.clock.now()

    def step(self, seconds: float) -> int:
        """Move time on by ``seconds``, every robot driving its command; returns the integration steps taken."""
        steps = max(1, round(seconds / _SUBSTEP))
        for _ in range(steps):
            for robot in self._robots.values():
                robot._advance(seconds / steps)
        self.clock.advance(seconds)
        return steps

    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        return self.map.boxes()

    def blocker(self, x: float, y: float, radius: float, ignore: str | None = None) -> str | None:
        for other in self._robots.values():
            if other.name != ignore and math.hypot(other.pose[0] - x, other.pose[1] - y) < radius + other.spec.radius:
                return f"robot '{other.name}'"
        if not self.map.disc_free(x, y, radius):
            return "an occupied cell of the map"
        return None

    def robot_hits(self, xs: np.ndarray, ys: np.ndarray, ignore: str) -> np.ndarray:
        """Whether each point is inside another robot's disc (what a lidar sees of the other robots)."""
        hits = np.zeros(np.shape(xs), dtype=bool)
        for other in self._robots.values():
            if other.name != ignore:
                ox, oy, _ = other.pose
                hits |= (xs - ox) ** 2 + (ys - oy) ** 2 <= other.spec.radius**2
        return hits

    def blocks_facts(self) -> set[tuple[str, ...]]:
        return set()


#: The field of :func:`make_robot` without a ``map`` option: 12 m x 12 m of 0.25 m cells, walled, with three blocks.
FIELD = (
    ["#" * 48]
    + ["#" + "." * 46 + "#"] * 9
    + ["#" + "." * 10 + "#" * 4 + "." * 32 + "#"] * 12
    + ["#" + "." * 46 + "#"] * 4
    + ["#" + "." * 24 + "#" * 14 + "." * 8 + "#"] * 4
    + ["#" + "." * 46 + "#"] * 8
    + ["#" + "." * 6 + "#" * 6 + "." * 34 + "#"] * 3
    + ["#" + "." * 46 + "#"] * 6
    + ["#" * 48]
)


def make_robot(name: str, role: str, options: Mapping[str, str]) -> UnicycleWorld:
    """The robot factory of the plug-in ``unicycle``: a world of its own holding one unicycle named ``name``.

    Options (all strings, as ``--robot-option KEY=VALUE`` gives them):

    * ``map``: a text file of ``#`` (occupied) and ``.`` (free) rows, the first row at the top
      (default :data:`FIELD`);
    * ``resolution``: metres per cell (default 0.25);
    * ``origin``: ``x,y`` of the map's lower-left corner (default ``0,0``);
    * ``pose``: ``x,y,yaw`` where the robot starts (default: 1 m from the lower-left corner, ``x0+1,y0+1,0``);
    * ``kind``: the robot kind whose size and speeds it takes (default: the role's, lower-cased, when
      it is a kind; else ``scout``);
    * ``seed``: the lidar noise's seed (default 0); ``lidar_noise``: its standard deviation in metres
      (default 0.01).

    The world is simulated: the run steps it (:meth:`UnicycleWorld.step`) once per tick.

    Raises:
        ValueError: an unknown option, or a value that is not what the option takes (the message says which).
        WorldError: the robot does not fit where it starts.
    """
    known = {"map", "resolution", "origin", "pose", "kind", "seed", "lidar_noise"}
    unknown = sorted(set(options) - known)
    if unknown:
        raise ValueError(f"the unicycle has no option {', '.join(unknown)}; its options: {', '.join(sorted(known))}")

    def number(key: str, default: float) -> float:
        text = options.get(key)
        try:
            value = default if text is None else float(text)
        except ValueError:
            raise ValueError(f"option {key}: '{text}' is not a number") from None
        if not math.isfinite(value):
            raise ValueError(f"option {key}: '{text}' is not a finite number")
        return value

    rows = FIELD
    if "map" in options:
        try:
            rows = [line.strip() for line in Path(options["map"]).read_text(encoding="utf-8").splitlines()]
        except (OSError, UnicodeDecodeError) as exc:
            raise ValueError(f"option map: cannot read '{options['map']}': {exc}") from None
        rows = [row for row in rows if row]
    origin = option_numbers(options, "origin", "0,0", "x,y")
    try:
        occupancy = OccupancyMap.from_rows(rows, number("resolution", 0.25), (origin[0], origin[1]))
    except ValueError as exc:
        raise ValueError(f"option map: {exc}") from None
    pose = option_numbers(options, "pose", f"{origin[0] + 1:g},{origin[1] + 1:g},0", "x,y,yaw")
    kind = options.get("kind") or (role.lower() if role.lower() in ROBOT_KINDS else "scout")
    if kind not in ROBOT_KINDS:
        raise ValueError(f"option kind: no robot kind '{kind}'; kinds: {', '.join(sorted(ROBOT_KINDS))}")
    seed = number("seed", 0)
    if seed != int(seed):
        raise ValueError(f"option seed: '{options['seed']}' is not a whole number")
    noise = number("lidar_noise", 0.01)
    if noise < 0:
        raise ValueError(f"option lidar_noise: must be >= 0, got {noise:g}")
    world = UnicycleWorld(occupancy, seed=int(seed), lidar_noise=noise)
    world.add_robot(kind, name, pose)
    return world


def option_numbers(options: Mapping[str, str], key: str, default: str, shape: str) -> list[float]:
    """The comma-separated finite numbers of option ``key`` (as many as ``shape`` names)."""
    text = options.get(key, default)
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != shape.count(",") + 1 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"option {key}: '{text}' is not {shape} ({shape.count(',') + 1} numbers)")
    return values


if TYPE_CHECKING:  # mypy checks that the unicycle satisfies the robot interface

    def _is_a_robot_world(world: UnicycleWorld) -> RobotWorld:
        return world

    def _is_a_mobile_robot(robot: UnicycleRobot) -> MobileRobot:
        return robot
