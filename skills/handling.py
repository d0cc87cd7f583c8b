"""Manipulation skills: Pickup, Putdown, Stack and Unstack, with the IPC blocks-world semantics.

Each skill runs the same phases, polled tick by tick:

1. **approach**: if the work site is out of the arm's reach, drive to a
   stand-off point facing it (an inner :class:`MoveToPosition`), then turn to it;
2. **plan**: a job plans the arm motion on the robot's own planning scene
   (:mod:`alica.skills.manipulation`: IK with joint-limit checks and random
   restarts, OMPL joint-space paths with collision checks, the held object
   included);
3. **execute**: the arm follows the paths in simulated time; the gripper
   closes and the object becomes an attachment (Pickup, Unstack) or is
   released (Putdown, Stack);
4. **verify**: the grip (finger force, the object still held) or the
   placement (the object rests where it should) is checked against the
   simulated state; a failed grasp opens the hand and retries, up to
   ``retries`` times, then the skill fails and says why.

For blocks, preconditions and effects are those of the IPC blocks domain
(``clear``, ``on``, ``ontable``, ``holding``, ``handempty``), checked on the
simulated state before and after; the effects are written to the world model.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills import reservations
from alica.skills.arm_world import area_spots, find_object, place_area, write_held, write_placed, write_released
from alica.skills.context import SkillContextLike
from alica.skills.jobs import Job
from alica.skills.navigation import MoveToPosition
from alica.skills.world_skill import WorldSkill, distance, world_cache
from alica.worldsim.geometry import wrap_angle
from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing

if TYPE_CHECKING:
    from alica.skills.manipulation import ArmScene, Box
    from alica.worldsim.arm import Arm

#: Horizontal distance from the arm's base at which the arm works best.
REACH = 0.55
#: Joint speed used to time arm paths, rad/s.
JOINT_SPEED = 1.5
#: Seconds a released object gets to settle before the placement is checked.
SETTLE = 0.5
#: Turns (rad) from straight ahead tried for a free spot to put a block down.
PUTDOWN_TURNS = (0.0, 0.6, -0.6, 1.2, -1.2, 1.8, -1.8, 3.14)
#: Free room (m) a put-down spot needs around it.
PUTDOWN_ROOM = 0.15
#: Room (m) between a put-down spot and the field's edge: robots must find sides of the block to stand on.
EDGE_ROOM = 0.8
#: Free room (m) a spot in an area (the collection point) needs: the hand descends beside what stands there.
AREA_ROOM = 0.25
#: Sides of a work site tried for the stand-off point (the nearest first).
STANDOFF_TRIES = 12
#: Room kept around the robot at its stand-off point, metres.
STANDOFF_MARGIN = 0.1
#: Simulated seconds a skill waits for a free side of its work site before it fails (the team then replans).
STANDOFF_WAIT = 30.0
#: A stand-off point this close (m) to one from which the arm found no plan counts as tried.
SIDE_TRIED = 0.2
#: How far (m) a placed object may lie from its place and count as placed there.
PLACE_TOLERANCE = 0.08


def _box(obj: WorldThing) -> Box:
    """An object as a box for arm planning: its own extents and yaw for boxes, else its bounding box."""
    from alica.skills.manipulation import Box
    from alica.skills.manipulation.geometry import upright_box

    low, high = (np.asarray(v, dtype=float) for v in obj.aabb())
    half = tuple(obj.half_extents)
    if obj.kind == "sample" and obj.radius:
        # a cylinder: its true size, not a bounding box that grows as it turns in the hand
        r = float(obj.radius)
        half = (r, r, 0.5 * float(obj.size))
    if half and half[0] > 0.0:
        center, quat = obj.pose()
        yaw, upright = upright_box(quat, half)  # a block that fell onto a side has its faces turned another way
        return Box(obj.name, (float(center[0]), float(center[1]), float(center[2])), upright, yaw)
    return Box(obj.name, tuple((low + high) / 2.0), tuple((high - low) / 2.0))


def grasp_shape(obj: WorldThing) -> str:
    """How to grasp ``obj`` from the top: ``"cylinder"`` for a sample standing upright, else ``"box"``.

    A sample container that fell over lies as a box (its length along the
    ground, its diameter across and up: :func:`_box`), grasped across.
    """
    if obj.kind != "sample" or not obj.radius:
        return "box"
    from alica.skills.manipulation.geometry import quat_rotate

    axis = quat_rotate(tuple(obj.pose()[1]), (0.0, 0.0, 1.0))
    return "cylinder" if abs(axis[2]) > 0.9 else "box"


def _crowds(box: Box, target: Box) -> bool:
    """Whether ``box`` stands beside ``target`` closer than the fingers need to close around it.

    Beside: its top is above the target's bottom (not the block the target stands on), and its centre
    is within 1.6 times the sum of the two boxes' largest horizontal half extents.
    """
    if box.center[2] + box.half_extents[2] <= target.center[2] - target.half_extents[2] + 0.01:
        return False
    reach = 1.6 * (max(box.half_extents[:2]) + max(target.half_extents[:2]))
    return math.dist(box.center[:2], target.center[:2]) < reach


def _duration(path: np.ndarray) -> float:
    steps = np.abs(np.diff(np.asarray(path), axis=0)).max(axis=1) if len(path) > 1 else np.zeros(1)
    return max(0.2, float(steps.sum()) / JOINT_SPEED)


def blocks_state(world: RobotWorld) -> set[tuple[str, ...]]:
    """The IPC blocks facts of the simulated state."""
    from alica.worldsim.scenarios import blocks_facts

    return set(blocks_facts(world))


class ArmSkill(WorldSkill):
    """The phases shared by the manipulation skills; subclasses say what to plan and check.

    The step skills of the Pickup and Putdown plans (:mod:`alica.skills.arm_steps`)
    run some of these phases: AlignWithObject only the approach, Grasp the plan
    and its execution up to the grip, and so on (see the class attributes).
    """

    #: Whether the skill grasps (else it releases what it holds).
    grasps = True
    #: Whether the robot needs an arm (AlignWithObject only drives).
    needs_arm = True
    #: Whether the skill first drives to a stand-off point facing the work site.
    approaches = True
    #: Whether failed attempts are written to the world model as ``attempts(self)``.
    counts_attempts = True

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm (when :attr:`needs_arm`)."""
        super().setup(**kwargs)
        if self.needs_arm and self.robot.arm is None:
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' has no arm")

    @property
    def arm(self) -> Arm:
        """The robot's arm (:meth:`setup` checked that it has one).

        Raises:
            SkillError: the robot has no arm.
        """
        arm = self.robot.arm
        if arm is None:
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' has no arm")
        return arm

    # -- what subclasses define -----------------------------------------------

    def target_object(self) -> WorldThing:
        """The object grasped (or held, for placing): ``object`` (see :func:`find_object`)."""
        return find_object(self, self.param("object"))

    def object_label(self) -> str:
        """The object's name in the outcome facts: the ``object`` parameter as given (the plan's name for it)."""
        return str(self.param("object"))

    def site(self) -> tuple[float, float]:
        """Where the work happens, for the approach."""
        position = self.target_object().position()
        return float(position[0]), float(position[1])

    def check_before(self) -> str | None:
        """Why the skill cannot start now, or None."""
        return None

    def plan(self, scene: ArmScene, q: np.ndarray, rng: np.random.Generator) -> Any:
        """The arm plan, run as a job: grasp and lift, or place at :meth:`place_top` and retreat."""
        from alica.skills.manipulation import plan_pickup, plan_place

        if self.grasps:
            obj = self.target_object()
            return plan_pickup(scene, _box(obj), q, rng=rng, kind=grasp_shape(obj))
        held = self._held_box(scene, q)  # the object in the tool's frame
        if held is None:
            from alica.skills.manipulation import PlacePlan

            return PlacePlan(False, None, None, None, None, [], "the object is tilted in the hand")
        return plan_place(scene, held, self.place_top(), q, rng=rng)

    def arm_steps(self, paths: list[np.ndarray]) -> list[Any]:
        """What the arm does with a plan's paths, in order: a path to follow, or ``"grip"`` / ``"release"``.

        Pick: to the pre-grasp, down, grip, up to the transport pose; place:
        above the place, down, release, up to the transport pose.
        """
        return [*paths[:2], "grip" if self.grasps else "release", *paths[2:]]

    def finger_force(self) -> float | None:
        """The finger force (N) to close with; None: the gripper's default."""
        return None

    def finished(self) -> Status:
        """The end of a successful run (after :meth:`check_after`)."""
        return self.succeed(f"done after {self.attempts + 1} attempt(s)")

    def place_top(self) -> tuple[float, float, float]:
        """Where the bottom of a placed object goes: on the ground at the site, or on top of a target block."""
        target = self.param("target")
        if isinstance(target, str) and target in self.world.objects and self.world.objects[target].kind == "block":
            _, high = self.world.objects[target].aabb()
            x, y = self.site()
            return x, y, float(high[2])
        x, y = self.site()
        return x, y, 0.0

    def check_after(self) -> str | None:
        """Why the outcome is wrong, or None; writes the outcome facts when right."""
        return None

    # -- the phases --------------------------------------------------------------

    def initialise(self) -> None:
        """Start with the approach."""
        self.retries = int(self.param("retries", 3))  # type: ignore[call-overload]
        self.attempts = 0
        self.phase = "check"
        self.mover: MoveToPosition | None = None
        self.steps: list[Any] = []
        self.step_index = 0
        self.job: Job | None = None
        self.settle_until = 0.0
        self.blocked_since: float | None = None
        self.tried_sides: list[tuple[float, float]] = []
        self.goal_moves = 0
        self.reserved_xy: tuple[float, float] | None = None
        self.reserved_at = 0.0
        self.followed: list[np.ndarray] = []
        self.released = False
        self.np_rng = np.random.default_rng(self.context.rng.randrange(2**31) if self.context is not None else 0)

    def update(self) -> Status:
        """One step of the current phase (a held stand-off reservation is refreshed now and then)."""
        if self.reserved_xy is not None and self.now() - self.reserved_at >= reservations.REFRESH_PERIOD:
            self._reserve(self.reserved_xy)
        handler = getattr(self, f"_phase_{self.phase}")
        return handler()

    def _phase_check(self) -> Status:
        reason = self.check_before()
        if reason is not None:
            return self.fail(reason)
        if not self.approaches:
            self.phase = "plan"
            return self._phase_plan()
        self.phase = "approach"
        return self._phase_approach()

    def _arm_xy(self) -> tuple[float, float]:
        position = self.arm.base_pose()[0]
        return float(position[0]), float(position[1])

    # -- the approach (AlignWithObject runs it alone) -------------------------------

    def standoff(self) -> float:
        """Distance (m) from the work site to the robot's centre after the approach: the arm's reach ahead of its mount."""
        return REACH + _mount_ahead(self.robot)

    def approach_slack(self) -> float:
        """How far (m) from :meth:`standoff` the robot may stand and still work without driving."""
        return 0.12

    def approach_tolerance(self) -> float:
        """The goal tolerance (m) of the drive to the stand-off point."""
        return 0.05

    def approached(self) -> Status:
        """The robot stands at the work site, facing it: go on with planning the arm motion."""
        self.phase = "plan"
        return self._phase_plan()

    def _phase_approach(self) -> Status:
        robot = self.robot
        site = self.site()
        x, y, yaw = robot.estimate  # the robot drives by its estimate (as MoveToPosition does)
        if self.mover is None:
            gap = distance((x, y), site)
            facing = abs(wrap_angle(math.atan2(site[1] - y, site[0] - x) - yaw))
            if abs(gap - self.standoff()) <= self.approach_slack() and facing < 0.15 and not self._side_tried((x, y)):
                self._reserve((float(x), float(y)))
                return self.approached()
            goal = self._standoff(site)
            self.goal_moves = 0
            if goal is None:
                if self.blocked_since is None:
                    self.blocked_since = self.now()
                elif self.now() - self.blocked_since >= STANDOFF_WAIT:
                    return self.fail(
                        f"every side of the work site {_xy_text(site)} was taken by other robots for {STANDOFF_WAIT:g} s"
                    )
                return self.running("waiting: every side of the work site is taken by other robots")
            self.blocked_since = None
            self.mover = self._approach_to(goal)
        if self.mover.status != Status.SUCCESS:
            self.mover.tick_once()
            if self.mover.status == Status.FAILURE:
                return self.fail(f"cannot get to {site}: {self.mover.feedback_message}")
            if self.mover.status == Status.RUNNING:
                if self._goal_taken() and self._switch_side(site):
                    return self.running("approaching: another robot stands on the stand-off point, taking another side")
                return self.running(f"approaching: {self.mover.feedback_message}")
        error = wrap_angle(math.atan2(site[1] - y, site[0] - x) - yaw)
        if abs(error) > 0.03:
            robot.drive(0.0, max(-robot.spec.max_yaw_rate, min(robot.spec.max_yaw_rate, 2.0 * error)))
            return self.running("turning to the work site")
        robot.stop()
        return self.approached()

    def _standoff(
        self, site: tuple[float, float], skip: tuple[float, float] | None = None
    ) -> tuple[float, float] | None:
        """A free point facing ``site`` at the arm's reach: the nearest side first, then around it.

        Points overlapping another robot, a point a teammate reserved
        (:mod:`alica.skills.reservations`) or an object (with a margin) are
        skipped, and so is ``skip`` (a side found taken); ``None`` when every
        side is taken (the skill waits and looks again).
        """
        from alica.skills.navigation import robot_checker

        robot = self.robot
        x, y, _ = robot.estimate
        standoff = self.standoff()
        heading = math.atan2(site[1] - y, site[0] - x)
        others = [
            (r.pose[0], r.pose[1], r.spec.radius + STANDOFF_MARGIN)
            for r in self.world.robots.values()
            if r is not robot
        ]
        others += [(rx, ry, rr + STANDOFF_MARGIN) for rx, ry, rr in reservations.reserved(self)]
        # the motion planner's own check of a goal (static obstacles, blocks, other robots)
        checker = robot_checker(self.world, robot, self.world_model).with_robots(others)
        for k in range(STANDOFF_TRIES):
            turn = ((k + 1) // 2) * (1 if k % 2 else -1) * (2.0 * math.pi / STANDOFF_TRIES)
            angle = heading + turn
            goal = (site[0] - standoff * math.cos(angle), site[1] - standoff * math.sin(angle))
            if self._side_tried(goal) or (skip is not None and distance(goal, skip) < SIDE_TRIED):
                continue
            if not inside_field(self.world, goal, robot.spec.radius + STANDOFF_MARGIN):
                continue  # the robot's body would leave the field: it cannot stand there
            if distance(goal, (x, y)) < 0.05 or checker.valid_xy(goal[0], goal[1]):
                return goal
        return None

    def _reserve(self, xy: tuple[float, float]) -> None:
        """Tell the teammates where this robot will stand to work (refreshed by :meth:`update`)."""
        reservations.reserve(self, xy)
        self.reserved_xy = xy
        self.reserved_at = self.now()

    def _goal_taken(self) -> bool:
        """Whether the approach waits for another robot to leave its stand-off point."""
        mover = self.mover
        return mover is not None and mover.job is None and mover.follower is None and self.now() < mover.wait_until

    def _switch_side(self, site: tuple[float, float]) -> bool:
        """Drive to another free side of ``site`` instead of waiting for the robot on this one.

        The robot on the stand-off point may wait itself (for what this robot
        does next), or be crashed there. Up to :data:`STANDOFF_TRIES` switches.
        """
        mover = self.mover
        if mover is None or self.goal_moves >= STANDOFF_TRIES:
            return False
        current = (float(mover.goal[0]), float(mover.goal[1]))
        goal = self._standoff(site, skip=current)
        if goal is None:
            return False
        self.goal_moves += 1
        mover.stop(Status.INVALID)
        self.mover = self._approach_to(goal)
        self.mover.tick_once()
        return True

    def _approach_to(self, goal: tuple[float, float]) -> MoveToPosition:
        """The drive to the stand-off point ``goal``, which is reserved for this robot from now on."""
        mover = MoveToPosition(
            f"{self.name}/approach",
            {"goal": goal, "tolerance": self.approach_tolerance(), "timeout": 60.0},
            self.context,
        )
        mover.setup(context=self.context)
        self._reserve(goal)
        return mover

    def _side_tried(self, xy: tuple[float, float]) -> bool:
        """Whether the arm found no plan from a stand-off point this close to ``xy`` already."""
        return any(distance(xy, side) < SIDE_TRIED for side in self.tried_sides)

    def _scene(self) -> ArmScene:
        from alica.skills.manipulation import ArmPlanningModel, ArmScene

        cache = world_cache(self.world)
        key = f"arm-scene:{self.robot.name}"
        scene = cache.get(key)
        if scene is None:
            # one planning model (pybullet client, arm, collision bodies) per kind of arm, shared by
            # the robots' scenes: a model costs about 40 MB, a scene of its own only its state
            models = cache.setdefault("arm-planning-models", {})
            model = models.get(self.arm.urdf_path)
            if model is None:
                model = models[self.arm.urdf_path] = ArmPlanningModel(self.arm.urdf_path)
            scene = cache[key] = ArmScene(self.arm.urdf_path, self.arm.base_pose(), seed=self.world.seed, model=model)
        scene.set_base_pose(self.arm.base_pose())
        left_out = self.scene_exclusions()
        boxes = [
            _box(o)
            for name, o in sorted(self.world.objects.items())
            if name not in left_out and _near(o, self._arm_xy()) and o.kind not in ("terrain", "collection_point")
        ]
        scene.set_obstacles(boxes)
        q = np.asarray(self.arm.q(), dtype=float)
        held = self._held_box(scene, q)
        if boxes and scene.collides(q, held):
            # the arm, or what it holds, touches an object already (pushed against it): no plan could
            # leave a start in collision, so the objects it touches are left out of the scene
            touching = []
            for box in boxes:
                scene.set_obstacles([box])
                if scene.collides(q, held):
                    touching.append(box)
            scene.set_obstacles([b for b in boxes if b not in touching])
        elif self.grasps and self.last_attempt():
            # the last attempt: blocks pressed against the target (one fell right beside it) are left out of
            # the scene, and the closing fingers push them aside; else no grasp of the target ever works
            near = _box(self.target_object())
            crowding = [b for b in boxes if _crowds(b, near)]
            if crowding:
                scene.set_obstacles([b for b in boxes if b not in crowding])
        return scene

    def scene_exclusions(self) -> set[str]:
        """Objects left out of the arm's planning scene: the target (the planner adds it itself) and what the arm holds."""
        held = self.arm.held
        return {self.target_object().name} | ({held.name} if held is not None else set())

    def last_attempt(self) -> bool:
        """Whether this is the last attempt (objects crowding the target are then pushed aside)."""
        return self.attempts == self.retries - 1

    def _held_box(self, scene: ArmScene, q: np.ndarray) -> Box | None:
        """What the arm holds, as a box in the tool's frame (None when it holds nothing)."""
        held = self.arm.held
        if held is None:
            return None
        from alica.skills.manipulation import held_box

        try:
            return held_box(_box(held), scene.fk(q))
        except ValueError:
            return None  # tilted in the hand: the planner says so itself

    def _phase_plan(self) -> Status:
        if self.job is None and self.arm.busy:
            return self.running("waiting for the arm to come back")
        if self.job is None:
            self.job = self.jobs.submit(self.plan, self._scene(), np.asarray(self.arm.q(), dtype=float), self.np_rng)
            return self.running("planning the arm motion")
        if not self.job.done():
            return self.running("planning the arm motion")
        result = self.job.result()
        self.job = None
        if not result.ok:
            return self._retry(f"no arm plan: {result.reason}")
        self.steps = self.arm_steps([np.asarray(p) for p in result.paths])
        self.step_index = 0
        self.phase = "execute"
        if self.grasps:
            self.arm.open()
        return self.running("arm plan ready")

    def _phase_execute(self) -> Status:
        arm = self.arm
        if arm.busy:
            return self.running(f"moving the arm (step {self.step_index}/{len(self.steps)})")
        while self.step_index < len(self.steps):
            step = self.steps[self.step_index]
            self.step_index += 1
            if isinstance(step, str):
                taken = self._grip_or_release()
                if taken is not None:
                    return self.fail(taken)
                continue
            arm.follow(step, _duration(step))
            if not self.released:  # after a release the way back would lead through what was put down
                self.followed.append(np.asarray(step, dtype=float))
            return self.running(f"moving the arm (step {self.step_index}/{len(self.steps)})")
        self.phase = "verify"
        self.settle_until = self.now() + (SETTLE if self.released else 0.0)
        return self.running("checking the result")

    def _grip_or_release(self) -> str | None:
        """Close on the object or let it go; why not, when another robot has taken the object or put one on it meanwhile."""
        arm = self.arm
        if self.grasps:
            obj = self.target_object()
            holder = next(
                (
                    r.name
                    for r in self.world.robots.values()
                    if r.arm is not None and r.arm.held is obj and r is not self.robot
                ),
                None,
            )
            if holder is not None:
                return f"{obj.name} was taken by robot '{holder}' before the grip"
            if obj.kind == "block" and ("clear", obj.name) not in blocks_state(self.world):
                return f"something was put on {obj.name} before the grip"  # lifting it would throw that off
            arm.close(self.finger_force())
            arm.attach(obj.name)
        else:
            arm.detach()
            arm.open()
            self.followed = []
            self.released = True
        return None

    def _phase_verify(self) -> Status:
        if self.now() < self.settle_until:
            return self.running("letting the object settle")
        reason = self.check_after()
        if reason is None:
            return self.finished()
        return self._retry(reason)

    def _retry(self, reason: str) -> Status:
        self.attempts += 1
        if self.world_model is not None and self.counts_attempts:
            self.world_model.set("attempts", self.robot.name, value=self.attempts)
        if self.attempts >= self.retries:
            return self.fail(f"gave up after {self.attempts} attempt(s): {reason}")
        arm = self.arm
        if self.grasps and arm.held is not None:
            arm.detach()
        if self.grasps:
            arm.open()
        elif arm.held is not self.target_object():
            # released, but it does not rest where it should: there is nothing left to place
            x, y, z = (float(v) for v in self.target_object().position())
            return self.fail(
                f"{reason}; {self.target_object().name} is no longer in the hand (it lies at ({x:.2f}, {y:.2f}, {z:.2f}))"
            )
        self.phase = "plan"
        self.job = None
        if reason.startswith("no arm plan"):
            # the arm found no way from here: the next attempt comes from another side of the work site
            self.tried_sides.append((float(self.robot.pose[0]), float(self.robot.pose[1])))
            self.phase = "approach"
            self.mover = None
        return self.running(f"retrying ({reason})")

    def terminate(self, new_status: Status) -> None:
        """Stop the base (and the inner approach) when the skill ends or is stopped.

        A skill that fails or is stopped with the arm out and an empty hand
        gets its arm out of the way (:meth:`_back_out`): a hand left at a stack
        would push the blocks others put there.
        """
        if self.mover is not None and self.mover.status == Status.RUNNING:
            self.mover.stop(Status.INVALID)
        if getattr(self, "reserved_xy", None) is not None and self.has_robot:
            reservations.release(self)
            self.reserved_xy = None
        if self.has_robot:
            self.robot.stop()
            if new_status != Status.SUCCESS:
                self._back_out()

    def _back_out(self) -> None:
        """Get an empty hand away from the work site.

        Before anything was put down, the arm follows this skill's paths
        backwards to where it started (nothing it passed has moved: a failed
        grip lets go where it gripped). After a release it goes on with the
        rest of the plan instead (the retreat and the way back to the
        transport pose), since the way back leads through the object it put
        down. An arm that holds something stays as it is.
        """
        arm = self.robot.arm
        if arm is None or self.robot.crashed or arm.held is not None:
            return
        q = np.asarray(arm.q(), dtype=float)
        followed = self.followed
        if followed:
            last = followed[-1]
            k = _reached(last, q)
            way = [last[: k + 1][::-1], *(path[::-1] for path in reversed(followed[:-1]))]
        elif self.released:
            steps, index = self.steps, self.step_index
            way = [np.asarray(step, dtype=float) for step in steps[index:] if not isinstance(step, str)]
            current = steps[index - 1] if 0 < index <= len(steps) and not isinstance(steps[index - 1], str) else None
            if current is not None and arm.busy:
                way.insert(
                    0, np.asarray(current, dtype=float)[_reached(current, q) :]
                )  # the rest of the path it was on
        else:
            way = []
        self.followed = []
        if way:
            arm.stop()
            arm.follow(np.vstack(way))


def _reached(path: Any, q: np.ndarray) -> int:
    """The waypoint of ``path`` closest to the configuration ``q``: how far along the path the arm got."""
    return int(np.argmin(np.abs(np.asarray(path, dtype=float) - q).max(axis=1)))


def _xy_text(xy: tuple[float, float]) -> str:
    return f"({float(xy[0]):.2f}, {float(xy[1]):.2f})"


def _mount_ahead(robot: MobileRobot) -> float:
    """How far ahead of the base centre the arm is mounted (metres; 0 without an arm)."""
    return float(robot.arm.mount_offset[0]) if robot.arm is not None else 0.0


def inside_field(world: RobotWorld, xy: tuple[float, float], margin: float) -> bool:
    """Whether ``xy`` lies at least ``margin`` metres inside the world's field."""
    xmin, ymin, xmax, ymax = world.bounds
    return xmin + margin <= xy[0] <= xmax - margin and ymin + margin <= xy[1] <= ymax - margin


def putdown_spots(world: RobotWorld, robot: MobileRobot) -> list[tuple[float, float]]:
    """The spots at the arm's reach where ``robot`` could put a block down, straight ahead first, then turned.

    Only spots with :data:`PUTDOWN_ROOM` free of objects and other robots are listed, and
    only those :data:`EDGE_ROOM` inside the field: a robot stands beside a block to take
    it, and a block at the edge leaves it few sides to stand on.
    """
    from alica.worldsim.queries import blocker

    x, y, yaw = robot.pose
    ahead = REACH + _mount_ahead(robot)
    spots = []
    for turn in PUTDOWN_TURNS:
        spot = (x + ahead * math.cos(yaw + turn), y + ahead * math.sin(yaw + turn))
        if not inside_field(world, spot, EDGE_ROOM):
            continue
        hit = blocker(world, spot[0], spot[1], PUTDOWN_ROOM)
        if hit is None or hit == f"robot '{robot.name}'":
            spots.append(spot)
    return spots


def _near(obj: WorldThing, xy: tuple[float, float], radius: float = 1.2) -> bool:
    position = obj.position()
    return distance((float(position[0]), float(position[1])), xy) <= radius


# -- the skills ---------------------------------------------------------------


class Pickup(ArmSkill):
    """Pick ``object`` up and hold it in the transport pose (retries after a failed grasp)."""

    def check_before(self) -> str | None:
        """The hand must be empty; a block must be clear and on the table (IPC pickup)."""
        if self.arm.held is not None:
            return f"the hand is not empty: it holds {self.arm.held.name}"
        obj = self.target_object()
        if obj.kind == "block":
            facts = blocks_state(self.world)
            if ("clear", obj.name) not in facts:
                return f"precondition clear({obj.name}) does not hold: something lies on it"
            if ("ontable", obj.name) not in facts and self.requires_table:
                return f"precondition ontable({obj.name}) does not hold: use Unstack to take it off a block"
        return None

    requires_table = True

    def check_after(self) -> str | None:
        """The object is held with force."""
        arm = self.arm
        obj = self.target_object()
        if arm.held is not obj or arm.grip_force() <= 0:
            return f"the grip on {obj.name} failed (the object is not held)"
        write_held(self, self.object_label())
        return None


class Unstack(Pickup):
    """Take ``object`` off the block ``from`` (IPC unstack)."""

    requires_table = False

    def check_before(self) -> str | None:
        """``on(object, from)``, ``clear(object)`` and an empty hand."""
        reason = super().check_before()
        if reason is not None:
            return reason
        below = self.param("from")
        obj = self.target_object()
        if ("on", obj.name, below) not in blocks_state(self.world):
            return f"precondition on({obj.name}, {below}) does not hold"
        return None

    def check_after(self) -> str | None:
        """Held, and ``clear(from)`` now holds."""
        reason = super().check_after()
        if reason is None:
            below = str(self.param("from"))
            self.write(False, "on", self.target_object().name, below)
            self.write(True, "clear", below)
        return reason


class Putdown(ArmSkill):
    """Put the held ``object`` down at ``target`` (by default on the ground in front of the robot)."""

    grasps = False

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name, params, context)
        #: The free spot chosen (kept from when an opponent asked for :meth:`site` before the start).
        self._spot: tuple[float, float] | None = None
        #: Spots where a placement failed.
        self._tried: list[tuple[float, float]] = []

    def check_before(self) -> str | None:
        """The robot must hold the object."""
        held = self.arm.held
        obj = self.target_object()
        if held is not obj:
            return f"precondition holding({self.robot.name}, {obj.name}) does not hold (holding {held.name if held else 'nothing'})"
        return None

    def site(self) -> tuple[float, float]:
        """The target (a position, a place such as ``pos(g)``, or a block to put it on), or a free spot near the robot.

        The free spot lies at the arm's reach, straight ahead if nothing is there, else
        turned to one side; a retry after a failed placement takes another spot.
        """
        target = self.param("target")
        if target is not None and place_area(self, target) is None:
            return self.resolve_position(target)
        if self._spot is None:
            self._spot = self._free_spot()
        return self._spot

    def _free_spot(self) -> tuple[float, float]:
        tried = self._tried
        area = place_area(self, self.param("target"))
        spots = (
            putdown_spots(self.world, self.robot)
            if area is None
            else area_spots(self.world, self.robot, area, AREA_ROOM)
        )
        for spot in spots:
            if not any(distance(spot, old) < PUTDOWN_ROOM for old in tried):
                return spot
        if area is not None:
            return area[0], area[1]  # nothing free in the area: its centre (the placement check fails)
        x, y, yaw = self.robot.estimate
        ahead = REACH + _mount_ahead(self.robot)
        return x + ahead * math.cos(yaw), y + ahead * math.sin(
            yaw
        )  # nothing free: straight ahead (the placement check fails)

    def _retry(self, reason: str) -> Status:
        """Try another spot on the next attempt (when no target was given)."""
        status = super()._retry(reason)
        if status == Status.RUNNING and (self.param("target") is None or place_area(self, self.param("target"))):
            self._tried = [*self._tried, self.site()]
            self._spot = None
            self.phase = "approach"
            self.mover = None
        return status

    def check_after(self) -> str | None:
        """Released, resting near the place."""
        obj = self.target_object()
        if self.arm.held is not None:
            return f"{obj.name} is still in the hand"
        x, y, _ = self.place_top()
        here = obj.position()
        if math.hypot(here[0] - x, here[1] - y) > PLACE_TOLERANCE:
            return f"{obj.name} lies at ({here[0]:.2f}, {here[1]:.2f}), not at ({x:.2f}, {y:.2f})"
        write_released(self, self.object_label())
        write_placed(self, self.object_label(), obj, self.param("target"))
        return None


class Stack(Putdown):
    """Put the held ``object`` on top of the clear block ``target`` (IPC stack)."""

    def check_before(self) -> str | None:
        """Holding the object, and the target block is clear."""
        reason = super().check_before()
        if reason is not None:
            return reason
        below = self.object_named(self.param("target"))
        if ("clear", below.name) not in blocks_state(self.world):
            return f"precondition clear({below.name}) does not hold: something lies on it"
        return None

    def site(self) -> tuple[float, float]:
        """The target block."""
        position = self.object_named(self.param("target")).position()
        return float(position[0]), float(position[1])

    def place_top(self) -> tuple[float, float, float]:
        """On top of the target block."""
        below = self.object_named(self.param("target"))
        _, high = below.aabb()
        x, y = self.site()
        return x, y, float(high[2])

    def check_after(self) -> str | None:
        """``on(object, target)`` holds in the simulated state."""
        obj = self.target_object()
        below = str(self.param("target"))
        if self.arm.held is not None:
            return f"{obj.name} is still in the hand"
        if ("on", obj.name, below) not in blocks_state(self.world):
            return f"{obj.name} did not come to rest on {below}"
        write_released(self, self.object_label())
        self.write(True, "clear", self.object_label())
        self.write(True, "on", self.object_label(), below)
        self.write(False, "clear", below)
        return None
