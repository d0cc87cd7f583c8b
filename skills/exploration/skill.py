"""ExploreFrontier: drive to frontiers until no frontier with gain is left (IMPERA Fig. 7, Eq. 7-8).

Every ``period`` simulated seconds the skill reads the map
(:func:`alica.skills.exploration.maps.current_map`), extracts the frontier
candidates with their information gain (Algorithm 1,
:func:`alica.skills.exploration.frontiers.extract_frontiers`) and publishes
them to the team's world model: objects of type ``Frontier`` with ``Pos(f) =
(x, y)`` and ``gain(f)`` (with a time to live), plus ``Pos(robot)``, so the
constraints of ``plans/skills/explore.yaml`` (Eq. 7-8) can assign one
frontier to each robot. Frontiers it published earlier that are gone are
retracted (``Pos`` and ``gain`` removed; the world model's object sets only
grow, so a retracted frontier stays listed but no constraint can pick it).

The robot drives with an inner :class:`~alica.skills.navigation.MoveToPosition`
to its frontier. It reads the team's solution (``context.solve("frontier")``:
the plan's constraints, Eq. 7-8, and utilities) when it needs a frontier: at
the start, and when its frontier is reached, unreachable or gone. With
``reassign: true`` it also reads it at every reading of the map while it
drives and follows when the solution moves it (the team reassigns every
robot periodically); it then writes ``Targets(robot, frontier)`` while it
drives to a frontier, which the plan's KeepFrontier utility reads: that is
the hysteresis, a robot is moved only when that raises the team's gain over
travel by more than the bonus (:mod:`alica.skills.exploration.assign`,
:func:`~alica.skills.exploration.assign.decide`); the Explore plan's
DriveToFrontier sets it. Without it (the skill's default) no ``Targets``
fact is written and KeepFrontier adds nothing. A ``frontier``
parameter (bound by a plan) names the first one. When the constraints have
no solution, or give a frontier within ``spacing`` of one another robot
heads for (with ``reassign``: and keeps heading for), a robot with a
frontier keeps it and one without takes the best remaining one itself: gain
over distance, more than ``spacing`` from the frontiers the other robots
head for (``heading(robot) = (x, y)`` in the world model, written with a
time to live while a robot drives to a frontier). With no frontier of gain
left it writes ``explored`` and succeeds.

Positions are the robot's pose *estimate* (odometry corrected by Localize),
never the true pose.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.context import SkillContextLike
from alica.skills.exploration.assign import TARGETS, How, decide, proposal_of
from alica.skills.exploration.frontiers import FrontierCandidate, extract_frontiers
from alica.skills.exploration.maps import current_map
from alica.skills.world_skill import WorldSkill
from alica.worldmodel import WorldModelLike

__all__ = ["HEADING", "ExploreFrontier", "heading_of", "publish_frontiers"]

#: Seconds a published frontier (and the robot's Pos) lives in the world model without being written again.
PUBLISH_TTL = 10.0
#: Seconds a frontier the robot could not reach is left out of its own choice.
UNREACHABLE_FOR = 30.0
#: Failed drives after which a frontier is given up for good (it lies among rocks, say).
GIVE_UP_AFTER = 2
#: Metres beyond the robot's radius a frontier cell keeps from occupied cells to be a candidate.
CLEARANCE_MARGIN = 0.1
#: Seconds MoveToPosition may take to one frontier.
DRIVE_TIMEOUT = 30.0
#: Scratch key: the names of the frontiers this agent published last.
PUBLISHED_KEY = "exploration_published"
#: World-model function: where a robot is heading (its frontier's position), for the others' own choice.
HEADING = "heading"


def publish_frontiers(
    wm: WorldModelLike,
    scratch: dict[str, object],
    candidates: list[FrontierCandidate],
    robot: str,
    position: tuple[float, float],
) -> None:
    """Write frontier candidates to the team's world model and retract the ones published before that are gone.

    ``Frontier`` objects with ``Pos(f)`` and ``gain(f)`` (time to live
    :data:`PUBLISH_TTL`), and ``Pos(robot)`` for Eq. 8. What this agent
    published is remembered in its ``scratch`` (key :data:`PUBLISHED_KEY`).
    BuildMap may call it too, so that the first frontiers are known before
    ExploreFrontier starts (its variable needs a candidate).
    """

    put = _putter(wm)
    put("Pos", robot, (round(position[0], 3), round(position[1], 3)))
    fresh = set()
    for cand in candidates:
        wm.add_object(cand.name, "Frontier")
        put("Pos", cand.name, (round(cand.position[0], 3), round(cand.position[1], 3)))
        put("gain", cand.name, cand.gain)
        fresh.add(cand.name)
    before = scratch.get(PUBLISHED_KEY)
    for name in sorted(before if isinstance(before, set) else set()):
        if name not in fresh:  # stale: retract it
            wm.set("Pos", name, value=None)
            wm.set("gain", name, value=None)
    scratch[PUBLISHED_KEY] = fresh


def _putter(wm: WorldModelLike) -> Callable[[str, str, object], None]:
    def put(name: str, arg: str, value: object) -> None:
        try:
            wm.set(name, arg, value=value, ttl=PUBLISH_TTL)
        except ValueError:  # a world model without a clock takes no time to live
            wm.set(name, arg, value=value)

    return put


def heading_of(wm: Any, but: str) -> dict[str, tuple[float, float]]:
    """Robot -> where it is heading now (``heading(robot)`` in the world model), for the robots other than ``but``."""
    if wm is None:
        return {}
    out = {}
    for name, args, value in wm.values():
        if name == HEADING and args and args[0] != but and isinstance(value, (tuple, list)) and len(value) == 2:
            out[str(args[0])] = (float(value[0]), float(value[1]))
    return out


class ExploreFrontier(WorldSkill):
    """Explore frontier by frontier; see the module docstring.

    Parameters (see :mod:`alica.skills.catalog`): ``frontier`` (a ``Frontier``
    object name, optional), ``spacing`` (m, Eq. 7), ``reach`` (m, wave-front
    range of Algorithm 1), ``min_gain`` (m²), ``period`` (s), ``tolerance`` (m), ``reassign`` (bool).

    Attributes:
        candidates: the frontier candidates of the last update, best first.
        visited: the frontiers the robot drove to, in order.
        solved: how many of them the team's solution gave (switches included).
        fallbacks: how many it chose itself (no solution, or another robot heads there).
        switches: how many times the team's solution moved it from the frontier it drove to.
    """

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name, params, context)
        self.candidates: list[FrontierCandidate] = []
        self.visited: list[str] = []
        self._check_params()

    # -- parameters -------------------------------------------------------------

    def _number(self, name: str, default: float, *, positive: bool = True) -> float:
        value = self.param(name, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SkillError(f"skill '{self.name}': parameter '{name}' must be a number, got {value!r}")
        if positive and not value > 0.0:
            raise SkillError(f"skill '{self.name}': parameter '{name}' must be > 0, got {value!r}")
        if not positive and value < 0.0:
            raise SkillError(f"skill '{self.name}': parameter '{name}' must be >= 0, got {value!r}")
        return float(value)

    def _check_params(self) -> None:
        frontier = self.params.get("frontier")
        if frontier is not None and (not isinstance(frontier, str) or not frontier.strip()):
            raise SkillError(
                f"skill '{self.name}': parameter 'frontier' must name a Frontier object (e.g. f_3_4), got {frontier!r}"
            )
        self.bound = frontier.strip() if isinstance(frontier, str) else None
        self.spacing = self._number("spacing", 4.0, positive=False)
        reassign = self.param("reassign", False)
        if not isinstance(reassign, bool):
            raise SkillError(f"skill '{self.name}': parameter 'reassign' must be true or false, got {reassign!r}")
        self.reassign = reassign
        self.reach = self._number("reach", 3.0)
        self.min_gain = self._number("min_gain", 1.0, positive=False)
        self.period = self._number("period", 1.0)
        self.tolerance = self._number("tolerance", 0.5)

    # -- life cycle -------------------------------------------------------------

    def initialise(self) -> None:
        """Start: the first update reads the map at once."""
        self.inner: Any = None
        self.target: FrontierCandidate | None = None
        self.next_update = -math.inf
        self.unreachable: dict[str, float] = {}
        self.failed_drives: dict[str, int] = {}
        self.first = True
        self.solved = 0
        self.fallbacks = 0
        self.switches = 0
        self.targeted: str | None = None  # the frontier of the Targets fact this robot wrote

    def update(self) -> Status:
        """Read the map and publish frontiers when due, pick a frontier, drive to it."""
        now = self.now()
        if now >= self.next_update:
            self.next_update = now + self.period
            self._refresh()
            if not self.candidates or all(self.unreachable.get(c.name) == math.inf for c in self.candidates):
                given_up = len(self.candidates)
                self._stop_inner()
                self.robot.stop()
                if given_up:  # nobody is to drive to them any more
                    self.candidates = []
                    self._publish()
                self.write(True, "explored")
                if given_up:
                    return self.succeed(
                        f"explored: {given_up} frontier(s) left that the robot reached without seeing beyond, "
                        f"or failed to reach {GIVE_UP_AFTER} times"
                    )
                return self.succeed("explored: no frontier with gain is left")
            if self.target is not None and self.target.name not in self._by_name():
                self._stop_inner()  # seen while driving there (or no longer a frontier)
                self.target = None
            elif self.target is not None and self.reassign:
                self._reconsider(now)  # the team reassigns every robot periodically
        if self.target is None:
            target = self._choose(now)
            if target is None:
                self._head(None)
                self.robot.stop()
                return self.running(f"waiting: every one of {len(self.candidates)} frontiers is taken or unreachable")
            self._take(target)
        target = self.target
        assert target is not None
        self.inner.tick_once()
        status = self.inner.status
        if status == Status.RUNNING:
            return self.running(
                f"to frontier {target.name} at ({target.position[0]:.1f}, {target.position[1]:.1f}), "
                f"gain {target.gain:.1f} m²; {len(self.candidates)} frontiers"
            )
        if status == Status.FAILURE:
            failures = self.failed_drives[target.name] = self.failed_drives.get(target.name, 0) + 1
            self.unreachable[target.name] = now + UNREACHABLE_FOR if failures < GIVE_UP_AFTER else math.inf
        else:  # reached: should it still be a frontier at the next reading, it is not one to drive to again
            self.unreachable[target.name] = math.inf
        self.inner = None
        self.target = None
        self._claim(None)
        self.next_update = now  # read the map from where the robot stands now
        return self.running("frontier reached" if status == Status.SUCCESS else "frontier unreachable")

    def terminate(self, new_status: Status) -> None:
        """Stop the drive and the base; head nowhere."""
        self._stop_inner()
        if self.has_robot:
            self.robot.stop()
            self._head(None)
            self._claim(None)

    # -- map and world model ----------------------------------------------------

    def _by_name(self) -> dict[str, FrontierCandidate]:
        return {c.name: c for c in self.candidates}

    def _refresh(self) -> None:
        assert self.context is not None
        view = current_map(self.context, self.robot, self.world.bounds)
        self.candidates = extract_frontiers(
            view.occupancy(),
            view.resolution,
            view.origin,
            reach=self.reach,
            min_gain=self.min_gain,
            clearance=self.robot.spec.radius + CLEARANCE_MARGIN,
        )
        self._publish()

    def _publish(self) -> None:
        wm = self.world_model
        if wm is None or self.context is None:
            return
        x, y, _ = self.robot.estimate
        publish_frontiers(wm, self.context.scratch, self.candidates, self.robot.name, (float(x), float(y)))
        if self.target is not None:
            self._head(self.target.position)  # keep it alive
            self._claim(self.target.name)

    def _head(self, goal: tuple[float, float] | None) -> None:
        """Tell the team where this robot heads (``None``: nowhere)."""
        wm = self.world_model
        if wm is None:
            return
        if goal is None:
            if wm.get(HEADING, self.robot.name) is not None:
                wm.set(HEADING, self.robot.name, value=None)
            return
        _putter(wm)(HEADING, self.robot.name, (round(goal[0], 3), round(goal[1], 3)))

    def _claim(self, frontier: str | None) -> None:
        """``Targets(robot, frontier)`` for the plan's KeepFrontier (``None``: no frontier), the one before retracted."""
        wm = self.world_model
        if wm is None or not self.reassign:
            return
        robot = self.robot.name
        if self.targeted is not None and self.targeted != frontier:
            wm.set(TARGETS, robot, self.targeted, value=None)
        self.targeted = frontier
        if frontier is None:
            return
        try:
            wm.set(TARGETS, robot, frontier, value=True, ttl=PUBLISH_TTL)
        except ValueError:  # a world model without a clock takes no time to live
            wm.set(TARGETS, robot, frontier, value=True)

    # -- choosing ---------------------------------------------------------------

    def _usable(self, now: float) -> dict[str, FrontierCandidate]:
        return {n: c for n, c in self._by_name().items() if self.unreachable.get(n, -math.inf) <= now}

    def _here(self) -> tuple[float, float]:
        x, y, _ = self.robot.estimate
        return (float(x), float(y))

    def _proposal(self) -> dict[str, str]:
        """The team's solution, robot -> frontier (empty without one: alone, no engine, or no solution)."""
        context = self.context
        if context is None or context.solver is None:  # alone, no engine: no constraints
            return {}
        result = context.solve("frontier")
        if not result.ok:
            return {}
        # every robot's values: the engine's SolveResult.team (SolveAnswer, the skills' view of it, names only values)
        team = getattr(result, "team", None)
        proposal = proposal_of(team) if isinstance(team, Mapping) else {}
        mine = result.values.get("frontier")
        if isinstance(mine, str):
            proposal[self.robot.name] = mine
        return proposal

    def _choose(self, now: float) -> FrontierCandidate | None:
        usable = self._usable(now)
        if not usable:
            return None
        # 1. the frontier the plan bound (once: after it, the team's current solution)
        if self.first:
            self.first = False
            if self.bound is not None and self.bound in usable:
                return usable[self.bound]
        # 2. the team's assignment (Eq. 7-8), unless another robot heads (and keeps heading) there;
        # 3. else its own choice: gain over distance, away from where the others head (Eq. 7)
        heading = heading_of(self.world_model, self.robot.name)
        choice = decide(
            self.robot.name,
            self._here(),
            None,
            self._by_name(),
            usable,
            self._proposal(),
            heading,
            spacing=self.spacing,
            others_follow=self.reassign,
        )
        if choice.how is How.SOLVED:
            self.solved += 1
        elif choice.how is How.FALLBACK:
            self.fallbacks += 1
        return choice.frontier

    def _reconsider(self, now: float) -> None:
        """Follow the team's solution when it moves this robot to another frontier (hysteresis: the plan's KeepFrontier)."""
        if self.target is None or self.context is None or self.context.solver is None:
            return
        usable = self._usable(now)
        heading = heading_of(self.world_model, self.robot.name)
        choice = decide(
            self.robot.name,
            self._here(),
            self.target,
            self._by_name(),
            usable,
            self._proposal(),
            heading,
            spacing=self.spacing,
        )
        if choice.how is How.SWITCHED and choice.frontier is not None:
            self._stop_inner()
            self.switches += 1
            self.solved += 1
            self._take(choice.frontier)

    def _take(self, target: FrontierCandidate) -> None:
        """Drive to ``target`` from now on."""
        self.target = target
        self.visited.append(target.name)
        self._head(target.position)
        self._claim(target.name)
        self.inner = self._drive(target.position)

    def _drive(self, goal: tuple[float, float]) -> Any:
        from alica.skills.context import SkillEnv
        from alica.skills.navigation import MoveToPosition

        assert self.context is not None
        context = SkillEnv.without_world_model(self.context)
        inner = MoveToPosition(
            f"{self.name}/drive",
            {"goal": [goal[0], goal[1]], "tolerance": self.tolerance, "timeout": DRIVE_TIMEOUT},
            context,
        )
        inner.map_model = self.world_model  # it plans on the team map, though it writes no facts
        inner.team_source = self.world_model  # and shares its pose with the team, and avoids its teammates
        inner.setup(context=context)
        return inner

    def _stop_inner(self) -> None:
        if self.inner is not None and self.inner.status == Status.RUNNING:
            self.inner.stop(Status.INVALID)
        self.inner = None
