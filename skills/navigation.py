"""Driving skills: MoveToPosition (and its primitive DriveTo), DriveToFreeSpace, Idle.

MoveToPosition plans in SE2 with OMPL on the world's occupancy grid, inflated
by the robot's radius (:func:`alica.skills.motion.plan_path`), checks the path
exactly with FCL against the rocks' meshes and the other robots, follows it,
replans when another robot or a new obstacle blocks it, and when the robot is
stuck (bumped, or no progress) drives into free space first. Planning runs as
a job; ``update`` only polls. The robot drives by its pose *estimate*
(``robot.estimate``: odometry, corrected by Localize), which is its true pose
while the world's odometry drift is 0.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from py_trees.common import Status

from alica.skills.jobs import Job
from alica.skills.world_skill import WorldSkill, distance, world_cache
from alica.worldsim.interface import RobotWorld

if TYPE_CHECKING:
    from alica.skills.motion import FclChecker, GridChecker, PathFollower
    from alica.worldsim.grid import OccupancyGrid

#: Replans (after being stuck or blocked) before MoveToPosition gives up.
MAX_REPLANS = 5


def planning_grid(world: RobotWorld) -> OccupancyGrid:
    """The world's static obstacles as an occupancy grid (5 cm cells), built once per world layout."""
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


def exact_checker(world: RobotWorld, radius: float) -> FclChecker:
    """FCL against the world's static obstacles (rocks as their convex meshes, tables) for a robot of ``radius``.

    The final exact check of a path; movable objects (blocks, samples, held or not) are left to the grid.
    """
    from alica.skills.motion import FclChecker

    planning_grid(world)  # drops stale checkers when the layout changed
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


def planning_checker(world: RobotWorld, radius: float) -> GridChecker:
    """The grid inflated for a robot of ``radius`` (a :class:`alica.skills.motion.GridChecker`), built once per radius."""
    from alica.skills.motion import GridChecker

    grid = planning_grid(world)
    checkers = world_cache(world).setdefault("checkers", {})
    checker: GridChecker | None = checkers.get(radius)
    if checker is None:
        checker = checkers[radius] = GridChecker(grid, radius)
    return checker


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
    """Drive to ``goal`` within ``tolerance`` metres, or fail with a reason after ``timeout`` seconds."""

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
        # a goal within an obstacle's clearance: drive to the nearest drivable point within the tolerance
        self.target = drivable_goal(planning_checker(self.world, self.robot.spec.radius), self.goal, self.tolerance)
        self._plan(self.target or self.goal)

    def _others(self) -> list[tuple[float, float, float]]:
        return [
            (r.pose[0], r.pose[1], r.spec.radius)
            for name, r in sorted(self.world.robots.items())
            if r is not self.robot
        ]

    def _plan(self, goal: tuple[float, float]) -> None:
        from alica.skills.motion import plan_path

        checker = planning_checker(self.world, self.robot.spec.radius)
        exact = exact_checker(self.world, self.robot.spec.radius)
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
            return self._stuck(now)
        if self._blocked():
            self.replans += 1
            if self.replans > MAX_REPLANS:
                robot.stop()
                return self.fail(f"the path to {self.goal} stays blocked after {MAX_REPLANS} replans")
            robot.stop()
            self._plan(self.target or self.goal)
            return self.running("path blocked by another robot or a new obstacle: replanning")
        if done:
            robot.stop()
            if self.escaping:
                self.escaping = False
                self._plan(self.target or self.goal)
                return self.running("out of the tight spot: replanning")
            self._plan(self.target or self.goal)  # the follower ended short of the goal: plan the rest
            return self.running("close to the goal: planning the last part")
        robot.drive(v, w)
        return self.running(f"driving to {self.goal}")

    def _poll_plan(self, now: float) -> Status:
        from alica.skills.motion import PathFollower

        if self.job is None:
            if now < self.wait_until:
                return self.running(f"waiting for another robot to clear the goal ({self.reason})")
            self._plan(self.target or self.goal)
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
            planning_grid(self.world),
            robot.estimate,
            clearance=robot.spec.radius + 0.3,
            max_distance=3.0,
            other_robots=self._others(),
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

    def _blocked(self) -> bool:
        """Whether another robot or a new obstacle stands on the next metres of the path (checked every 0.3 s)."""
        follower = self.follower
        now = self.now()
        if follower is None or self.escaping or now < self.next_block_check:
            return False
        self.next_block_check = now + 0.3
        checker = planning_checker(self.world, self.robot.spec.radius)  # rebuilt when the layout changed
        return bool(follower.blocked(checker, self.robot.estimate, other_robots=self._others(), horizon=4.0))

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


class DriveToFreeSpace(MoveToPosition):
    """Drive to the nearest place with ``clearance`` metres of free space within ``max_distance``.

    With ``keep_away`` > 0 the place is also at least that far (centre to
    centre) from every movable object lying in the world (blocks, samples):
    a robot waiting there does not crowd the stacks others work on.

    Any free place serves, so when another robot stands on the chosen one
    (it got there first, or it is crashed there) the skill drives to the next
    free place instead of waiting for it to leave (up to ``MAX_REPLANS``
    times; then it waits as MoveToPosition does, until the timeout).
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
        away = float(self.param("keep_away", 0.0))  # type: ignore[arg-type]
        grid = planning_grid(self.world)
        lying = self.world.ground_truth_obstacles(include_samples=True) if away > 0 else []  # held objects are left out
        sites = [(fp.x, fp.y, away) for fp in lying if self.world.objects[fp.name].kind in ("block", "sample")]
        return escape_goal(
            grid,
            self.robot.estimate,
            clearance=self.robot.spec.radius + clearance,
            max_distance=reach,
            other_robots=self._others(),
            keep_away=sites,
        )

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
                self.spot = spot
                self.params["goal"] = spot
                self.goal = spot
                self.target = drivable_goal(planning_checker(self.world, self.robot.spec.radius), spot, self.tolerance)
                self.wait_until = 0.0
                self._plan(self.target or spot)
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
