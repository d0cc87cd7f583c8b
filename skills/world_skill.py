"""The base of skills that act on a world: the robot of the agent, positions, outcome facts.

A skill class is its own factory: the engine calls ``Skill(name, params,
context)``, then ``setup(context=...)``; ``context.world`` is a :class:`alica.worldsim.World`
(or a real robot interface with the same members) and
the robot is the one named like the agent. Skills see the world through the
robot interface (:mod:`alica.worldsim.interface`) and the context through
:class:`~alica.skills.context.SkillContextLike`. ``update`` only polls: planning runs
as a job (:mod:`alica.skills.jobs`).
"""

from __future__ import annotations

import math
import re
import weakref
from collections.abc import Iterator, Mapping
from typing import Any

import py_trees
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.context import SkillContextLike
from alica.skills.jobs import DeferredJobs, Jobs
from alica.skills.team_poses import BeliefLike, TeamPose, share_pose, teammates
from alica.worldmodel.protocol import WorldModelLike
from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing

_TERM = re.compile(r"^\s*(?:pos|pose)\s*\(\s*([A-Za-z_][A-Za-z0-9_\-]*)\s*\)\s*$")
#: Per-world caches (planning grids, arm scenes); entries go with their world.
_CACHES: weakref.WeakKeyDictionary[RobotWorld, dict[str, Any]] = weakref.WeakKeyDictionary()


def world_cache(world: RobotWorld) -> dict[str, Any]:
    """A dict that lives as long as ``world``, for things skills build once per world."""
    cache = _CACHES.get(world)
    if cache is None:
        cache = _CACHES[world] = {}
    return cache


class WorldSkill(py_trees.behaviour.Behaviour):
    """A skill acting through one robot of a world.

    Args:
        name: the behaviour's name.
        params: the skill's parameters (declared in :mod:`alica.skills.catalog`).
        context: the engine's :class:`~alica.engine.SkillContext` (any
            :class:`~alica.skills.context.SkillContextLike`).

    Attributes:
        world: the robot world (after :meth:`setup`).
        robot: the agent's robot in it (after :meth:`setup`; :attr:`has_robot` tells).
    """

    def __init__(self, name: str, params: Mapping[str, object], context: SkillContextLike | None = None) -> None:
        super().__init__(name)
        self.params = dict(params)
        self.context = context
        self._world: RobotWorld | None = None
        self._robot: MobileRobot | None = None
        self.jobs: Jobs = DeferredJobs()
        #: The team's world model for an inner skill that has none of its own (see :attr:`team_model`).
        self.team_source: WorldModelLike | None = None

    @property
    def world(self) -> RobotWorld:
        """The robot world.

        Raises:
            SkillError: the skill was not set up in a world.
        """
        if self._world is None:
            raise SkillError(f"skill '{self.name}' has no world: call setup(context=...) with a world first")
        return self._world

    @property
    def robot(self) -> MobileRobot:
        """The agent's robot.

        Raises:
            SkillError: the skill was not set up in a world.
        """
        if self._robot is None:
            raise SkillError(f"skill '{self.name}' has no robot: call setup(context=...) with a world first")
        return self._robot

    @property
    def has_robot(self) -> bool:
        """Whether :meth:`setup` found the agent's robot."""
        return self._robot is not None

    # -- life cycle -----------------------------------------------------------

    def setup(self, **kwargs: Any) -> None:
        """Find the world and the agent's robot.

        Raises:
            SkillError: there is no world, or no robot named like the agent.
        """
        context: SkillContextLike | None = kwargs.get("context", self.context)
        self.context = context
        world = context.world if context is not None else None
        if context is None or world is None:
            raise SkillError(
                f"skill '{self.name}' acts on a world, and this run has none (run it in a simulated world, e.g. 'alica skill run {type(self).__name__} --world lunar')"
            )
        if not isinstance(world, RobotWorld):
            raise SkillError(
                f"skill '{self.name}': {type(world).__name__} does not offer the robot interface (alica.worldsim.interface.RobotWorld)"
            )
        robots = world.robots
        if context.agent not in robots:
            raise SkillError(
                f"skill '{self.name}': the world has no robot named '{context.agent}' (robots: {', '.join(sorted(robots)) or 'none'})"
            )
        self._world = world
        self._robot = robots[context.agent]
        jobs = context.extra.get("jobs")
        self.jobs = jobs if isinstance(jobs, Jobs) else DeferredJobs()

    def tick(self) -> Iterator[py_trees.behaviour.Behaviour]:
        """Share the robot's pose with the team (throttled), then tick as py_trees does.

        Not the skill's behaviour (that is :meth:`update`): every world skill
        passes here on each tick, so a robot that runs any world skill tells its
        teammates where it believes it is (:func:`alica.skills.team_poses.share_pose`;
        at most about two writes a second).
        """
        if self._robot is not None and self._world is not None:
            share_pose(self.team_model, self._world, self._robot)
        yield from super().tick()

    def now(self) -> float:
        """Simulated (or wall) time of the run."""
        return float(self.context.now()) if self.context is not None else self.world.now()

    def fail(self, reason: str) -> Status:
        """End with FAILURE and say why (the engine reports ``feedback_message``)."""
        self.feedback_message = reason
        return Status.FAILURE

    def succeed(self, message: str = "") -> Status:
        """End with SUCCESS."""
        self.feedback_message = message
        return Status.SUCCESS

    def running(self, message: str) -> Status:
        """Keep RUNNING, saying what the skill is doing."""
        self.feedback_message = message
        return Status.RUNNING

    # -- helpers ---------------------------------------------------------------

    @property
    def world_model(self) -> WorldModelLike | None:
        """The agent's world-model replica, or None."""
        return self.context.world_model if self.context is not None else None

    @property
    def team_model(self) -> WorldModelLike | None:
        """The world model through which the robot shares its pose and reads its teammates'.

        :attr:`team_source` when set (an inner skill run without a world model
        of its own, so that it writes no facts, still hears its team), else
        :attr:`world_model`.
        """
        return self.team_source if self.team_source is not None else self.world_model

    def teammates(self) -> list[TeamPose]:
        """The poses the robot's teammates shared (:func:`alica.skills.team_poses.teammates`, with the agent's belief)."""
        return teammates(self.team_model, self.world, self.robot.name, belief=self.team_belief)

    @property
    def team_belief(self) -> BeliefLike | None:
        """The agent's belief (who is alive), or None outside an engine."""
        return self.context.belief if self.context is not None else None

    def write(self, positive: bool, pred: str, *args: object) -> None:
        """Write an outcome fact to the world model, when there is one."""
        wm = self.world_model
        if wm is None:
            return
        (wm.assert_fact if positive else wm.retract_fact)(pred, *args)

    def param(self, name: str, default: object = None) -> object:
        """A parameter, or ``default`` when it is not given."""
        value = self.params.get(name)
        return default if value is None else value

    def resolve_position(self, value: object) -> tuple[float, float]:
        """A goal as ``(x, y)``: a list of numbers, an object's name, or a term ``pos(name)``.

        A name is looked up as ``pos(name)`` in the world model first. Without
        it, what falls back to the world:

        * the skill's own robot: its pose *estimate* (what the robot knows of itself);
        * any object or robot of the world, when the world's layout counts as
          known: no world model, or one without a team map (the blocks world,
          a skill run alone, ``alica skill run``).

        In a mission that maps (the world model holds a team map's frame:
        :meth:`mapping_mission`), a name without ``pos(name)`` other than the
        robot's own is an error: where things are comes from perception and the
        mission's data, not from the simulator.

        Raises:
            SkillError: the value names nothing the skill can locate.
        """
        if isinstance(value, (tuple, list)) and len(value) >= 2 and all(isinstance(v, (int, float)) for v in value[:2]):
            return float(value[0]), float(value[1])
        if isinstance(value, str):
            match = _TERM.match(value)
            name = match.group(1) if match else value.strip()
            wm = self.world_model
            known = wm.lookup("pos", (name,)) if wm is not None else None
            if isinstance(known, (tuple, list)) and len(known) >= 2:
                return float(known[0]), float(known[1])
            if self._robot is not None and name == self._robot.name:
                x, y, _ = self._robot.estimate
                return float(x), float(y)
            if self.mapping_mission():
                raise SkillError(
                    f"skill '{self.name}': the world model has no pos({name}) (in a mission that maps, positions "
                    "come from perception)"
                )
            obj = self.world.objects.get(name)
            if obj is not None:
                position = obj.position()
                return float(position[0]), float(position[1])
            robot = self.world.robots.get(name)
            if robot is not None:
                x, y, _ = robot.pose
                return float(x), float(y)
        raise SkillError(
            f"skill '{self.name}': cannot tell where {value!r} is (give [x, y], an object's name or pos(name))"
        )

    def mapping_mission(self) -> bool:
        """Whether the skill's world model holds a team map (the robots map; the world's layout is not known)."""
        from alica.skills.mapping.sharing import team_resolution

        return team_resolution(self.world_model) is not None

    def object_named(self, value: object) -> WorldThing:
        """The world object called ``value``.

        Raises:
            SkillError: no such object.
        """
        objects = self.world.objects
        if not isinstance(value, str) or value not in objects:
            raise SkillError(
                f"skill '{self.name}': the world has no object {value!r} (objects: {', '.join(sorted(objects)) or 'none'})"
            )
        return objects[value]


def distance(a: tuple[float, float], b: tuple[float, float]) -> float:
    """Euclidean distance of two points."""
    return math.hypot(a[0] - b[0], a[1] - b[1])


def number_param(
    skill: WorldSkill, name: str, default: float | None, *, low: float = 0.0, strict: bool = True
) -> float:
    """The numeric parameter ``name`` of ``skill``: finite and above ``low`` (``strict``) or at least ``low``.

    Raises:
        SkillError: not a number, or out of range (the message names the parameter and the bound).
    """
    raw = skill.param(name, default)
    try:
        value = float(raw)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise SkillError(f"skill '{skill.name}': parameter '{name}' must be a number, got {raw!r}") from None
    if not math.isfinite(value) or (value <= low if strict else value < low):
        raise SkillError(
            f"skill '{skill.name}': parameter '{name}' must be {'>' if strict else '>='} {low:g}, got {raw!r}"
        )
    return value
