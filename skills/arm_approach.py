"""The approach phase of the arm skills: drive to a free side of the work site, at the arm's reach, facing it.

A free side (:meth:`Approach.free_side`) is a stand-off point no other robot
stands on or reserved (:mod:`alica.skills.reservations`), inside the field and
free for the robot's body; the nearest side first, then around the site. The
robot drives there with an inner :class:`~alica.skills.navigation.MoveToPosition`,
then turns to the site. When every side is taken it waits, up to
:data:`STANDOFF_WAIT`; when another robot stands on its stand-off point it takes
another side; a side from which the arm found no plan is not taken again.

The skill it serves (:class:`~alica.skills.handling.ArmSkill`) says how far to
stand (``standoff()``, ``approach_slack()``, ``approach_tolerance()``) and what
follows (``approached()``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from py_trees.common import Status

from alica.skills import reservations
from alica.skills.arm_world import inside_field
from alica.skills.navigation import MoveToPosition
from alica.skills.team_poses import teammate_discs
from alica.skills.world_skill import distance
from alica.worldsim.geometry import wrap_angle

if TYPE_CHECKING:
    from alica.skills.handling import ArmSkill

__all__ = ["STANDOFF_MARGIN", "STANDOFF_TRIES", "STANDOFF_WAIT", "Approach"]

#: Sides of a work site tried for the stand-off point (the nearest first).
STANDOFF_TRIES = 12
#: Room kept around the robot at its stand-off point, metres.
STANDOFF_MARGIN = 0.1
#: Simulated seconds a skill waits for a free side of its work site before it fails (the team then replans).
STANDOFF_WAIT = 30.0
#: A stand-off point this close (m) to one from which the arm found no plan counts as tried.
SIDE_TRIED = 0.2


class Approach:
    """The approach of one run of an arm skill: the drive, the reserved stand-off point, the sides tried.

    Attributes:
        mover: the drive to the stand-off point under way (None: none yet, or a new one is chosen).
        tried_sides: stand-off points from which the arm found no plan.
        reserved_xy: the stand-off point reserved for this robot (None: none).
    """

    def __init__(self, skill: ArmSkill) -> None:
        self.skill = skill
        self.mover: MoveToPosition | None = None
        self.blocked_since: float | None = None
        self.tried_sides: list[tuple[float, float]] = []
        self.goal_moves = 0
        self.reserved_xy: tuple[float, float] | None = None
        self.reserved_at = 0.0

    def tick(self) -> Status:
        """One step of the approach: choose a side, drive there, turn to the site."""
        skill = self.skill
        robot = skill.robot
        site = skill.site()
        x, y, yaw = robot.estimate  # the robot drives by its estimate (as MoveToPosition does)
        if self.mover is None:
            gap = distance((x, y), site)
            facing = abs(wrap_angle(math.atan2(site[1] - y, site[0] - x) - yaw))
            if abs(gap - skill.standoff()) <= skill.approach_slack() and facing < 0.15 and not self.side_tried((x, y)):
                self.reserve((float(x), float(y)))
                return skill.approached()
            goal = self.free_side(site)
            self.goal_moves = 0
            if goal is None:
                if self.blocked_since is None:
                    self.blocked_since = skill.now()
                elif skill.now() - self.blocked_since >= STANDOFF_WAIT:
                    return skill.fail(
                        f"every side of the work site {_xy_text(site)} was taken by other robots for {STANDOFF_WAIT:g} s"
                    )
                return skill.running("waiting: every side of the work site is taken by other robots")
            self.blocked_since = None
            self.mover = self._drive_to(goal)
        if self.mover.status != Status.SUCCESS:
            self.mover.tick_once()
            if self.mover.status == Status.FAILURE:
                return skill.fail(f"cannot get to {site}: {self.mover.feedback_message}")
            if self.mover.status == Status.RUNNING:
                if self._goal_taken() and self._switch_side(site):
                    return skill.running(
                        "approaching: another robot stands on the stand-off point, taking another side"
                    )
                return skill.running(f"approaching: {self.mover.feedback_message}")
        error = wrap_angle(math.atan2(site[1] - y, site[0] - x) - yaw)
        if abs(error) > 0.03:
            robot.drive(0.0, max(-robot.spec.max_yaw_rate, min(robot.spec.max_yaw_rate, 2.0 * error)))
            return skill.running("turning to the work site")
        robot.stop()
        return skill.approached()

    def again(self) -> None:
        """Choose the stand-off point anew on the next tick (after an inaccurate drive, or for another place)."""
        self.mover = None

    def avoid_here(self) -> None:
        """The arm found no plan from where the robot stands: take another side next."""
        pose = self.skill.robot.estimate
        self.tried_sides.append((float(pose[0]), float(pose[1])))
        self.mover = None

    def free_side(
        self, site: tuple[float, float], skip: tuple[float, float] | None = None
    ) -> tuple[float, float] | None:
        """A free point facing ``site`` at the arm's reach: the nearest side first, then around it.

        Points overlapping another robot, a point a teammate reserved
        (:mod:`alica.skills.reservations`) or an object (with a margin) are
        skipped, and so is ``skip`` (a side found taken); ``None`` when every
        side is taken (the skill waits and looks again).
        """
        from alica.skills.navigation import robot_checker

        skill = self.skill
        robot = skill.robot
        x, y, _ = robot.estimate
        standoff = skill.standoff()
        heading = math.atan2(site[1] - y, site[0] - x)
        others = teammate_discs(skill, margin=STANDOFF_MARGIN)  # the poses teammates shared
        others += [(rx, ry, rr + STANDOFF_MARGIN) for rx, ry, rr in reservations.reserved(skill)]
        # the motion planner's own check of a goal (static obstacles, blocks, other robots)
        checker = robot_checker(skill.world, robot, skill.world_model, skill.team_model, skill.team_belief)
        checker = checker.with_robots(others)
        for k in range(STANDOFF_TRIES):
            turn = ((k + 1) // 2) * (1 if k % 2 else -1) * (2.0 * math.pi / STANDOFF_TRIES)
            angle = heading + turn
            goal = (site[0] - standoff * math.cos(angle), site[1] - standoff * math.sin(angle))
            if self.side_tried(goal) or (skip is not None and distance(goal, skip) < SIDE_TRIED):
                continue
            if not inside_field(skill.world, goal, robot.spec.radius + STANDOFF_MARGIN):
                continue  # the robot's body would leave the field: it cannot stand there
            if distance(goal, (x, y)) < 0.05 or checker.valid_xy(goal[0], goal[1]):
                return goal
        return None

    def reserve(self, xy: tuple[float, float]) -> None:
        """Tell the teammates where this robot will stand to work (refreshed by :meth:`refresh`)."""
        reservations.reserve(self.skill, xy)
        self.reserved_xy = xy
        self.reserved_at = self.skill.now()

    def refresh(self) -> None:
        """Renew a held reservation now and then, before it expires."""
        if self.reserved_xy is not None and self.skill.now() - self.reserved_at >= reservations.REFRESH_PERIOD:
            self.reserve(self.reserved_xy)

    def end(self) -> None:
        """Stop the drive and give the reservation up (the skill ends or is stopped)."""
        if self.mover is not None and self.mover.status == Status.RUNNING:
            self.mover.stop(Status.INVALID)
        if self.reserved_xy is not None and self.skill.has_robot:
            reservations.release(self.skill)
            self.reserved_xy = None

    def side_tried(self, xy: tuple[float, float]) -> bool:
        """Whether the arm found no plan from a stand-off point this close to ``xy`` already."""
        return any(distance(xy, side) < SIDE_TRIED for side in self.tried_sides)

    def _goal_taken(self) -> bool:
        """Whether the drive waits for another robot to leave its stand-off point."""
        mover = self.mover
        return (
            mover is not None and mover.job is None and mover.follower is None and self.skill.now() < mover.wait_until
        )

    def _switch_side(self, site: tuple[float, float]) -> bool:
        """Drive to another free side of ``site`` instead of waiting for the robot on this one.

        The robot on the stand-off point may wait itself (for what this robot
        does next), or be crashed there. Up to :data:`STANDOFF_TRIES` switches.
        """
        mover = self.mover
        if mover is None or self.goal_moves >= STANDOFF_TRIES:
            return False
        current = (float(mover.goal[0]), float(mover.goal[1]))
        goal = self.free_side(site, skip=current)
        if goal is None:
            return False
        self.goal_moves += 1
        mover.stop(Status.INVALID)
        self.mover = self._drive_to(goal)
        self.mover.tick_once()
        return True

    def _drive_to(self, goal: tuple[float, float]) -> MoveToPosition:
        """The drive to the stand-off point ``goal``, which is reserved for this robot from now on."""
        skill = self.skill
        mover = MoveToPosition(
            f"{skill.name}/approach",
            {"goal": goal, "tolerance": skill.approach_tolerance(), "timeout": 60.0},
            skill.context,
        )
        mover.setup(context=skill.context)
        mover.team_source = skill.team_source  # an inner skill's approach hears the same team
        self.reserve(goal)
        return mover


def _xy_text(xy: tuple[float, float]) -> str:
    return f"({float(xy[0]):.2f}, {float(xy[1]):.2f})"
