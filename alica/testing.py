"""Test doubles for users' and our own tests: scripted skills and a simulated clock.

Example::

    from alica.testing import ScriptedSkill, scripted
    team = SimulatedTeam(library, "Mission", {"r1": "Scout"},
                         skills={"DriveTo": scripted(["running", "running", "success"])})
    team.run(ticks=10)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import py_trees
from py_trees.common import Status

from alica.clock import ManualClock
from alica.errors import AlicaError
from alica.lang import literals
from alica.lang.skills import SkillRegistry
from alica.model import Behaviour
from alica.worldmodel import WorldModelLike

__all__ = ["ManualClock", "ScriptedSkill", "TimedSkill", "default_fallback", "scripted"]

_STATUS = {"running": Status.RUNNING, "success": Status.SUCCESS, "failure": Status.FAILURE}
#: A change a scripted skill writes on success: ``(positive, predicate, args)`` (assert when positive, else retract).
FactChange = tuple[bool, str, tuple[object, ...]]


def _status(value: str | Status) -> Status:
    if isinstance(value, Status):
        return value
    try:
        return _STATUS[value.lower()]
    except KeyError:
        raise ValueError(f"unknown status '{value}' in a script (use running, success or failure)") from None


class _Context(Protocol):
    """What the stand-ins use of the engine's skill context (:class:`alica.engine.behaviours.SkillContext`)."""

    @property
    def agent(self) -> str: ...

    @property
    def world_model(self) -> WorldModelLike | None: ...

    def now(self) -> float: ...


def _write(context: _Context | None, facts: Sequence[FactChange]) -> None:
    world = context.world_model if context is not None else None
    if world is None or context is None:
        return
    me = context.agent
    for positive, name, args in facts:
        args = tuple(me if a == "self" else a for a in args)
        if positive:
            world.assert_fact(name, *args)
        else:
            world.retract_fact(name, *args)


class ScriptedSkill(py_trees.behaviour.Behaviour):
    """A behaviour that returns a fixed sequence of statuses, one per tick.

    Args:
        name: the behaviour's name.
        script: statuses for the 1st, 2nd, ... tick after each start; the last repeats.
        facts: ``(positive, predicate, args)`` written to the world model on success
            (``self`` in args is the agent).

    Attributes:
        starts: how often ``initialise`` ran; ``stops``: how often ``terminate`` ran;
        ticks: updates since the last start.
    """

    def __init__(
        self, name: str, script: Sequence[str | Status] = ("success",), facts: Sequence[FactChange] = ()
    ) -> None:
        super().__init__(name)
        if not script:
            raise ValueError("a script needs at least one status")
        self.script = [_status(s) for s in script]
        self.facts = tuple(facts)
        self.context: _Context | None = None
        self.starts = 0
        self.stops = 0
        self.ticks = 0

    def setup(self, **kwargs: Any) -> None:
        """Keep the engine's skill context."""
        self.context = kwargs.get("context")

    def initialise(self) -> None:
        """Start the script from its first status."""
        self.starts += 1
        self.ticks = 0

    def update(self) -> Status:
        """The next status of the script."""
        status = self.script[min(self.ticks, len(self.script) - 1)]
        self.ticks += 1
        if status is Status.SUCCESS:
            _write(self.context, self.facts)
        return status

    def terminate(self, new_status: Status) -> None:
        """Count stops (the engine stops a running behaviour when its state is left)."""
        self.stops += 1


class TimedSkill(py_trees.behaviour.Behaviour):
    """A behaviour that runs for a simulated duration, then ends with an outcome.

    Args:
        name: the behaviour's name.
        duration: seconds of simulated time until it ends; ``None`` runs forever.
        outcome: ``success`` or ``failure``.
        facts: written to the world model on success, as for :class:`ScriptedSkill`.
    """

    def __init__(
        self, name: str, duration: float | None, outcome: str = "success", facts: Sequence[FactChange] = ()
    ) -> None:
        super().__init__(name)
        self.duration = duration
        self.outcome = _status(outcome)
        self.facts = tuple(facts)
        self.context: _Context | None = None
        self.started = 0.0

    def setup(self, **kwargs: Any) -> None:
        """Keep the engine's skill context (its clock is used)."""
        self.context = kwargs.get("context")

    def initialise(self) -> None:
        """Remember the start time."""
        self.started = self.context.now() if self.context is not None else 0.0

    def update(self) -> Status:
        """Running until the duration passed, then the outcome."""
        if self.duration is None or self.context is None or self.context.now() - self.started < self.duration:
            return Status.RUNNING
        if self.outcome is Status.SUCCESS:
            _write(self.context, self.facts)
        return self.outcome


class scripted:
    """A skill factory making :class:`ScriptedSkill` behaviours; keeps every instance it made.

    Args:
        script: as for :class:`ScriptedSkill`.
        facts: as for :class:`ScriptedSkill`.
    """

    def __init__(self, script: Sequence[str | Status] = ("success",), facts: Sequence[FactChange] = ()) -> None:
        self.script = list(script)
        self.facts = tuple(facts)
        self.instances: list[ScriptedSkill] = []

    def __call__(self, name: str, params: Mapping[str, object], context: Any) -> ScriptedSkill:
        skill = ScriptedSkill(name, self.script, self.facts)
        self.instances.append(skill)
        return skill


def post_facts(behaviour: Behaviour) -> tuple[FactChange, ...]:
    """The post-condition of a behaviour as facts to write, when it is a conjunction of ground literals."""
    if behaviour.post is None:
        return ()
    try:
        found = literals(behaviour.post.text)
    except AlicaError:
        return ()
    return tuple((positive, name, tuple(args)) for positive, name, args in found if name != "=")


#: Skills that wait in place until their state is left (when their duration is 0 or not given).
IDLE_SKILLS = frozenset({"Idle"})
#: Parameter names a stand-in reads as how long it runs, in simulated seconds.
DURATION_PARAMS = ("duration", "seconds", "wait")


def _duration(params: Mapping[str, object]) -> float | None:
    """The first positive duration-like parameter (``duration``, ``seconds``, ``wait``, ``*_duration``)."""
    names = [n for n in DURATION_PARAMS if n in params] + sorted(n for n in params if n.endswith("_duration"))
    for name in names:
        value = params[name]
        if isinstance(value, (int, float)) and not isinstance(value, bool) and value > 0:
            return float(value)
    return None


def default_fallback(seed: int = 0, low: float = 0.5, high: float = 2.0, registry: SkillRegistry | None = None) -> Any:
    """Scripted stand-ins for skills that have no implementation, for dry runs of plans.

    A stand-in honours the skill's parameters, with the defaults ``registry``
    declares: it runs for its duration-like parameter (see :data:`DURATION_PARAMS`)
    when that is positive; else ``Idle`` runs until its state is left and
    every other skill for a time drawn from ``[low, high]`` seconds (fixed per
    behaviour and seed). Then it succeeds and writes its post-condition's
    literals to the world model (``Idle`` writes none).

    Args:
        seed: seeds the drawn times.
        low: shortest drawn time in seconds.
        high: longest drawn time in seconds.
        registry: skill declarations whose parameter defaults the stand-ins use.
    """
    import random

    def fallback(behaviour: Behaviour) -> Any:
        spec = registry.get(behaviour.skill) if registry is not None and behaviour.skill in registry else None
        defaults = {p.name: p.default for p in spec.params if not p.required} if spec is not None else {}

        def factory(name: str, params: Mapping[str, object], context: Any) -> TimedSkill:
            duration = _duration({**defaults, **params})
            if behaviour.skill in IDLE_SKILLS:
                return TimedSkill(name, duration)
            if duration is None:
                duration = round(random.Random(f"{seed}:{behaviour.name}").uniform(low, high), 3)
            return TimedSkill(name, duration, "success", post_facts(behaviour))

        return factory

    return fallback
