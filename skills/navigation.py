"""Driving skills: MoveToPosition (and its primitive DriveTo), DriveToFreeSpace, Idle.

MoveToPosition plans in SE2 with OMPL on an occupancy grid, inflated by the
robot's radius (:func:`alica.skills.motion.plan_path`), follows the path,
replans when another robot or a new obstacle blocks it, and when the robot is
stuck (bumped, or no progress) drives into free space first. Planning runs as
a job; ``update`` only polls. The robot drives by its pose *estimate*
(``robot.estimate``: odometry, corrected by Localize), which is its true pose
while the world's odometry drift is 0.

Which grid depends on what the robot knows (:func:`planning_grid`):

* **Map mode**: the skill's world model holds a team map
  (:func:`alica.skills.mapping.team_map`, the lunar mission after BuildMap).
  The robot plans on that map: occupied cells are obstacles, unknown cells
  count as free (it drives into the unknown and replans when the map shows
  an obstacle on its path: the path check reads the current team map), and
  the cells of the robots' bodies (teammates' lidar sees them) are cleared
  around the robots' current positions. There is no exact check against the
  rocks' meshes: the map is all the robot knows of them. While it drives the
  robot scans into its own layer of the team map (:func:`alica.skills.mapping.map_scan`),
  so a robot that does not explore still maps the rocks on its way.
* **Known-map mode**: without a team map (the blocks world, a skill run alone
  in a test or by ``alica skill run``) the world's layout is known: the grid
  is rasterised from the world's obstacles (tables, rocks, blocks) and a path
  is checked exactly with FCL against the rocks' meshes and the tables.
  Samples are left out (work sites the manipulation skills drive up to); a
  robot that bumps into one remembers the spot and plans around it for the
  rest of the drive, as in map mode.

In both modes the other robots are the poses the teammates shared through the
world model (``_others``, :mod:`alica.skills.team_poses`): a teammate that
never shared, or whose pose is stale, is not avoided (in map mode the team map
still shows its body where the lidar saw it).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from py_trees.common import Status

from alica.skills.context import SkillContextLike
from alica.skills.jobs import Job
from alica.skills.team_poses import BeliefLike, teammates
from alica.skills.world_skill import WorldSkill, distance, world_cache
from alica.worldmodel.protocol import WorldModelLike
from alica.worldsim.interface import MobileRobot, RobotWorld

if TYPE_CHECKING:
    from alica.skills.mapping import LogOddsGrid
    from alica.skills.motion import FclChecker, GridChecker, PathFollower
    from alica.worldsim.grid import OccupancyGrid

#: Replans (after being stuck or blocked) before MoveToPosition gives up.
MAX_REPLANS = 5
#: Simulated seconds between two reads of the team map by the driving skills (map mode).
MAP_PERIOD = 1.0
#: Metres beyond a robot's radius within which the team map's occupied cells count as that robot's body (map mode).
BODY_MARGIN = 0.1
#: Simulated seconds between two scans a driving robot adds to its layer of the team map (map mode).
DRIVE_SCAN_PERIOD = 1.0
#: Metres of lidar range a driving robot maps (map mode).
DRIVE_SCAN_RANGE = 6.0
#: Radius in metres of what the robot remembers it bumped into, just ahead of it (map mode).
BUMP_RADIUS = 0.1
#: Bumps remembered per drive (map mode).
MAX_BUMPS = 8


def planning_grid(world: RobotWorld, world_model: WorldModelLike | None = None) -> OccupancyGrid:
    """The grid the robot plans on: the team map when ``world_model`` holds one, else the world's obstacles.

    Map mode (a team map in ``world_model``): the cells the team map shows
    occupied are occupied, unknown and free cells are free (see :func:`map_planning`).
    Known-map mode: the world's static obstacles (5 cm cells), built once per world layout.
    """
    nav = map_planning(world, world_model)
    if nav is not None:
        return nav.grid
    return _known_grid(world)


def _known_grid(world: RobotWorld) -> OccupancyGrid:
    from alica.worldsim.grid import OccupancyGrid

    cache = world_cache(world)
    obstacles = tuple(world.ground_truth_obstacles())
    hit = cache.get("grid")
    if hit is None or hit[0] != obstacles:
        hit = cache["grid"] = (obstacles, OccupancyGrid.from_obstacles(list(obstacles), world.bounds, 0.05))
        cache.pop("checkers", None)
        cache.pop("exact", None)
    grid: OccupancyGrid = hit[1]
    return grid


def exact_checker(world: RobotWorld, radius: float, world_model: WorldModelLike | None = None) -> FclChecker | None:
    """FCL against the world's static obstacles (rocks as their convex meshes, tables) for a robot of ``radius``.

    The final exact check of a path in known-map mode; movable objects (blocks,
    samples, held or not) are left to the grid. ``None`` in map mode (a team map
    in ``world_model``): the robot knows the rocks only from its map.
    """
    from alica.skills.motion import FclChecker

    if map_planning(world, world_model) is not None:
        return None
    _known_grid(world)  # drops stale checkers when the layout changed
    checkers = world_cache(world).setdefault("exact", {})
    checker: FclChecker | None = checkers.get(radius)
    if checker is None:
        shapes: list[Any] = []
        for _, obj in sorted(world.objects.items()):
            mesh = obj.world_mesh()
            footprint = obj.footprint() if obj.kind == "table" else None
            if mesh is not None:
                shapes.append(mesh)
            elif footprint is not None:
                shapes.append(footprint)
        checker = checkers[radius] = FclChecker(shapes, radius)
    return checker


def planning_checker(world: RobotWorld, radius: float, world_model: WorldModelLike | None = None) -> GridChecker:
    """:func:`planning_grid` inflated for a robot of ``radius`` (a :class:`alica.skills.motion.GridChecker`).

    Built once per radius and world layout (known-map mode), or kept up to date
    tile by tile as the team map changes (map mode).
    """
    from alica.skills.motion import GridChecker

    nav = map_planning(world, world_model)
    if nav is not None:
        return nav.checker(radius)
    grid = _known_grid(world)
    checkers = world_cache(world).setdefault("checkers", {})
    checker: GridChecker | None = checkers.get(radius)
    if checker is None:
        checker = checkers[radius] = GridChecker(grid, radius)
    return checker


def robot_checker(
    world: RobotWorld,
    robot: MobileRobot,
    world_model: WorldModelLike | None = None,
    team_model: WorldModelLike | None = None,
    belief: BeliefLike | None = None,
) -> GridChecker:
    """:func:`planning_checker` for ``robot``; in map mode without the cells of the robots' bodies.

    A team map made with lidar shows the robots where teammates saw them. The
    cells within :data:`BODY_MARGIN` of a robot's body are cleared around the
    robot's pose estimate and the poses its teammates shared in ``world_model``
    (:func:`alica.skills.team_poses.teammates`, as ``MoveToPosition._others``),
    so that a robot can plan from where it stands; the other robots are checked
    as robots. The teammates' poses come from ``team_model`` when given, else
    from ``world_model``.
    """
    radius = robot.spec.radius
    checker = planning_checker(world, radius, world_model)
    if map_planning(world, world_model) is None:
        return checker
    x, y, _ = robot.estimate
    bodies = [(x, y, radius + BODY_MARGIN)]
    team = team_model if team_model is not None else world_model
    bodies += [(p.x, p.y, p.radius + BODY_MARGIN) for p in teammates(team, world, robot.name, belief=belief)]
    return checker.with_cleared_disks(bodies)


@dataclass
class MapPlanning:
    """The team map of one world-model replica as the driving skills plan on it (map mode).

    Attributes:
        source: the team map (:func:`alica.skills.mapping.team_map`) this was made from.
        revision: the team map's revision it matches (:func:`alica.skills.mapping.team_map_changes`).
        read_at: simulated time of the last read of the team map.
        grid: occupied where the team map's cells are occupied, free elsewhere (unknown counts as free).
        checkers: the grid inflated per robot radius, updated only in the tiles that changed.
    """

    source: LogOddsGrid
    revision: int
    read_at: float
    grid: OccupancyGrid
    checkers: dict[float, GridChecker] = field(default_factory=dict)

    def checker(self, radius: float) -> GridChecker:
        """The grid inflated for a robot of ``radius`` (unknown cells free)."""
        from alica.skills.motion import GridChecker

        checker = self.checkers.get(radius)
        if checker is None:
            checker = self.checkers[radius] = GridChecker(self.grid, radius, unknown_is_free=True)
        return checker


_MAP_PLANNING: weakref.WeakKeyDictionary[Any, MapPlanning] = weakref.WeakKeyDictionary()


def _occupied_cells(source: LogOddsGrid, rows: slice = slice(None), cols: slice = slice(None)) -> np.ndarray:
    from alica.skills.mapping.grid import THRESHOLD
    from alica.worldsim.grid import FREE, OCCUPIED

    return np.where(source.logodds[rows, cols] > THRESHOLD, OCCUPIED, FREE).astype(np.uint8)


def map_planning(world: RobotWorld, world_model: WorldModelLike | None) -> MapPlanning | None:
    """The team map in ``world_model`` as a planning grid, or ``None`` without a team map (known-map mode).

    The team map is read at most every :data:`MAP_PERIOD` simulated seconds per
    replica; only the tiles that changed since (the team map's tile revisions)
    are thresholded and inflated again.
    """
    from alica.skills.mapping import TILE, team_map, team_map_changes, team_resolution
    from alica.worldsim.grid import OccupancyGrid

    if world_model is None or team_resolution(world_model) is None:
        return None
    try:
        nav = _MAP_PLANNING.get(world_model)
    except TypeError:  # not weakly referenceable: no cache
        nav = None
    now = world.now()
    if nav is not None and 0.0 <= now - nav.read_at < MAP_PERIOD:
        return nav
    source = team_map(world_model)
    if source is None:
        return None
    changes = team_map_changes(world_model, nav.revision if nav is not None else 0)
    if nav is None or nav.source is not source or changes is None:
        grid = OccupancyGrid(source.origin, source.resolution, source.nx, source.ny, _occupied_cells(source))
        nav = MapPlanning(source, changes[0] if changes is not None else 0, now, grid)
        try:
            _MAP_PLANNING[world_model] = nav
        except TypeError:
            pass
        return nav
    revision, tiles = changes
    nav.read_at = now
    if revision == nav.revision:
        return nav
    cells = nav.grid.cells.copy()
    windows: list[tuple[int, int, int, int]] = []
    for tj, ti in zip(*np.nonzero(tiles), strict=True):
        j0, i0 = int(tj) * TILE, int(ti) * TILE
        j1, i1 = min(j0 + TILE, source.ny), min(i0 + TILE, source.nx)
        fresh = _occupied_cells(source, slice(j0, j1), slice(i0, i1))
        if not np.array_equal(fresh, cells[j0:j1, i0:i1]):
            cells[j0:j1, i0:i1] = fresh
            windows.append((j0, j1, i0, i1))
    nav.revision = revision
    if windows:
        old = nav.grid
        nav.grid = OccupancyGrid(old.origin, old.resolution, old.width, old.height, cells)
        nav.checkers = {r: c.updated(nav.grid, windows) for r, c in nav.checkers.items()}
    return nav


#: Replans around other robots on the path before MoveToPosition gives up (robots move on; the timeout bounds it too).
MAX_TRAFFIC_REPLANS = 20
#: Seconds a robot waits for another robot to leave its path before it plans around it.
ROBOT_YIELD = 2.0
#: Seconds to wait before planning again when another robot stands on the goal.
GOAL_WAIT = 1.0
#: Radial step in metres of the search for a drivable point near a goal inside an obstacle's clearance.
GOAL_SEARCH_STEP = 0.02


def drivable_goal(checker: GridChecker, goal: tuple[float, float], tolerance: float) -> tuple[float, float] | None:
    """The drivable point nearest to ``goal`` within ``tolerance`` metres, or ``None`` when there is none.

    A goal within an obstacle's clearance (the robot's radius plus margin) cannot
    be reached by the robot's centre; any point within the skill's tolerance
    counts as arrived, as a navigation stack's goal tolerance does. Rings of
    growing radius are searched, 64 directions each, the nearest valid point wins.
    """
    if checker.valid_xy(*goal):
        return goal
    steps = int(tolerance / GOAL_SEARCH_STEP)
    for k in range(1, steps + 1):
        r = k * GOAL_SEARCH_STEP
        for i in range(64):
            a = 2 * math.pi * i / 64
            point = (goal[0] + r * math.cos(a), goal[1] + r * math.sin(a))
            if checker.valid_xy(*point):
                return point
    return None


class MoveToPosition(WorldSkill):
    """Drive to ``goal`` within ``tolerance`` metres, or fail with a reason after ``timeout`` seconds.

    Plans on the team map when the world model holds one (map mode), else on
    the world's known layout (known-map mode); see the module docstring.

    Attributes:
        map_model: a world model whose team map to plan on when the skill's own
            context has none (ExploreFrontier's inner drive, which writes no facts).
    """

    map_model: WorldModelLike | None = None

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name, params, context)
        self.speed = 0.0
        self.bumps: list[tuple[float, float]] = []

    def initialise(self) -> None:
        """Resolve the goal and start planning."""
        self.goal = self.resolve_position(self.param("goal"))
        self.tolerance = float(self.param("tolerance", 0.3))  # type: ignore[arg-type]
        self.timeout = float(self.param("timeout", 60.0))  # type: ignore[arg-type]
        self.started = self.now()
        self.last = self.started
        self.replans = 0
        self.follower: PathFollower | None = None
        self.job: Job | None = None
        self.next_block_check = 0.0
        self.escaping = False
        self.reason = ""
        self.path_length = 0.0
        self.wait_until = 0.0
        self.next_scan = self.started
        self.speed = 0.0
        self.bumps = []
        self.yield_since: float | None = None
        self.robot_replans = 0
        # a goal within an obstacle's clearance: drive to the nearest drivable point within the tolerance
        self.target = drivable_goal(self._checker(), self.goal, self.tolerance)
        self._plan(self.target or self.goal)

    @property
    def map_source(self) -> WorldModelLike | None:
        """The world model whose team map the skill plans on (:attr:`map_model`, else its own), if any."""
        return self.map_model if self.map_model is not None else self.world_model

    def map_mode(self) -> bool:
        """Whether the skill plans on a team map now (else on the world's known layout)."""
        return map_planning(self.world, self.map_source) is not None

    def _checker(self) -> GridChecker:
        """The inflated grid to plan and check paths on.

        In map mode without the robots' bodies' cells, and with what the robot
        bumped into on this drive (:meth:`_remember_bump`).
        """
        checker = robot_checker(self.world, self.robot, self.map_source, self.team_model, self.team_belief)
        if self.bumps:
            reach = checker.robot_radius + checker.margin + BUMP_RADIUS
            checker = checker.with_blocked_disks(np.array(self.bumps), reach)
        return checker

    def _remember_bump(self) -> None:
        """Remember an obstacle just ahead of where the robot drove when it bumped.

        What the grid does not show stops the robot: in map mode a sample
        lying on the ground or a rock below the lidar, in known-map mode a
        sample (the known layout leaves samples out: they are work sites the
        manipulation skills drive up to). A robot's bumper tells it, and the
        robot plans around the spot and escapes away from it for the rest of
        this drive. Bumps into another robot are not remembered (robots move).
        """
        if abs(self.speed) < 1e-3:
            return
        x, y, yaw = self.robot.estimate
        heading = yaw if self.speed > 0 else yaw + math.pi
        reach = self.robot.spec.radius + BUMP_RADIUS
        spot = (x + reach * math.cos(heading), y + reach * math.sin(heading))
        if any(math.hypot(spot[0] - ox, spot[1] - oy) < r + BUMP_RADIUS for ox, oy, r in self._others()):
            return
        self.bumps = [*self.bumps[-(MAX_BUMPS - 1) :], spot]

    def _grid(self) -> OccupancyGrid:
        """The raw grid of :meth:`_checker` (for the search of free space)."""
        return self._checker().grid

    def _map_as_driving(self, now: float) -> None:
        """Map mode: every :data:`DRIVE_SCAN_PERIOD` s a scan into the robot's layer of the team map."""
        from alica.skills.mapping import map_scan, robot_mapper, team_resolution

        wm = self.world_model
        if wm is None or now < self.next_scan:
            return
        self.next_scan = now + DRIVE_SCAN_PERIOD
        resolution = team_resolution(wm)
        if resolution is None:
            return
        mapper = robot_mapper(self.context, self.robot.name, self.world.bounds, resolution)
        map_scan(self.robot, mapper, max_range=min(DRIVE_SCAN_RANGE, self.robot.spec.lidar_range), now=now)

    def _others(self) -> list[tuple[float, float, float]]:
        """The teammates' bodies as ``(x, y, radius)``, from the poses they shared (:mod:`alica.skills.team_poses`)."""
        return [p.disc for p in self.teammates()]

    def _replan(self) -> None:
        """Plan again to the target; in map mode the drivable point near the goal is sought again (the map changed)."""
        if self.map_mode():
            self.target = drivable_goal(self._checker(), self.goal, self.tolerance)
        self._plan(self.target or self.goal)

    def _plan(self, goal: tuple[float, float]) -> None:
        from alica.skills.motion import plan_path

        checker = self._checker()
        exact = exact_checker(self.world, self.robot.spec.radius, self.map_source)
        # An optimizing planner after the first path, when the run allows the time (real robots): anytime
        # planning by wall time is not repeatable, so simulated runs keep RRTConnect plus simplification.
        extra = self.context.extra if self.context is not None else {}
        optimize = float(extra.get("optimize_time", 0.0))  # type: ignore[arg-type]
        self.job = self.jobs.submit(
            plan_path,
            self.robot.estimate,
            goal,
            checker,
            self.robot.spec.radius,
            obstacles_exact=exact,
            other_robots=self._others(),
            time_limit=1.0,
            optimize_time=optimize,
        )
        self.follower = None

    def update(self) -> Status:
        """Poll the planner, follow the path, replan or escape when needed."""
        robot = self.robot
        now = self.now()
        dt, self.last = now - self.last, now
        self._map_as_driving(now)
        here = (robot.estimate[0], robot.estimate[1])
        if not self.escaping and distance(here, self.goal) <= self.tolerance:
            robot.stop()
            self._arrived(here)
            return self.succeed(f"reached {self.goal} after {now - self.started:.1f} s")
        if now - self.started > self.timeout:
            robot.stop()
            return self.fail(f"did not reach {self.goal} within {self.timeout:.0f} s ({self.reason or 'no progress'})")
        if self.follower is None:
            return self._poll_plan(now)
        v, w, done = self.follower.command(robot.estimate, dt)
        if robot.bumped or self.follower.stuck(robot.estimate, now):
            if robot.bumped:
                self._remember_bump()
            return self._stuck(now)
        blocked = self._blocked()
        since = now if self.yield_since is None else self.yield_since
        if blocked == "robot" and now - since < ROBOT_YIELD:
            # another robot crosses the path: wait for it to pass (a replan would route around a moving robot)
            self.yield_since = since
            robot.stop()
            self.speed = 0.0
            self.follower.reset_stuck()  # an intended pause, not a lack of progress
            return self.running("another robot is on the path: letting it pass")
        self.yield_since = None
        if blocked:
            # robots move on: traffic costs time (the timeout bounds it), only obstacles count toward giving up
            if blocked == "robot":
                self.robot_replans += 1
            else:
                self.replans += 1
            if self.replans > MAX_REPLANS or self.robot_replans > MAX_TRAFFIC_REPLANS:
                robot.stop()
                return self.fail(
                    f"the path to {self.goal} stays blocked after {self.replans + self.robot_replans} replans"
                )
            robot.stop()
            self._replan()
            return self.running(
                f"path blocked by {'another robot' if blocked == 'robot' else 'an obstacle'}: replanning"
            )
        if done:
            robot.stop()
            if self.escaping:
                self.escaping = False
                self._replan()
                return self.running("out of the tight spot: replanning")
            self._replan()  # the follower ended short of the goal: plan the rest
            return self.running("close to the goal: planning the last part")
        robot.drive(v, w)
        self.speed = v
        return self.running(f"driving to {self.goal}")

    def _poll_plan(self, now: float) -> Status:
        from alica.skills.motion import PathFollower

        if self.job is None:
            if now < self.wait_until:
                return self.running(f"waiting for another robot to clear the goal ({self.reason})")
            self._replan()
        job = self.job
        assert job is not None  # _plan submitted one
        if not job.done():
            return self.running("planning")
        result = job.result()
        target = self.goal
        if result.status != "exact":
            self.reason = result.reason or result.status
            if result.status == "invalid_goal" and "another robot" in self.reason:
                # robots move: wait for this one to go, until the skill's timeout
                self.robot.stop()
                self.job = None
                self.wait_until = now + GOAL_WAIT
                return self.running(f"waiting for another robot to clear the goal ({self.reason})")
            if result.status == "invalid_start" or self.reason.startswith("start "):
                return self._stuck(now)  # too close to something (a block put down next to it): back off first
            if result.status in ("invalid_goal", "unreachable") and not self.escaping:
                self.robot.stop()
                return self.fail(f"cannot reach {self.goal}: {self.reason}")
            self.replans += 1
            if self.replans > MAX_REPLANS:
                self.robot.stop()
                return self.fail(f"no path to {self.goal} after {MAX_REPLANS} attempts: {self.reason}")
            self._plan(target)
            return self.running(f"planning again ({self.reason})")
        spec = self.robot.spec
        self.path_length += float(result.length)
        self.follower = PathFollower(
            result.path,
            lookahead=max(0.3, 2 * spec.radius),
            max_speed=spec.max_speed,
            max_yaw_rate=spec.max_yaw_rate,
            tolerance=min(self.tolerance, 0.2),
        )
        return self.running("path found")

    def _stuck(self, now: float) -> Status:
        from alica.skills.motion import PathFollower, escape_goal

        robot = self.robot
        robot.stop()
        self.replans += 1
        if self.replans > MAX_REPLANS:
            return self.fail(f"stuck on the way to {self.goal} after {MAX_REPLANS} escapes")
        # free space away from the other robots too: the robot it bumped into is often one of them
        spot = escape_goal(
            self._grid(),
            robot.estimate,
            clearance=robot.spec.radius + 0.3,
            max_distance=3.0,
            other_robots=self._others() + [(bx, by, BUMP_RADIUS) for bx, by in self.bumps],
            body_radius=robot.spec.radius,
        )
        if spot is None:
            return self.fail(f"stuck at {robot.estimate[:2]} and no free space within 3 m to drive to")
        x, y, yaw = robot.estimate
        heading = math.atan2(spot[1] - y, spot[0] - x)
        path = np.array([[x, y, yaw], [spot[0], spot[1], heading]])
        spec = robot.spec
        # turn on the spot first: driving an arc while touching something pushes into it, and the base refuses
        self.follower = PathFollower(
            path,
            lookahead=0.3,
            max_speed=spec.max_speed * 0.5,
            max_yaw_rate=spec.max_yaw_rate,
            tolerance=0.1,
            turn_in_place=math.radians(15.0),
        )
        self.escaping = True
        robot.bumped = False
        return self.running(f"stuck: driving into free space at ({spot[0]:.2f}, {spot[1]:.2f})")

    def _blocked(self) -> str:
        """What stands on the next metres of the path: ``"robot"`` (only other robots), ``"obstacle"``, or ``""``.

        Checked every 0.3 s; in between the last answer holds while the robot
        waits for another to pass. In map mode a new obstacle is one the team
        map shows now (read at most every :data:`MAP_PERIOD` s).
        """
        follower = self.follower
        now = self.now()
        if follower is None or self.escaping:
            return ""
        if now < self.next_block_check:
            return "robot" if self.yield_since is not None else ""
        self.next_block_check = now + 0.3
        checker = self._checker()  # rebuilt when the layout or the team map changed
        pose = self.robot.estimate
        if not follower.blocked(checker, pose, other_robots=self._others(), horizon=4.0):
            return ""
        return "obstacle" if follower.blocked(checker, pose, horizon=4.0) else "robot"

    def _arrived(self, here: tuple[float, float]) -> None:
        wm = self.world_model
        if wm is not None:
            wm.set("pos", self.robot.name, value=(round(here[0], 3), round(here[1], 3)))
        goal = self.param("goal")
        there = self.param("at")
        if isinstance(there, str) and there.strip():
            self.write(True, "at", self.robot.name, there.strip())
        elif isinstance(goal, str):
            self.write(True, "at", self.robot.name, goal.strip().removeprefix("pos(").removesuffix(")").strip())

    def terminate(self, new_status: Status) -> None:
        """Stop the base whenever the skill ends or is stopped."""
        if self.has_robot:
            self.robot.stop()


def lying_sites(world: RobotWorld) -> list[tuple[float, float]]:
    """Where the movable objects lying in the world (blocks, samples; held ones are left out) are: the work sites.

    They come from the world's known layout (the blocks world, where the waiting skills use them).
    """
    return [
        (fp.x, fp.y)
        for fp in world.ground_truth_obstacles(include_samples=True)
        if world.objects[fp.name].kind in ("block", "sample")
    ]


class DriveToFreeSpace(MoveToPosition):
    """Drive to the nearest place with ``clearance`` metres of free space within ``max_distance``.

    With ``keep_away`` > 0 the place is also at least that far (centre to
    centre) from every movable object lying in the world (blocks, samples):
    a robot waiting there does not crowd the stacks others work on.

    Any free place serves, so when another robot stands on the chosen one
    (it got there first, or it is crashed there) the skill drives to the next
    free place instead of waiting for it to leave (up to ``MAX_REPLANS``
    times; then it waits as MoveToPosition does, until the timeout).

    The free space is that of the grid MoveToPosition plans on (the team map
    in map mode); the movable objects of ``keep_away`` are the world's (the
    blocks world's known layout, where the skill is used).
    """

    def initialise(self) -> None:
        """Find the free place, then drive there like MoveToPosition."""
        self.spot = self._free_place()
        self.params["goal"] = self.spot if self.spot is not None else self.robot.estimate[:2]
        self.params.setdefault("tolerance", 0.2)
        self.moved_goal = 0
        super().initialise()

    def _free_place(self) -> tuple[float, float] | None:
        from alica.skills.motion import escape_goal

        clearance = float(self.param("clearance", 1.0))  # type: ignore[arg-type]
        reach = float(self.param("max_distance", 3.0))  # type: ignore[arg-type]
        return escape_goal(
            self._grid(),
            self.robot.estimate,
            clearance=self.robot.spec.radius + clearance,
            max_distance=reach,
            other_robots=self._others(),
            keep_away=self._keep_away_sites(),
        )

    def _keep_away_sites(self) -> list[tuple[float, float, float]]:
        """Points ``(x, y, distance)`` the free place keeps away from: the work sites, ``keep_away`` each."""
        away = float(self.param("keep_away", 0.0))  # type: ignore[arg-type]
        return [(x, y, away) for x, y in lying_sites(self.world)] if away > 0 else []

    def _drive_to(self, spot: tuple[float, float]) -> None:
        """Make ``spot`` the place to drive to, and plan the way there."""
        self.spot = spot
        self.params["goal"] = spot
        self.goal = spot
        self.target = drivable_goal(self._checker(), spot, self.tolerance)
        self.wait_until = 0.0
        self._plan(self.target or spot)

    def update(self) -> Status:
        """Fail when there is no free place, else drive there; a place another robot took is given up for another."""
        if self.spot is None:
            return self.fail(f"no free place with the clearance within {self.param('max_distance', 3.0)} m")
        status = super().update()
        if status == Status.RUNNING and self.job is None and self.now() < self.wait_until:
            # any free place serves: waiting for the robot on this one could wait for good (it may be
            # waiting itself, for what this robot does next, or be crashed)
            spot = self._free_place()
            if spot is not None and spot != self.spot and self.moved_goal < MAX_REPLANS:
                self.moved_goal += 1
                self._drive_to(spot)
                return self.running(f"another robot took the free place: driving to ({spot[0]:.2f}, {spot[1]:.2f})")
        return status


class Idle(WorldSkill):
    """Stand still; succeed after ``duration`` seconds, or run until the state is left when it is 0."""

    def setup(self, **kwargs: Any) -> None:
        """Idle needs no world."""
        self.context = kwargs.get("context", self.context)
        world = self.context.world if self.context is not None else None
        if isinstance(world, RobotWorld) and self.context is not None and self.context.agent in world.robots:
            super().setup(**kwargs)

    def initialise(self) -> None:
        """Stop the robot, remember when."""
        self.started = self.now() if self.context is not None else 0.0
        if self.has_robot:
            self.robot.stop()

    def update(self) -> Status:
        """Running until the duration passed."""
        duration = float(self.param("duration", 0.0))  # type: ignore[arg-type]
        if duration > 0 and self.now() - self.started >= duration:
            return self.succeed()
        return self.running("standing still")
