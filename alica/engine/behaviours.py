"""Behaviours of states: a registered skill, built as a py_trees behaviour and driven by the engine.

A skill implementation is a *factory* ``(name, params, context) -> py_trees
behaviour`` (a py_trees ``Behaviour`` subclass taking ``(name, params,
context)`` works too). The engine calls ``setup(context=...)`` once, ticks it
with ``tick_once()`` while the agent is in the state (py_trees runs
``initialise`` on the first tick) and stops it with ``stop(INVALID)`` (py_trees
runs ``terminate``) when the state is left. Long work must happen off the
tick; ``update`` only polls.
"""

from __future__ import annotations

import logging
import random
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import py_trees

from alica.engine.status import ChildStatus
from alica.errors import AlicaError, UnknownSkillError
from alica.lang import BeliefBase
from alica.model import Behaviour
from alica.worldmodel import WorldModelLike

if TYPE_CHECKING:
    from alica.engine.belief import AgentBelief
    from alica.engine.conditions import Formulas
    from alica.engine.parts import SolveResult
    from alica.lang.skills import SkillRegistry

logger = logging.getLogger(__name__)

_STATUS = {
    py_trees.common.Status.RUNNING: ChildStatus.RUNNING,
    py_trees.common.Status.SUCCESS: ChildStatus.SUCCESS,
    py_trees.common.Status.FAILURE: ChildStatus.FAILURE,
}


@dataclass(slots=True)
class SkillContext:
    """What a skill receives: the agent it runs on and the agent's view of the world.

    Args:
        agent: the agent's name.
        now: a function giving the current (simulated) time.
        world_model: the agent's replica of the shared world model; write outcome facts here.
        belief: the agent's whole belief base (read-only use).
        rng: a random generator seeded from the run's seed and the agent.
        world: the simulated or real robot interface, when there is one.
        behaviour: the model behaviour being run.
        path: where it runs, ``Plan/State/Behaviour`` from the root.
        extra: run options for skills (e.g. ``optimize_time``).
        solver: the engine's constraint query for this behaviour (see :meth:`solve`).
        scratch: the agent's scratch space, shared by all its behaviours, never sent to the
            team: a pipeline of skills in consecutive states hands its data on here.
    """

    agent: str
    now: Callable[[], float]
    world_model: WorldModelLike | None
    belief: AgentBelief | None
    rng: random.Random
    world: object | None = None
    behaviour: Behaviour | None = None
    path: str = ""
    extra: dict[str, object] = field(default_factory=dict)
    solver: Callable[[tuple[str, ...]], SolveResult] | None = None
    scratch: dict[str, object] = field(default_factory=dict)

    def solve(self, *names: str) -> SolveResult:
        """The values the constraint solver gives the behaviour's variables ``names`` now.

        Returns:
            A :class:`alica.engine.parts.SolveResult`: ``status`` (``solved``,
            ``infeasible``, ``timeout``), ``values`` (this agent's, by variable
            name), ``team`` (every agent's), ``utility`` and ``reason``. No
            solution is a status, never an exception.

        Raises:
            AlicaError: the skill runs outside an engine (no plan to take constraints from).
        """
        if self.solver is None:
            raise AlicaError(f"'{self.path or self.agent}' runs outside an engine: there are no constraints to solve")
        return self.solver(tuple(names))


SkillFactory = Callable[[str, Mapping[str, object], SkillContext], py_trees.behaviour.Behaviour]


class SkillBinder:
    """Finds the factory for a behaviour.

    Lookup order: ``overrides`` by behaviour name, then by skill name; the
    skill registry's implementation; then ``fallback`` (e.g. scripted test
    doubles); else :class:`~alica.errors.UnknownSkillError`, whose message
    says how to bind an implementation. A skill declared in a plan file's
    ``skills:`` section (which the loader adds to the registry it was given)
    has no implementation, so it is built by ``fallback`` or not at all, like
    a Python declaration without one.

    Args:
        overrides: factories by behaviour or skill name.
        registry: a :class:`alica.lang.skills.SkillRegistry`; ``None`` skips it.
        fallback: a function ``behaviour -> factory`` for skills with no implementation.
    """

    def __init__(
        self,
        overrides: Mapping[str, SkillFactory] | None = None,
        registry: SkillRegistry | None = None,
        fallback: Callable[[Behaviour], SkillFactory] | None = None,
    ) -> None:
        self.overrides = dict(overrides or {})
        self.registry = registry
        self.fallback = fallback
        self._cache: dict[str, SkillFactory] = {}

    def forget(self, names: Iterable[str]) -> None:
        """Bind the behaviours ``names`` again when they next start (their skill may have changed: a hot reload)."""
        for name in names:
            self._cache.pop(name, None)

    def factory(self, behaviour: Behaviour) -> SkillFactory:
        """The factory that builds ``behaviour``.

        Raises:
            UnknownSkillError: nothing implements the skill.
        """
        hit = self._cache.get(behaviour.name)
        if hit is not None:
            return hit
        found = self.overrides.get(behaviour.name) or self.overrides.get(behaviour.skill)
        reason = ""
        if found is None and self.registry is not None and behaviour.skill in self.registry:
            try:
                found = self.registry.load(behaviour.skill)
            except UnknownSkillError as exc:
                reason = str(exc)
        if found is None and self.fallback is not None:
            found = self.fallback(behaviour)
        if found is None:
            why = reason or (
                f"skill '{behaviour.skill}' has no implementation; bind one with --skills MODULE, a module whose "
                f"register(registry) declares '{behaviour.skill}' with an implementation, "
                "or run scripted stand-ins with --stand-ins"
            )
            raise UnknownSkillError(f"behaviour '{behaviour.name}' cannot run: {why}")
        self._cache[behaviour.name] = found
        return found


class BehaviourRunner:
    """One behaviour in the agent's current state.

    Args:
        model: the behaviour of the plan library.
        params: its parameters with ``$variables`` bound.
        factory: builds the py_trees behaviour.
        context: handed to the skill.
    """

    __slots__ = ("_next_tick", "_period", "bt", "context", "factory", "model", "params", "reason", "status")

    def __init__(
        self, model: Behaviour, params: Mapping[str, object], factory: SkillFactory, context: SkillContext
    ) -> None:
        self.model = model
        self.params = dict(params)
        self.factory = factory
        self.context = context
        self.status = ChildStatus.WAITING
        self.reason = ""
        self.bt: py_trees.behaviour.Behaviour | None = None
        self._next_tick = 0.0
        self._period = 1.0 / model.frequency if model.frequency > 0 else 0.0

    def tick(self, belief: BeliefBase, formulas: Formulas, env: Mapping[str, object], now: float) -> ChildStatus:
        """Start the behaviour when its pre-condition holds, then tick it; returns its status."""
        if self.status.done:
            return self.status
        model = self.model
        if self.bt is None:
            if model.pre is not None and not formulas.holds(model.pre.text, belief, env):
                return self.status
            if not self._start():
                return self.status
        if model.run is not None and not formulas.holds(model.run.text, belief, env):
            self._finish(ChildStatus.FAILURE, f"run-time condition '{model.run.text}' no longer holds")
            return self.status
        if self._period and now < self._next_tick:
            return self.status
        self._next_tick = now + self._period
        bt = self.bt
        assert bt is not None
        try:
            bt.tick_once()
        except Exception as exc:
            self._finish(
                ChildStatus.FAILURE, f"exception in '{self.context.path}' [{model.skill}]: {type(exc).__name__}: {exc}"
            )
            return self.status
        self.status = _STATUS.get(bt.status, ChildStatus.RUNNING)
        if self.status is ChildStatus.FAILURE:
            self.reason = bt.feedback_message or f"skill '{model.skill}' failed"
        return self.status

    @property
    def feedback(self) -> str:
        """What the running skill says of its progress (its py_trees ``feedback_message``, e.g. ``0.00 m to go``).

        Empty when the skill has not started, has ended, or says nothing.
        """
        bt = self.bt
        if bt is None or self.status is not ChildStatus.RUNNING:
            return ""
        return str(bt.feedback_message or "")

    def _start(self) -> bool:
        try:
            bt = self.factory(self.model.name, self.params, self.context)
            bt.setup(context=self.context)
        except AlicaError as exc:
            self._finish(ChildStatus.FAILURE, str(exc))
            return False
        except Exception as exc:
            self._finish(
                ChildStatus.FAILURE,
                f"cannot start '{self.context.path}' [{self.model.skill}]: {type(exc).__name__}: {exc}",
            )
            return False
        self.bt = bt
        self.status = ChildStatus.RUNNING
        return True

    def _finish(self, status: ChildStatus, reason: str) -> None:
        self.stop()
        self.status = status
        self.reason = reason

    def stop(self) -> None:
        """Stop the py_trees behaviour if it is running (its ``terminate`` runs)."""
        bt = self.bt
        if bt is not None and bt.status == py_trees.common.Status.RUNNING:
            try:
                bt.stop(py_trees.common.Status.INVALID)
            except Exception as exc:
                logger.warning("terminate of '%s' raised %s: %s", self.context.path, type(exc).__name__, exc)
