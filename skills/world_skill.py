"""The base of skills that act on a world: the robot of the agent, positions, outcome facts.

A skill class is its own factory: the engine calls ``Skill(name, params,
context)``, then ``setup(context=...)``; ``context.world`` is a
:class:`worldsim.World` (or a real robot interface with the same methods) and
the robot is the one named like the agent. ``update`` only polls: planning runs
as a job (:mod:`alica.skills.jobs`).
"""

from __future__ import annotations

import math
import re
import weakref
from collections.abc import Mapping
from typing import Any

import py_trees
from py_trees.common import Status

from alica.errors import SkillError
from alica.skills.jobs import DeferredJobs, Jobs

_TERM = re.compile(r"^\s*(?:pos|pose)\s*\(\s*([A-Za-z_][A-Za-z0-9_\-]*)\s*\)\s*$")
#: Per-world caches (planning grids, arm scenes); entries go with their world.
_CACHES: weakref.WeakKeyDictionary[Any, dict[str, Any]] = weakref.WeakKeyDictionary()


def world_cache(world: Any) -> dict[str, Any]:
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
        context: the engine's :class:`~alica.engine.SkillContext` (or any object with
            ``agent``, ``world``, ``world_model``, ``now`` and ``rng``).
    """

    def __init__(self, name: str, params: Mapping[str, object], context: Any = None) -> None:
        super().__init__(name)
        self.params = dict(params)
        self.context = context
        self.world: Any = None
        self.robot: Any = None
        self.jobs: Jobs = DeferredJobs()

    # -- life cycle -----------------------------------------------------------

    def setup(self, **kwargs: Any) -> None:
        """Find the world and the agent's robot.

        Raises:
            SkillError: there is no world, or no robot named like the agent.
        """
        context = kwargs.get("context", self.context)
        self.context = context
        world = getattr(context, "world", None)
        if world is None:
            raise SkillError(
                f"skill '{self.name}' acts on a world, and this run has none (run it in a simulated world, e.g. 'alica skill run {type(self).__name__} --world lunar')"
            )
        agent = getattr(context, "agent", None)
        robots = getattr(world, "robots", {})
        if agent not in robots:
            raise SkillError(
                f"skill '{self.name}': the world has no robot named '{agent}' (robots: {', '.join(sorted(robots)) or 'none'})"
            )
        self.world = world
        self.robot = robots[agent]
        extra = getattr(context, "extra", None) or {}
        self.jobs = extra.get("jobs") or DeferredJobs()

    def now(self) -> float:
        """Simulated (or wall) time of the run."""
        return float(self.context.now()) if self.context is not None else float(self.world.now())

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
    def world_model(self) -> Any:
        """The agent's world-model replica, or None."""
        return getattr(self.context, "world_model", None)

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

        Raises:
            SkillError: the value names nothing in the world.
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
            thing = self.world.objects.get(name) or self.world.robots.get(name)
            if thing is not None:
                if hasattr(thing, "position"):
                    position = thing.position()
                    return float(position[0]), float(position[1])
                x, y, _ = thing.pose
                return float(x), float(y)
        raise SkillError(
            f"skill '{self.name}': cannot tell where {value!r} is (give [x, y], an object's name or pos(name))"
        )

    def object_named(self, value: object) -> Any:
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
