"""The mapping skills: BuildMap (the team's first map around a robot) and Localize (scan matching).

Both act through the robot interface: the lidar (:func:`alica.worldsim.sensors.lidar_scan`)
and the robot's pose *estimate* (``robot.estimate``, odometry with drift),
never the true pose. The map is the team map of :mod:`alica.skills.mapping.sharing`.

Other skills that map as they go (exploration) use the same pieces:
:func:`robot_mapper` (this robot's layer, kept in the agent's scratch space)
and :func:`map_scan` (one scan into it, changed tiles published).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.context import SkillContextLike
from alica.skills.jobs import Job
from alica.skills.mapping.grid import LogOddsGrid
from alica.skills.mapping.matching import Match, compose, match_scan, relative
from alica.skills.mapping.sharing import RobotMapper, team_map
from alica.skills.world_skill import WorldSkill
from alica.worldmodel.protocol import WorldModelLike
from alica.worldsim.interface import MobileRobot

__all__ = [
    "MAPPER_KEY",
    "BuildMap",
    "Localize",
    "lidar",
    "map_scan",
    "rays_for",
    "robot_mapper",
]

#: The agent's scratch-space key of its :class:`RobotMapper`.
MAPPER_KEY = "mapping.mapper"
#: Fewest rays of a scan.
MIN_RAYS = 360
#: Most rays of a scan.
MAX_RAYS = 2880
#: Default resolution (m) when a skill maps without being told one (a lone Localize).
DEFAULT_RESOLUTION = 0.05
#: Fraction of the cells within ``radius`` that must be known for BuildMap to be done at once.
READY_FRACTION = 0.9
#: BuildMap is also done when the known fraction grew less than this over the last scans
#: (what rocks hide cannot be seen from where the robot stands).
STALL_GROWTH = 0.005
STALL_SCANS = 3


def rays_for(radius: float, resolution: float) -> int:
    """Rays per scan such that neighbouring rays lie at most a cell apart at ``radius``."""
    return int(min(MAX_RAYS, max(MIN_RAYS, math.ceil(2.0 * math.pi * radius / resolution))))


def lidar(robot: MobileRobot, n_rays: int, max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """One scan of ``robot``'s lidar: ``(ranges, angles)``, angles relative to the heading."""
    rng = min(float(max_range), float(robot.spec.lidar_range))
    return robot.lidar(n_rays, rng), robot.lidar_angles(n_rays)


def robot_mapper(
    context: SkillContextLike | None,
    robot: str,
    bounds: tuple[float, float, float, float],
    resolution: float,
) -> RobotMapper:
    """This robot's layer of the team map, made once per agent and kept in its scratch space.

    Raises:
        SkillError: a bad resolution, or a team map of another resolution.
    """
    scratch: dict[str, object] = context.scratch if context is not None else {}
    wm: WorldModelLike | None = context.world_model if context is not None else None
    mapper = scratch.get(MAPPER_KEY)
    if isinstance(mapper, RobotMapper) and mapper.robot == robot and mapper.world_model is wm:
        if math.isclose(mapper.layer.resolution, resolution, rel_tol=1e-9):
            return mapper
    try:
        mapper = RobotMapper.for_robot(wm, robot, bounds, resolution)
    except ValueError as exc:
        raise SkillError(f"robot '{robot}' cannot map at resolution {resolution}: {exc}") from None
    scratch[MAPPER_KEY] = mapper
    return mapper


def map_scan(
    robot: MobileRobot,
    mapper: RobotMapper,
    *,
    max_range: float,
    n_rays: int | None = None,
    now: float | None = None,
    force: bool = False,
) -> int:
    """Scan, ray trace the scan at the robot's pose estimate into its layer, publish the changed tiles.

    Args:
        robot: the scanning robot.
        mapper: its layer (:func:`robot_mapper`).
        max_range: the range traced, in metres (capped at the lidar's).
        n_rays: rays of the scan; by default enough for neighbouring rays to lie a cell apart at ``max_range``.
        now: the time, to publish at most once per ``mapper.period`` (``None``: publish now).
        force: publish every changed tile now.

    Returns:
        The bytes written to the world model.
    """
    rays = n_rays if n_rays is not None else rays_for(max_range, mapper.layer.resolution)
    ranges, angles = lidar(robot, rays, max_range)
    mapper.add_scan(robot.estimate, ranges, angles, min(max_range, robot.spec.lidar_range))
    return mapper.publish(now=now, force=force)


def _number(skill: WorldSkill, name: str, default: float, *, low: float = 0.0, high: float = math.inf) -> float:
    value = skill.param(name, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (low < value <= high):
        bound = f" and at most {high}" if math.isfinite(high) else ""
        raise SkillError(f"skill '{skill.name}': parameter '{name}' must be a number above {low}{bound}, got {value!r}")
    return float(value)


class BuildMap(WorldSkill):
    """Scan standing still until the map within ``radius`` of the robot is known; then assert ``mapped``.

    Every tick one lidar scan goes into the robot's layer of the team map
    and the changed tiles into the world model. The skill succeeds when at
    least 90 % of the cells within ``radius`` are known in the team map, or
    when that fraction stops growing (cells behind rocks stay unknown from
    here); it fails after ``timeout`` seconds.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot and check the parameters.

        Raises:
            SkillError: no world or robot, or a parameter out of range.
        """
        super().setup(**kwargs)
        self.resolution = _number(self, "resolution", 0.05, high=1.0)
        self.radius = _number(self, "radius", 5.0)
        self.max_range = _number(self, "max_range", 10.0)
        self.timeout = _number(self, "timeout", 30.0)
        if self.max_range < self.radius:
            raise SkillError(
                f"skill '{self.name}': parameter 'max_range' ({self.max_range} m) must be at least 'radius' ({self.radius} m)"
            )
        self.n_rays = rays_for(self.max_range, self.resolution)

    def initialise(self) -> None:
        """Stand still; find this robot's layer of the team map."""
        self.robot.stop()
        self.mapper = robot_mapper(self.context, self.robot.name, self.world.bounds, self.resolution)
        self.started = self.now()
        self.fractions: list[float] = []
        self.scans = 0

    def update(self) -> Status:
        """One scan into the map; done when the surroundings are known."""
        robot = self.robot
        robot.stop()
        map_scan(robot, self.mapper, max_range=self.max_range, n_rays=self.n_rays, force=True)
        self.scans += 1
        grid = team_map(self.world_model) or self.mapper.layer
        x, y, _ = robot.estimate
        known = grid.known_fraction(x, y, self.radius)
        self.fractions.append(known)
        stalled = len(self.fractions) > STALL_SCANS and known - self.fractions[-1 - STALL_SCANS] < STALL_GROWTH
        if known >= READY_FRACTION or stalled:
            self.write(True, "mapped")
            return self.succeed(
                f"mapped {known:.0%} of the cells within {self.radius:g} m after {self.scans} scans "
                f"({self.mapper.tiles_sent} tiles, {self.mapper.bytes_sent} bytes shared)"
            )
        if self.now() - self.started > self.timeout:
            return self.fail(f"only {known:.0%} of the cells within {self.radius:g} m known after {self.timeout:g} s")
        return self.running(f"mapping: {known:.0%} of the cells within {self.radius:g} m known")

    def terminate(self, new_status: Status) -> None:
        """Stop the base."""
        if self.has_robot:
            self.robot.stop()


class Localize(WorldSkill):
    """Correct the robot's pose estimate by matching lidar scans against the team map.

    A scan is taken at the current estimate and matched (:func:`match_scan`)
    as a job; the corrected pose of the scan, moved on by the odometry since,
    becomes the new estimate (``robot.set_estimate``). Without
    ``continuous`` the skill succeeds once a fit needs no further correction
    (less than two cells and half a degree), and fails after ``timeout``
    seconds without one. With ``continuous`` it corrects every ``period``
    seconds until its state is left (run it next to a driving skill).

    With no team map at all (the robot is alone) the robot first scans its
    surroundings into the map at its estimate, as BuildMap would: the map
    starts where it stands.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot and check the parameters.

        Raises:
            SkillError: no world or robot, or a parameter out of range.
        """
        super().setup(**kwargs)
        self.timeout = _number(self, "timeout", 30.0)
        self.period = _number(self, "period", 0.5)
        self.max_range = _number(self, "max_range", 10.0)
        continuous = self.param("continuous", False)
        if not isinstance(continuous, bool):
            raise SkillError(f"skill '{self.name}': parameter 'continuous' must be true or false, got {continuous!r}")
        self.continuous = continuous

    def initialise(self) -> None:
        """Start with a scan on the first tick."""
        self.started = self.now()
        self.next_scan = self.started
        self.job: Job | None = None
        self.scan_pose: tuple[float, float, float] = self.robot.estimate
        self.corrections = 0
        self.reason = ""
        self.last: Match | None = None
        self._res = DEFAULT_RESOLUTION

    def _map(self) -> LogOddsGrid | None:
        grid = team_map(self.world_model)
        if grid is not None and (grid.logodds > 0.2).any():
            return grid
        # alone: start the map here, at the estimate
        res = grid.resolution if grid is not None else DEFAULT_RESOLUTION
        mapper = robot_mapper(self.context, self.robot.name, self.world.bounds, res)
        map_scan(self.robot, mapper, max_range=self.max_range, force=True)
        if self.world_model is None:
            return mapper.layer
        return team_map(self.world_model)

    def update(self) -> Status:
        """Poll the running match, or start the next one."""
        now = self.now()
        if self.job is not None:
            if not self.job.done():
                return self.running("matching the scan against the map")
            match: Match = self.job.result()
            self.job = None
            self.last = match
            if match.ok:
                moved = relative(self.scan_pose, self.robot.estimate)  # odometry since the scan
                before = self.robot.estimate
                corrected = compose(match.pose, moved)
                self.robot.set_estimate(corrected)
                self.corrections += 1
                shift = math.hypot(corrected[0] - before[0], corrected[1] - before[1])
                turn = abs(math.remainder(corrected[2] - before[2], 2.0 * math.pi))
                if not self.continuous and shift < 2.0 * self._res and turn < math.radians(0.5):
                    return self.succeed(
                        f"localized at ({corrected[0]:.2f}, {corrected[1]:.2f}, {math.degrees(corrected[2]):.1f} deg): "
                        f"{match.inliers:.0%} of the hits on the map, rmse {match.rmse:.3f} m"
                    )
                self.reason = f"corrected by {shift:.3f} m, {math.degrees(turn):.2f} deg"
            else:
                self.reason = match.reason
        if not self.continuous and now - self.started > self.timeout:
            return self.fail(f"not localized within {self.timeout:g} s: {self.reason or 'no fit'}")
        if self.job is None and now >= self.next_scan:
            grid = self._map()
            if grid is None:
                return self.fail("no map to localize in")
            self._res = grid.resolution
            n_rays = rays_for(min(self.max_range, 8.0), grid.resolution)
            ranges, angles = lidar(self.robot, n_rays, self.max_range)
            self.scan_pose = self.robot.estimate
            rng = min(self.max_range, self.robot.spec.lidar_range)
            self.job = self.jobs.submit(match_scan, grid.copy(), self.scan_pose, ranges, angles, rng)
            self.next_scan = now + self.period
        return self.running(f"localizing ({self.corrections} corrections{': ' + self.reason if self.reason else ''})")
