"""The steps of the Pickup and Putdown skill plans (IMPERA Figs. 15 and 16), one skill each.

``plans/skills/pickup.yaml`` runs AlignWithObject, Grasp, MoveArmToTransport
and ValidateGrip (OpenGripper between attempts); ``plans/skills/putdown.yaml``
runs MoveArmToPlace, OpenGripper, MoveArmToTransport and VerifyPlaced. They
are the phases of the monolithic :class:`~alica.skills.handling.Pickup` and
:class:`~alica.skills.handling.Putdown` run one at a time: the same approach,
arm planning, execution and checks (:class:`~alica.skills.handling.ArmSkill`).

What the gripper holds is in the world (``robot.arm``); the steps hand the
rest on in the agent's scratch space (``context.scratch``), in the typed slots
of :mod:`alica.skills.arm_scratch`:

``"grasp"`` (:class:`~alica.skills.arm_scratch.GraspCount`)
    the grasp attempts on an object (Grasp counts them, OpenGripper marks
    the next one a retry, ValidateGrip's success ends the count).
``"names"`` (:class:`~alica.skills.arm_scratch.GraspedNames`)
    the world object each name a plan gave Grasp stands for.
``"held"`` (:class:`~alica.skills.arm_scratch.Held`)
    what Grasp took (the plan's name and the world's); OpenGripper and
    ValidateGrip (on a slip) drop it.
``"arm_retreat"`` (:class:`~alica.skills.arm_scratch.Retreat`)
    the rest of the last arm plan (the lift after a grasp, the retreat after
    a placement), which MoveArmToTransport follows when it starts where the arm is.
``"tried_sides"`` (:class:`~alica.skills.arm_scratch.TriedSides`)
    stand-off points from which Grasp found no arm plan; AlignWithObject
    takes another side of the object.
``"aligned"`` (:class:`~alica.skills.arm_scratch.Aligned`)
    where AlignWithObject left the robot.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.arm_motion import ArmStep, arm_xy, held_object_box
from alica.skills.arm_scratch import (
    ALIGNED,
    ARM_RETREAT,
    GRASP,
    HELD,
    NAMES,
    PLACED,
    TRIED_SIDES,
    Aligned,
    GraspCount,
    GraspedNames,
    Held,
    Placed,
    Retreat,
    TriedSides,
)
from alica.skills.arm_world import REACH, find_object, place_area, write_held, write_placed, write_released
from alica.skills.close_look import GROUND_CUT, look_at
from alica.skills.handling import PLACE_TOLERANCE, SETTLE, ArmSkill, Phase, Pickup, Putdown
from alica.skills.team_poses import holders
from alica.skills.world_skill import WorldSkill, distance, number_param
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.interface import WorldThing

if TYPE_CHECKING:
    from alica.skills.manipulation import TransportPlan

#: Grasp attempts after which crowding objects are pushed aside (the plans give up after three).
GRASP_ATTEMPTS = 3
#: How far beyond :data:`~alica.skills.arm_world.REACH` (m) an object may be from the arm's base for Grasp to try.
REACH_SLACK = 0.25
#: An object whose bottom is higher than this (m) does not lie on the ground.
ON_GROUND = 0.03


def _scratch(skill: WorldSkill) -> dict[str, object]:
    """The agent's scratch space (an own dict when the context has none)."""
    if skill.context is not None:
        return skill.context.scratch
    own: dict[str, object] = skill.__dict__.setdefault("_own_scratch", {})
    return own


def _label(skill: WorldSkill, obj: WorldThing) -> str:
    """The name the plan gave the held object ``obj`` (the world's name when Grasp did not take it)."""
    held = HELD.get(_scratch(skill))
    if held is not None and held.world == obj.name:
        return held.object
    return obj.name


def _has_arm(skill: WorldSkill) -> None:
    if skill.robot.arm is None:
        raise SkillError(f"skill '{skill.name}': robot '{skill.robot.name}' has no arm")


class AlignWithObject(ArmSkill):
    """Drive to a stand-off point facing ``object``, ``standoff`` from it within ``tolerance``.

    The approach of :class:`~alica.skills.handling.ArmSkill` alone: an inner
    MoveToPosition to a free side of the object (by the robot's pose estimate),
    then a turn to face it. The object's place is the world model's
    ``pos(object)`` (perception's estimate) when known, else the object's.
    After an inaccurate drive the robot drives again (three times at most).
    A side from which Grasp found no arm plan (``scratch["tried_sides"]``) is
    not taken again.
    """

    needs_arm = False
    counts_attempts = False

    def initialise(self) -> None:
        """Check the parameters; take the sides Grasp tried."""
        super().initialise()
        given = self.param("standoff")
        self.standoff_m = None if given is None else number_param(self, "standoff", None)
        self.tolerance = number_param(self, "tolerance", 0.02)
        self.drives = 0
        tried = TRIED_SIDES.get(_scratch(self))
        if tried is not None and tried.object == self.object_label():
            self.approach.tried_sides = list(tried.sides)

    def site(self) -> tuple[float, float]:
        """Where the object is: the robot's close look, else the world model's estimate, else the world's."""
        if self.sighting is not None:
            return self.sighting.xy
        return self.resolve_position(self.param("object"))

    def expected_xy(self) -> tuple[float, float]:
        """Where the object should be (:meth:`site`)."""
        return self.site()

    def standoff(self) -> float:
        """The ``standoff`` parameter; by default the arm's reach ahead of its mount."""
        return super().standoff() if self.standoff_m is None else self.standoff_m

    def approach_slack(self) -> float:
        """The ``tolerance``."""
        return self.tolerance

    def approach_tolerance(self) -> float:
        """The ``tolerance``."""
        return self.tolerance

    def approached(self) -> Status:
        """Facing the object: look at it; succeed when the distance is right, else drive again.

        The close look (:meth:`~alica.skills.handling.ArmSkill.look`) measures
        where the sample stands; when that is more than ``tolerance`` from
        where the robot aligned to (the team's detection, or a sample that
        slipped out of the hand and fell), the robot tells the team
        (``pos(object)``) and drives again.
        """
        before = self.site()
        self.look()
        site = self.site()
        moved = distance(before, site) > self.tolerance
        if moved and self.world_model is not None:
            self.world_model.set("pos", self.object_label(), value=(round(site[0], 3), round(site[1], 3)))
        x, y, _ = self.robot.estimate
        gap = distance((x, y), site)
        wanted = self.standoff()
        if abs(gap - wanted) <= self.tolerance + 1e-9:
            ALIGNED.put(_scratch(self), Aligned(self.object_label(), site, self.robot.estimate))
            return self.succeed(
                f"facing {self.object_label()} at {gap:.3f} m (stand-off {wanted:.2f} m, tolerance {self.tolerance:g} m)"
            )
        self.drives += 1
        if self.drives >= 3:
            return self.fail(
                f"cannot align with {self.object_label()}: {gap:.3f} m from it after {self.drives} drives, "
                f"wanted {wanted:.2f} m within {self.tolerance:g} m"
            )
        self.approach.again()
        self.phase = Phase.APPROACH
        return self.running(f"{gap:.3f} m from {self.object_label()}, wanted {wanted:.2f} m: driving again")


class Grasp(Pickup):
    """Plan and execute a top grasp of ``object``, close the fingers with ``force`` and attach it.

    The plan and execution of :class:`~alica.skills.handling.Pickup` up to the
    grip, from where the robot stands (AlignWithObject brought it there): to
    the pre-grasp pose, straight down, close. The arm stays at the grasp; the
    lift to the transport pose is left in ``scratch["arm_retreat"]`` for
    MoveArmToTransport. Every run is one attempt: the attempts on the object
    are counted in ``scratch["grasp"]`` and written as ``attempts(self)``
    (a run after OpenGripper counts on, any other starts at 1). On success
    ``holding(self, object)`` holds (and no longer ``handempty(self)``,
    ``onground(object)``); a failure says why and the arm backs out.
    """

    approaches = False
    counts_attempts = False

    def initialise(self) -> None:
        """Check ``force``; count the attempt."""
        super().initialise()
        self.force = number_param(self, "force", 10.0)
        self.retries = 1
        name = self.object_label()
        scratch = _scratch(self)
        record = GRASP.get(scratch)
        again = record is not None and record.object == name and record.retry
        self.attempt = record.attempts + 1 if record is not None and again else 1
        GRASP.put(scratch, GraspCount(name, self.attempt))
        scratch.pop(ARM_RETREAT.key, None)
        if self.world_model is not None:
            self.world_model.set("attempts", self.robot.name, value=self.attempt)
        self._retreat: list[np.ndarray] = []

    def check_before(self) -> str | None:
        """Pickup's preconditions, and the object within the arm's reach."""
        reason = super().check_before()
        if reason is not None:
            return reason
        obj = self.target_object()
        gap = distance(arm_xy(self.arm), self.site())
        if gap > REACH + REACH_SLACK:
            return (
                f"{obj.name} is {gap:.2f} m from the arm's base, beyond its reach ({REACH:g} m): "
                f"align with it first (AlignWithObject)"
            )
        return None

    def last_attempt(self) -> bool:
        """From the third attempt on, objects crowding the target are pushed aside."""
        return self.attempt >= GRASP_ATTEMPTS

    def finger_force(self) -> float:
        """The ``force`` parameter."""
        return self.force

    def arm_steps(self, paths: list[np.ndarray]) -> list[ArmStep]:
        """To the pre-grasp pose, down, grip; the lift is kept for MoveArmToTransport."""
        self._retreat = [np.asarray(p, dtype=float) for p in paths[2:]]
        return [*paths[:2], "grip"]

    def finished(self) -> Status:
        """Hand the lift and the names on."""
        scratch = _scratch(self)
        obj = self.target_object()
        ARM_RETREAT.put(scratch, Retreat(self.robot.name, self._retreat))
        HELD.put(scratch, Held(self.object_label(), obj.name))
        NAMES.setdefault(scratch, GraspedNames).names[self.object_label()] = obj.name
        return self.succeed(f"grasped {self.object_label()} with {self.force:g} N (attempt {self.attempt})")

    def _retry(self, reason: str) -> Status:
        """No retry here (the plan retries): fail; remember a side from which no arm plan was found."""
        if reason.startswith("no arm plan"):
            scratch = _scratch(self)
            tried = TRIED_SIDES.get(scratch)
            sides = list(tried.sides) if tried is not None and tried.object == self.object_label() else []
            x, y, _ = self.robot.estimate
            TRIED_SIDES.put(scratch, TriedSides(self.object_label(), [*sides, (float(x), float(y))]))
        if self.arm.held is not None:
            self.arm.open()
        return self.fail(f"attempt {self.attempt}: {reason}")


class MoveArmToTransport(ArmSkill):
    """Move the arm, with what it holds, to the transport pose.

    It follows the rest of the last arm plan (``scratch["arm_retreat"]``: the
    lift after Grasp, the retreat after MoveArmToPlace and OpenGripper) when
    that starts where the arm is; else it plans a straight lift and a free
    motion (:func:`~alica.skills.manipulation.plan_transport`). Stopped on the
    way, the arm goes on to the transport pose.
    """

    grasps = False
    approaches = False
    counts_attempts = False

    def initialise(self) -> None:
        """Take the stored retreat when it starts at the arm's configuration."""
        super().initialise()
        self.retries = 1
        self.motion.released = True  # stopped midway, the arm goes on to the transport pose (never back)
        self.stored: list[np.ndarray] | None = None
        scratch = _scratch(self)
        record = ARM_RETREAT.get(scratch)
        scratch.pop(ARM_RETREAT.key, None)
        if record is not None and record.robot == self.robot.name and record.paths:
            paths = [np.asarray(p, dtype=float) for p in record.paths]
            q = np.asarray(self.arm.q(), dtype=float)
            if float(np.abs(paths[0][0] - q).max()) < 1e-3:
                self.stored = paths

    def scene_exclusions(self) -> set[str]:
        """What the arm holds."""
        held = self.arm.held
        return {held.name} if held is not None else set()

    def plan(self, scene: ArmPlanningScene, q: np.ndarray, rng: np.random.Generator) -> TransportPlan:
        """The stored retreat, or a new plan to the transport pose."""
        from alica.skills.manipulation import TransportPlan, plan_transport

        if self.stored is not None:
            return TransportPlan(True, self.stored, "ok")
        return plan_transport(scene, q, rng=rng, held=held_object_box(self.arm, scene, q))

    def arm_steps(self, paths: list[np.ndarray]) -> list[ArmStep]:
        """Each path in turn."""
        return list(paths)

    def finished(self) -> Status:
        """In the transport pose."""
        held = self.arm.held
        return self.succeed("in the transport pose" + (f", holding {_label(self, held)}" if held is not None else ""))

    def _retry(self, reason: str) -> Status:
        return self.fail(reason)


class MoveArmToPlace(Putdown):
    """Move the held object to its place pose at ``target``, just above the ground (or a block).

    The plan and execution of :class:`~alica.skills.handling.Putdown` up to
    the release, with its approach (when the place is out of the arm's reach)
    and its choice of place: a position; a free spot in an area such as the
    collection point ``pos(g)``; a free spot in front of the robot by default.
    The retreat is left in ``scratch["arm_retreat"]`` for MoveArmToTransport
    (after OpenGripper).
    """

    counts_attempts = False

    def initialise(self) -> None:
        """Start with nothing kept."""
        super().initialise()
        self._retreat: list[np.ndarray] = []

    def target_object(self) -> WorldThing:
        """What the arm holds.

        Raises:
            SkillError: the hand is empty.
        """
        held = self.arm.held
        if held is None:
            raise SkillError(f"skill '{self.name}': robot '{self.robot.name}' holds nothing to place")
        return held

    def object_label(self) -> str:
        """The plan's name of the held object."""
        return _label(self, self.target_object())

    def check_before(self) -> str | None:
        """Something is held."""
        if self.arm.held is None:
            return "the hand is empty: there is nothing to place (run Pickup or Grasp first)"
        return None

    def arm_steps(self, paths: list[np.ndarray]) -> list[ArmStep]:
        """Above the place and down; the retreat is kept for MoveArmToTransport."""
        self._retreat = [np.asarray(p, dtype=float) for p in paths[2:]]
        return list(paths[:2])

    def check_after(self) -> str | None:
        """Still held."""
        if self.arm.held is None:
            return "the object slipped out of the hand on the way to its place"
        return None

    def finished(self) -> Status:
        """Hand the retreat and the place on."""
        ARM_RETREAT.put(_scratch(self), Retreat(self.robot.name, self._retreat))
        x, y, _ = self.place_top()
        PLACED.put(_scratch(self), Placed(self.object_label(), (float(x), float(y))))
        return self.succeed(f"{self.object_label()} at its place ({x:.2f}, {y:.2f})")


class OpenGripper(WorldSkill):
    """Open the fingers and let go of what they hold; succeed once it has settled.

    Letting go writes ``handempty(self)`` and no longer ``holding(self, object)``;
    a grasp count under way (``scratch["grasp"]``) makes the next Grasp a retry.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm."""
        super().setup(**kwargs)
        _has_arm(self)

    def initialise(self) -> None:
        """Nothing opened yet."""
        self.until: float | None = None
        self.let_go = ""

    def update(self) -> Status:
        """Open, then wait for the object to settle."""
        arm = self.robot.arm
        assert arm is not None
        if self.until is None:
            held = arm.held
            arm.open()
            scratch = _scratch(self)
            if held is not None:
                self.let_go = _label(self, held)
                write_released(self, self.let_go)
                scratch.pop(HELD.key, None)
            grasp = GRASP.get(scratch)
            if grasp is not None:
                grasp.retry = True
            self.until = self.now() + (SETTLE if held is not None else 0.0)
        if self.now() < self.until:
            return self.running(f"letting {self.let_go} settle")
        return self.succeed(f"opened, let go of {self.let_go}" if self.let_go else "opened (the hand was empty)")


class ValidateGrip(WorldSkill):
    """Check by the finger force that the object is still held (at least ``min_force``).

    A slipped object (the hand is empty) makes ``handempty(self)`` and
    ``onground(object)`` hold again. Success ends the grasp count.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm."""
        super().setup(**kwargs)
        _has_arm(self)

    def initialise(self) -> None:
        """Check ``min_force``."""
        self.min_force = number_param(self, "min_force", 2.0, strict=False)

    def update(self) -> Status:
        """Read the finger force."""
        arm = self.robot.arm
        assert arm is not None
        scratch = _scratch(self)
        held = arm.held
        force = arm.grip_force()
        record = HELD.get(scratch)
        if held is None:
            if record is None:
                return self.fail(f"the gripper holds nothing (finger force {force:g} N)")
            name = record.object
            write_released(self, name)
            self.write(True, "onground", name)
            scratch.pop(HELD.key, None)
            return self.fail(
                f"{name} slipped out of the gripper (finger force {force:g} N, at least {self.min_force:g} N needed)"
            )
        name = _label(self, held)
        if force < self.min_force:
            return self.fail(f"the finger force on {name} is {force:g} N, below {self.min_force:g} N")
        scratch.pop(GRASP.key, None)
        scratch.pop(TRIED_SIDES.key, None)
        write_held(self, name)
        return self.succeed(f"holding {name} with {force:g} N")


class VerifyPlaced(WorldSkill):
    """Check that the gripper is empty and ``object`` lies on the ground at ``target``.

    The robot looks with its own camera (:func:`alica.skills.close_look.look_at`)
    where MoveArmToPlace set the object down (``scratch["placed"]``; else
    where the team saw it, ``pos(object)``; else the arm's place point straight
    ahead): the container it sees there, its bottom
    at the local ground, is the object. At a position it must lie within
    :data:`~alica.skills.handling.PLACE_TOLERANCE`; in an area such as the
    collection point ``pos(g)``, inside it; without a target, anywhere on the
    ground. On success ``onground(object)``, ``handempty(self)``,
    ``at(object, place)`` for a named place, and the object's new
    ``pos(object)`` (where the camera saw it) are written.
    """

    def setup(self, **kwargs: Any) -> None:
        """Find the robot; it needs an arm."""
        super().setup(**kwargs)
        _has_arm(self)

    def update(self) -> Status:
        """Check the gripper and where the object lies."""
        arm = self.robot.arm
        assert arm is not None
        name = str(self.param("object"))
        obj = find_object(self, self.param("object"))
        if arm.held is not None:
            return self.fail(f"the gripper still holds {_label(self, arm.held)}")
        holder = holders(self.team_model, self.team_belief).get(name)  # the team's holding facts
        if holder is not None and holder != self.robot.name:
            return self.fail(f"{name} is in the gripper of robot '{holder}'")
        placed = PLACED.get(_scratch(self))
        known = self.world_model.lookup("pos", (name,)) if self.world_model is not None else None
        if placed is not None and placed.object == name:
            where = placed.place
        elif isinstance(known, (tuple, list)) and len(known) >= 2:  # not put down by this robot: where the team saw it
            where = (float(known[0]), float(known[1]))
        else:  # the arm's place point straight ahead
            rx, ry, ryaw = self.robot.estimate
            ahead = REACH + (float(self.robot.arm.mount_offset[0]) if self.robot.arm is not None else 0.0)
            where = (rx + ahead * math.cos(ryaw), ry + ahead * math.sin(ryaw))
        size = float(obj.size) if obj.kind == "sample" else float(obj.size or 0.1)
        radius = float(obj.radius) if obj.radius else 0.5 * size
        seen = look_at(self.robot, where, size=size, radius=radius)
        if seen is None:
            return self.fail(f"the camera sees no {name} where it was put down ({where[0]:.2f}, {where[1]:.2f})")
        x, y = seen.xy
        bottom = seen.bottom - seen.ground - GROUND_CUT
        if bottom > ON_GROUND:
            return self.fail(f"{name} does not lie on the ground: its bottom is {bottom:.2f} m high")
        target = self.param("target")
        if target is not None:
            area = place_area(self, target)
            if area is not None:
                (tx, ty), tolerance = area[:2], area[2]
            else:
                (tx, ty), tolerance = self.resolve_position(target), PLACE_TOLERANCE
            off = math.hypot(x - tx, y - ty)
            if off > tolerance:
                return self.fail(
                    f"{name} lies at ({x:.2f}, {y:.2f}), {off:.2f} m from {target} at ({tx:.2f}, {ty:.2f}); "
                    f"at most {tolerance:g} m counts as placed there"
                )
        write_released(self, name)
        write_placed(self, name, obj, target)
        if self.world_model is not None:
            self.world_model.set("pos", name, value=(round(x, 3), round(y, 3)))
        return self.succeed(f"{name} lies at ({x:.2f}, {y:.2f})" + (f", at {target}" if target is not None else ""))
