"""The engine's side of the child-runtime seam (:mod:`alica.engine.child`).

:class:`Children` attaches every child kind of the engine's configuration
when the engine is built, each with its own :class:`EngineHost` bound to the
topic the kind owns: the host is all a child runtime sees of the engine.
:class:`Children` then makes the runtime of every child of a configured type
and routes the messages of each kind's topic to its factory.
"""

from __future__ import annotations

from collections.abc import Mapping, MutableMapping, Sequence
from typing import TYPE_CHECKING, Any

from alica.engine.child import (
    ChildFactory,
    ChildRuntime,
    PlanDecision,
    RunningPlan,
    WorldFacts,
    missing_kind_message,
    reachable_elements,
)
from alica.engine.node import PlanNode
from alica.errors import AlicaError
from alica.lang.fact import Fact
from alica.model import Behaviour, Plan, PlanLibrary, PlanType, Priority, RoleSet

if TYPE_CHECKING:
    from alica.engine.agent import AgentEngine
    from alica.engine.slot import Slot

_NONE: Mapping[str, str] = {}


class _World:
    """The agent's world model as :class:`WorldFacts`: its facts as :class:`Fact` values."""

    __slots__ = ("_model",)

    def __init__(self, model: Any) -> None:
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
        engine: the agent's engine.
        topic: the team topic the kind owns (``None``: it may not publish).
    """

    def __init__(self, engine: AgentEngine, topic: str | None) -> None:
        self._engine = engine
        self._topic = topic
        self._world = _World(engine.world_model)

    @property
    def name(self) -> str:
        return self._engine.name

    def now(self) -> float:
        return self._engine.now()

    @property
    def library(self) -> PlanLibrary:
        return self._engine.library

    @property
    def roleset(self) -> RoleSet:
        return self._engine.base_roleset

    @property
    def world(self) -> WorldFacts:
        return self._world

    @property
    def counters(self) -> MutableMapping[str, int]:
        return self._engine.stats

    def holds(self, formula: str, plan: RunningPlan) -> bool:
        if not isinstance(plan, PlanNode):
            raise TypeError(f"not a plan this engine runs: {plan!r}")
        engine = self._engine
        return engine.formulas.holds(formula, engine.belief_for(plan), plan.env)

    def override(self, element: str) -> Mapping[str, str]:
        return self._engine.overrides.get(element, _NONE)

    @property
    def review(self) -> bool:
        return self._engine.config.review

    def decisions(self, element: str) -> Sequence[tuple[int, PlanDecision]]:
        return self._engine.decisions.get(element, ())

    def emit(self, event: str, **fields: Any) -> None:
        self._engine.emit(event, **fields)

    def publish(self, payload: object) -> None:
        if self._topic is None:
            raise AlicaError("this child kind owns no topic to publish on: give it a 'topic'")
        self._engine.publish(self._topic, payload)

    def register_plan(
        self,
        plan: Plan,
        priorities: Mapping[str, tuple[Priority, ...]],
        pins: Mapping[str, tuple[str, ...]],
    ) -> None:
        self._engine.generated.register(plan, priorities, pins)

    def unregister_plan(self, name: str) -> None:
        self._engine.generated.unregister(name)


class Children:
    """The child kinds attached to one agent's engine: per configured element type a factory with its host.

    Args:
        engine: the agent's engine; its configuration names the kinds (``EngineConfig.children``).

    Raises:
        AlicaError: the engine's plan tree reaches an element no kind is configured for.
    """

    def __init__(self, engine: AgentEngine) -> None:
        self._factories: list[tuple[type, ChildFactory]] = []
        self.routes: dict[str, ChildFactory] = {}
        """Topic -> the factory its messages go to."""
        for element_type, kind in engine.config.children.items():
            topic = kind.topic
            factory = kind(EngineHost(engine, topic))
            self._factories.append((element_type, factory))
            if topic is not None:
                self.routes[topic] = factory
        for where, element in reachable_elements(engine.library, engine.root_plan.name):
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
