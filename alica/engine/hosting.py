"""The engine's side of the child-runtime seam (:mod:`alica.engine.child`).

:class:`Children` attaches every child kind of the engine's configuration
when the engine is built, each with its own :class:`EngineHost` bound to the
topic the kind owns: the host is all a child runtime sees of the engine.
:class:`Children` then makes the runtime of every child of a configured type
and routes the messages of each kind's topic to its factory.

Neither holds the engine: they read the agent's shared context
(:class:`~alica.engine.parts.AgentContext`) and, for what a child runtime may
see beyond it, :class:`Operated` (the library, the generated plans, the world
model, the operator's settings and decisions, publishing on a topic), which
:class:`~alica.engine.agent.AgentEngine` satisfies.
"""

from __future__ import annotations

from collections.abc import Mapping, MutableMapping, Sequence
from typing import TYPE_CHECKING, Protocol

from alica.engine.child import (
    ChildFactory,
    ChildRuntime,
    PlanDecision,
    RunningPlan,
    WorldFacts,
    missing_kind_message,
    reachable_elements,
)
from alica.engine.generated import GeneratedPlans
from alica.engine.node import PlanNode
from alica.engine.parts import AgentContext
from alica.errors import AlicaError
from alica.lang.fact import Fact
from alica.model import Behaviour, Plan, PlanLibrary, PlanType, Priority, RoleSet
from alica.worldmodel import WorldModelLike

if TYPE_CHECKING:
    from alica.engine.slot import Slot

_NONE: Mapping[str, str] = {}


class Operated(Protocol):
    """What a child runtime's host reads of the agent beyond the shared context (the engine satisfies it)."""

    @property
    def library(self) -> PlanLibrary:
        """The plan library."""
        ...

    @property
    def generated(self) -> GeneratedPlans:
        """The plans child runtimes generated, with the team's base role set."""
        ...

    @property
    def world_model(self) -> WorldModelLike:
        """The agent's world model."""
        ...

    @property
    def overrides(self) -> Mapping[str, Mapping[str, str]]:
        """Element -> what the operator set for it (``goal``, ``world``)."""
        ...

    @property
    def decisions(self) -> Mapping[str, Sequence[tuple[int, PlanDecision]]]:
        """Element -> the operator's decisions on its proposed plans, ``(generation, decision)``, oldest first."""
        ...

    def publish(self, topic: str, payload: object) -> None:
        """Send a message to the team on ``topic`` (reliably)."""
        ...


class _World:
    """The agent's world model as :class:`WorldFacts`: its facts as :class:`Fact` values."""

    __slots__ = ("_model",)

    def __init__(self, model: WorldModelLike) -> None:
        self._model = model

    def facts(self) -> list[Fact]:
        return [Fact.of(f) for f in self._model.facts()]

    def holds(self, predicate: str, *args: object) -> bool:
        return bool(self._model.holds(predicate, *args))

    def types(self) -> list[str]:
        return list(self._model.types())

    def objects(self, type_name: str) -> tuple[object, ...]:
        return tuple(self._model.objects(type_name))

    def values(self) -> list[tuple[str, tuple[object, ...], object]]:
        return list(self._model.values())

    def assert_fact(self, predicate: str, *args: object) -> object:
        return self._model.assert_fact(predicate, *args)

    def retract_fact(self, predicate: str, *args: object) -> object:
        return self._model.retract_fact(predicate, *args)


class EngineHost:
    """An agent's engine as the host of one kind of child runtime (a :class:`~alica.engine.child.ChildHost`).

    Args:
        ctx: the agent's name, clock, settings, formulas, belief, counters and trace.
        agent: the rest of what a child runtime may see of the agent.
        topic: the team topic the kind owns (``None``: it may not publish).
    """

    def __init__(self, ctx: AgentContext, agent: Operated, topic: str | None) -> None:
        self._ctx = ctx
        self._agent = agent
        self._topic = topic
        self._world = _World(agent.world_model)

    @property
    def name(self) -> str:
        return self._ctx.name

    def now(self) -> float:
        return self._ctx.now()

    @property
    def library(self) -> PlanLibrary:
        return self._agent.library

    @property
    def roleset(self) -> RoleSet:
        return self._agent.generated.base

    @property
    def roles(self) -> Mapping[str, str]:
        return self._ctx.team.roles

    @property
    def world(self) -> WorldFacts:
        return self._world

    @property
    def counters(self) -> MutableMapping[str, int]:
        return self._ctx.stats

    def holds(self, formula: str, plan: RunningPlan) -> bool:
        if not isinstance(plan, PlanNode):
            raise TypeError(f"not a plan this engine runs: {plan!r}")
        ctx = self._ctx
        return ctx.formulas.holds(formula, ctx.belief.at(plan), plan.env)

    def override(self, element: str) -> Mapping[str, str]:
        return self._agent.overrides.get(element, _NONE)

    @property
    def review(self) -> bool:
        return self._ctx.config.review

    def decisions(self, element: str) -> Sequence[tuple[int, PlanDecision]]:
        return self._agent.decisions.get(element, ())

    def emit(self, event: str, **fields: object) -> None:
        self._ctx.emit(event, **fields)

    def publish(self, payload: object) -> None:
        if self._topic is None:
            raise AlicaError("this child kind owns no topic to publish on: give it a 'topic'")
        self._agent.publish(self._topic, payload)

    def register_plan(
        self,
        plan: Plan,
        priorities: Mapping[str, tuple[Priority, ...]],
        pins: Mapping[str, tuple[str, ...]],
    ) -> None:
        self._agent.generated.register(plan, priorities, pins)

    def unregister_plan(self, name: str) -> None:
        self._agent.generated.unregister(name)


class Children:
    """The child kinds attached to one agent's engine: per configured element type a factory with its host.

    Args:
        ctx: the agent's shared context; its configuration names the kinds (``EngineConfig.children``).
        agent: what the kinds' hosts read of the agent beyond ``ctx``.
        root: the name of the agent's root plan.

    Raises:
        AlicaError: the agent's plan tree reaches an element no kind is configured for.
    """

    def __init__(self, ctx: AgentContext, agent: Operated, root: str) -> None:
        self._factories: list[tuple[type, ChildFactory]] = []
        self.routes: dict[str, ChildFactory] = {}
        """Topic -> the factory its messages go to."""
        for element_type, kind in ctx.config.children.items():
            topic = kind.topic
            factory = kind(EngineHost(ctx, agent, topic))
            self._factories.append((element_type, factory))
            if topic is not None:
                self.routes[topic] = factory
        self.check(agent.library, root)

    def check(self, library: PlanLibrary, root: str) -> None:
        """Whether every element the plan tree of ``root`` reaches in ``library`` can run here.

        Raises:
            AlicaError: an element no child kind is configured for (named, with where it is).
        """
        for where, element in reachable_elements(library, root):
            if not isinstance(element, (Behaviour, Plan, PlanType)) and self.factory(type(element)) is None:
                raise AlicaError(missing_kind_message(element, where))

    def factory(self, element_type: type) -> ChildFactory | None:
        """The factory of child runtimes for elements of ``element_type`` (``None``: none configured)."""
        return next((f for t, f in self._factories if issubclass(element_type, t)), None)

    def runtime(self, slot: Slot) -> ChildRuntime:
        """The runtime of a child that is neither a behaviour, a plan nor a plan type (a planning problem).

        Raises:
            AlicaError: no child kind is configured for the child's element type.
        """
        factory = self.factory(type(slot.element))
        if factory is None:
            parent = slot.parent
            raise AlicaError(missing_kind_message(slot.element, f"state '{parent.state}' of plan '{parent.plan.name}'"))
        return factory(slot)
