"""Manipulation skills: Pickup, Putdown, Stack and Unstack, with the IPC blocks-world semantics.

Each skill runs the same phases (:class:`Phase`), polled tick by tick; the
table :data:`PHASES` says what each phase does:

1. **check**: the skill's preconditions (:meth:`ArmSkill.check_before`);
2. **approach**: if the work site is out of the arm's reach, drive to a
   stand-off point facing it, then turn to it (:class:`~alica.skills.arm_approach.Approach`);
3. **plan**: a job plans the arm motion on the arm's planning scene
   (:mod:`alica.skills.arm_motion`, :mod:`alica.skills.manipulation`: IK with
   joint-limit checks and random restarts, OMPL joint-space paths with
   collision checks, the held object included);
4. **execute**: the arm follows the paths in simulated time; the gripper
   closes and the object becomes an attachment (Pickup, Unstack) or is
   released (Putdown, Stack) (:class:`~alica.skills.arm_motion.ArmMotion`);
5. **verify**: the grip (finger force, the object still held) or the
   placement (the object rests where it should) is checked against the
   simulated state; a failed grasp opens the hand and retries, up to
   ``retries`` times, then the skill fails and says why.

For blocks, preconditions and effects are those of the IPC blocks domain
(``clear``, ``on``, ``ontable``, ``holding``, ``handempty``), checked before and
after (:mod:`alica.skills.blocks_rules`); the effects are written to the world model.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from enum import StrEnum
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills import blocks_rules, reservations
from alica.skills.arm_approach import Approach
from alica.skills.arm_motion import ArmMotion, ArmStep, grasp_shape, held_object_box, object_box, planning_scene
from alica.skills.arm_world import (
    REACH,
    area_spots,
    find_object,
    inside_field,
    known_discs,
    mount_ahead,
    place_area,
    write_held,
    write_placed,
    write_released,
)
from alica.skills.close_look import Sighting, in_arm_frame, look_at
from alica.skills.context import SkillContextLike
from alica.skills.jobs import Job
from alica.skills.team_poses import holders
from alica.skills.world_skill import WorldSkill, distance
from alica.worldsim.arm_interface import ArmPlanningScene, RobotArm
from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import Box
from alica.worldsim.interface import WorldThing

if TYPE_CHECKING:
    from alica.skills.manipulation import PickupPlan, PlacePlan, TransportPlan

__all__ = [
    "AREA_ROOM",
    "PHASES",
    "PLACE_TOLERANCE",
    "REACH",
    "SETTLE",
    "ArmSkill",
    "Phase",
    "Pickup",
    "Putdown",
    "Stack",
    "Unstack",
    "inside_field",
]

#: Seconds a released object gets to settle before the placement is checked.
SETTLE = 0.5
#: Free room (m) a spot in an area (the collection point) needs: the hand descends beside what stands there.
AREA_ROOM = 0.25
#: How far (m) a placed object may lie from its place and count as placed there.
PLACE_TOLERANCE = 0.08


class Phase(StrEnum):
    """The phases of an arm skill, in order (a retry goes back to plan, or to approach for another side)."""

    CHECK = "check"
    """The preconditions are checked."""
    APPROACH = "approach"
    """The robot drives to a stand-off point facing the work site."""
    PLAN = "plan"
    """A job plans the arm's motion."""
    EXECUTE = "execute"
    """The arm follows the plan; the gripper grips or releases."""
    VERIFY = "verify"
    """The outcome is checked (after the object settled)."""


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

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name, params, context)
        self.phase = Phase.CHECK
        self.approach = Approach(self)
        self.motion = ArmMotion()
        self.job: Job | None = None
        #: The close look's measurement of the sample to grasp (:meth:`look`); None before it, and for blocks.
        self.sighting: Sighting | None = None

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm (when :attr:`needs_arm`)."""
        super().setup(**kwargs)
        if self.needs_arm and self.robot.arm is None:
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' has no arm")

    @property
    def arm(self) -> RobotArm:
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
        """Where the work happens, for the approach: where the robot believes the object is (:meth:`expected_xy`)."""
        return self.expected_xy()

    def expected_xy(self) -> tuple[float, float]:
        """Where the robot believes the object to grasp lies.

        A sample: the close look's measurement (:meth:`look`), else the team's
        detection ``pos(object)`` in the world model. A block, or a sample
        without ``pos(object)`` in a world whose layout is known (a skill run
        alone): the object's place in the world, the stand-in for the blocks
        world's overhead camera.
        """
        obj = self.target_object()
        if obj.kind == "sample":
            if self.sighting is not None:
                return self.sighting.xy
            wm = self.world_model
            known = wm.lookup("pos", (self.object_label(),)) if wm is not None else None
            if isinstance(known, (tuple, list)) and len(known) >= 2:
                return float(known[0]), float(known[1])
        position = obj.position()
        return float(position[0]), float(position[1])

    def look(self) -> None:
        """Before planning a grasp of a sample: a close look with the robot's camera at where it should lie.

        The measurement (:func:`alica.skills.close_look.look_at`) replaces the
        detection for the site and the grasp; when the camera sees nothing
        there, the last measurement (or the detection) stays.
        """
        if not self.grasps:
            return
        obj = self.target_object()
        if obj.kind != "sample" or not obj.radius:
            return
        seen = look_at(self.robot, self.expected_xy(), size=float(obj.size), radius=float(obj.radius))
        if seen is not None:
            self.sighting = seen

    def grasp_target(self) -> tuple[Box, Literal["box", "cylinder"]]:
        """The object to grasp as the arm planner's box, and how to grasp it.

        A sample: as the close look measured it (:meth:`look`), or standing
        upright at the detection when the camera saw nothing. A block: its box
        in the world (the overhead camera's stand-in).
        """
        obj = self.target_object()
        if obj.kind == "sample" and obj.radius:
            size, radius = float(obj.size), float(obj.radius)
            seen = self.sighting
            if seen is None:
                x, y = self.expected_xy()
                seen = Sighting(x, y, 0.0, size, 0.0, True, 0.0, 0)
            arm = self.robot.arm
            if arm is not None:  # measured from the robot: relative to the arm's base, where the arm plans
                seen = in_arm_frame(seen, self.robot.estimate, arm.mount_offset, arm.base_pose())
            return seen.box(obj.name, size, radius), ("cylinder" if seen.upright else "box")
        return object_box(obj), grasp_shape(obj)

    def check_before(self) -> str | None:
        """Why the skill cannot start now, or None."""
        return None

    def before_grip(self, obj: WorldThing) -> str | None:
        """Why the fingers must not close on ``obj`` now (something changed since the plan), or None."""
        return None

    def plan(
        self, scene: ArmPlanningScene, q: np.ndarray, rng: np.random.Generator
    ) -> PickupPlan | PlacePlan | TransportPlan:
        """The arm plan, run as a job: grasp and lift, or place at :meth:`place_top` and retreat."""
        from alica.skills.manipulation import PlacePlan, plan_pickup, plan_place

        if self.grasps:
            box, kind = self.grasp_target()
            return plan_pickup(scene, box, q, rng=rng, kind=kind)
        held = held_object_box(self.arm, scene, q)  # the object in the tool's frame
        if held is None:
            return PlacePlan(False, None, None, None, None, [], "the object is tilted in the hand")
        return plan_place(scene, held, self.place_top(), q, rng=rng)

    def arm_steps(self, paths: list[np.ndarray]) -> list[ArmStep]:
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

    def standoff(self) -> float:
        """Distance (m) from the work site to the robot's centre after the approach: the arm's reach ahead of its mount."""
        return REACH + mount_ahead(self.robot)

    def approach_slack(self) -> float:
        """How far (m) from :meth:`standoff` the robot may stand and still work without driving."""
        return 0.12

    def approach_tolerance(self) -> float:
        """The goal tolerance (m) of the drive to the stand-off point."""
        return 0.05

    def approached(self) -> Status:
        """The robot stands at the work site, facing it: go on with planning the arm motion."""
        self.phase = Phase.PLAN
        return _plan(self)

    def scene_exclusions(self) -> set[str]:
        """Objects left out of the arm's planning scene: the target (the planner adds it itself) and what the arm holds."""
        held = self.arm.held
        return {self.target_object().name} | ({held.name} if held is not None else set())

    def last_attempt(self) -> bool:
        """Whether this is the last attempt (objects crowding the target are then pushed aside)."""
        return self.attempts == self.retries - 1

    # -- the run -----------------------------------------------------------------

    def initialise(self) -> None:
        """Start with the check."""
        self.retries = int(self.param("retries", 3))  # type: ignore[call-overload]
        self.attempts = 0
        self.phase = Phase.CHECK
        self.approach = Approach(self)
        self.motion = ArmMotion()
        self.job = None
        self.sighting = None
        self.settle_until = 0.0
        self.np_rng = np.random.default_rng(self.context.rng.randrange(2**31) if self.context is not None else 0)

    def update(self) -> Status:
        """One step of the current phase (a held stand-off reservation is refreshed now and then)."""
        self.approach.refresh()
        return PHASES[self.phase](self)

    def _retry(self, reason: str) -> Status:
        """Another attempt after ``reason``: from the plan, or from another side when the arm found no plan."""
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
        self.phase = Phase.PLAN
        self.job = None
        if reason.startswith("no arm plan"):
            # the arm found no way from here: the next attempt comes from another side of the work site
            self.approach.avoid_here()
            self.phase = Phase.APPROACH
        return self.running(f"retrying ({reason})")

    def terminate(self, new_status: Status) -> None:
        """Stop the base (and the inner approach) when the skill ends or is stopped.

        A skill that fails or is stopped with the arm out and an empty hand
        gets its arm out of the way (:meth:`~alica.skills.arm_motion.ArmMotion.back_out`):
        a hand left at a stack would push the blocks others put there. An arm
        that holds something stays as it is.
        """
        self.approach.end()
        if self.has_robot:
            self.robot.stop()
            arm = self.robot.arm
            if new_status != Status.SUCCESS and arm is not None and not self.robot.crashed and arm.held is None:
                self.motion.back_out(arm)


# -- the phases ------------------------------------------------------------------


def _check(skill: ArmSkill) -> Status:
    reason = skill.check_before()
    if reason is not None:
        return skill.fail(reason)
    if not skill.approaches:
        skill.phase = Phase.PLAN
        return _plan(skill)
    skill.phase = Phase.APPROACH
    return skill.approach.tick()


def _plan(skill: ArmSkill) -> Status:
    arm = skill.arm
    if skill.job is None and arm.busy:
        return skill.running("waiting for the arm to come back")
    if skill.job is None:
        skill.look()  # a sample: where the camera sees it now, before each plan (a failed grasp may have moved it)
        crowded = skill.target_object() if skill.grasps and skill.last_attempt() else None
        scene = planning_scene(arm, skill.world.objects, skill.scene_exclusions(), crowded)
        skill.job = skill.jobs.submit(skill.plan, scene, np.asarray(arm.q(), dtype=float), skill.np_rng)
        return skill.running("planning the arm motion")
    if not skill.job.done():
        return skill.running("planning the arm motion")
    result = skill.job.result()
    skill.job = None
    if not result.ok:
        return skill._retry(f"no arm plan: {result.reason}")
    skill.motion.start(skill.arm_steps([np.asarray(p) for p in result.paths]))
    skill.phase = Phase.EXECUTE
    if skill.grasps:
        arm.open()
    return skill.running("arm plan ready")


def _execute(skill: ArmSkill) -> Status:
    arm, motion = skill.arm, skill.motion
    if arm.busy:
        return skill.running(f"moving the arm ({motion.progress})")
    done, refusal = motion.advance(arm, lambda _step: _grip_or_release(skill))
    if refusal is not None:
        return skill.fail(refusal)
    if not done:
        return skill.running(f"moving the arm ({motion.progress})")
    skill.phase = Phase.VERIFY
    skill.settle_until = skill.now() + (SETTLE if motion.released else 0.0)
    return skill.running("checking the result")


def _grip_or_release(skill: ArmSkill) -> str | None:
    """Close on the object or let it go; why not, when another robot has taken the object or it changed meanwhile."""
    arm = skill.arm
    if not skill.grasps:
        skill.motion.release(arm)
        return None
    obj = skill.target_object()
    holder = holders(skill.team_model, skill.team_belief).get(
        obj.name
    )  # what the team says; the gripper tells the rest
    if holder is not None and holder != skill.robot.name:
        return f"{obj.name} was taken by robot '{holder}' before the grip"
    refusal = skill.before_grip(obj)
    if refusal is not None:
        return refusal
    arm.close(skill.finger_force())
    try:
        arm.attach(obj.name)
    except WorldError as exc:  # taken by a teammate whose holding(...) has not reached this robot yet
        return f"{obj.name} could not be gripped: {exc}"
    return None


def _verify(skill: ArmSkill) -> Status:
    if skill.now() < skill.settle_until:
        return skill.running("letting the object settle")
    reason = skill.check_after()
    if reason is None:
        return skill.finished()
    return skill._retry(reason)


#: What each phase does: one step of it, polled by :meth:`ArmSkill.update`.
PHASES: Mapping[Phase, Callable[[ArmSkill], Status]] = {
    Phase.CHECK: _check,
    Phase.APPROACH: lambda skill: skill.approach.tick(),
    Phase.PLAN: _plan,
    Phase.EXECUTE: _execute,
    Phase.VERIFY: _verify,
}


# -- the skills ---------------------------------------------------------------


class Pickup(ArmSkill):
    """Pick ``object`` up and hold it in the transport pose (retries after a failed grasp)."""

    #: Whether a block must lie on the table (IPC pickup; Unstack takes it off a block).
    requires_table = True

    def check_before(self) -> str | None:
        """The hand must be empty; a block must be clear and on the table (IPC pickup)."""
        if self.arm.held is not None:
            return f"the hand is not empty: it holds {self.arm.held.name}"
        obj = self.target_object()
        if obj.kind == "block":
            facts = blocks_rules.blocks_state(self.world)
            return blocks_rules.pickup_refusal(facts, obj.name, from_table=self.requires_table)
        return None

    def before_grip(self, obj: WorldThing) -> str | None:
        """A block must still be clear: lifting it would throw off what was put on it."""
        if obj.kind == "block":
            return blocks_rules.grip_refusal(blocks_rules.blocks_state(self.world), obj.name)
        return None

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
        obj = self.target_object()
        return blocks_rules.unstack_refusal(blocks_rules.blocks_state(self.world), obj.name, self.param("from"))

    def check_after(self) -> str | None:
        """Held, and ``clear(from)`` now holds."""
        reason = super().check_after()
        if reason is None:
            blocks_rules.write_unstacked(self, self.target_object().name, str(self.param("from")))
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
        turned to one side; a retry after a failed placement takes another spot. With
        the parameter ``spread`` (metres) the robot first looks for the nearest spot that
        far from every block and from the stand-off points teammates reserved
        (:func:`~alica.skills.blocks_rules.spread_spots`), and drives there: the stacks
        spread over the field instead of crowding where the blocks were taken from.
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
        if area is not None:
            spots = area_spots(self.world, self.robot, area, AREA_ROOM, self._known_taken())
        else:
            spread = float(self.param("spread", 0.0))  # type: ignore[arg-type]
            near = blocks_rules.putdown_spots(self.world, self.robot)
            spots = near
            if spread > 0:
                taken = [(x, y) for x, y, _ in reservations.reserved(self)]
                spots = [*blocks_rules.spread_spots(self.world, self.robot, spread, taken, near), *near]
        for spot in spots:
            if not any(distance(spot, old) < blocks_rules.PUTDOWN_ROOM for old in tried):
                return spot
        if area is not None:
            return area[0], area[1]  # nothing free in the area: its centre (the placement check fails)
        x, y, yaw = self.robot.estimate
        ahead = REACH + mount_ahead(self.robot)
        return x + ahead * math.cos(yaw), y + ahead * math.sin(yaw)  # nothing free: straight ahead (the check fails)

    def _known_taken(self) -> list[tuple[float, float, float]] | None:
        """In a mission that maps, what the team knows lies or stands in the area (:func:`known_discs`); else None.

        Without a team map the layout counts as known (the blocks world, a skill
        run alone) and the spots are checked against the world's objects.
        """
        if not self.mapping_mission():
            return None
        return known_discs(self, skip=self.object_label())

    def _retry(self, reason: str) -> Status:
        """Try another spot on the next attempt (when no target was given)."""
        status = super()._retry(reason)
        if status == Status.RUNNING and (self.param("target") is None or place_area(self, self.param("target"))):
            self._tried = [*self._tried, self.site()]
            self._spot = None
            self.phase = Phase.APPROACH
            self.approach.again()
        return status

    def check_after(self) -> str | None:
        """Released, resting near the place."""
        obj = self.target_object()
        if self.arm.held is not None:
            return f"{obj.name} is still in the hand"
        x, y, _ = self.place_top()
        if obj.kind == "sample" and obj.radius:  # the robot looks where it put the sample down
            seen = look_at(self.robot, (x, y), size=float(obj.size), radius=float(obj.radius))
            if seen is None:
                return f"the camera sees no {obj.name} where it was put down ({x:.2f}, {y:.2f})"
            here: tuple[float, ...] = seen.xy
        else:  # a block: the overhead camera's stand-in
            here = tuple(float(v) for v in obj.position())
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
        return blocks_rules.stack_refusal(blocks_rules.blocks_state(self.world), below.name)

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
        reason = blocks_rules.stacked_refusal(blocks_rules.blocks_state(self.world), obj.name, below)
        if reason is not None:
            return reason
        write_released(self, self.object_label())
        blocks_rules.write_stacked(self, self.object_label(), below)
        return None
