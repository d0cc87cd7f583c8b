"""The engine's seam for child runtimes: what decides which plan runs under a state, and what the engine offers it.

A state's child is usually a behaviour, a plan or a plan type, and the engine
knows how to run each. A child may also be a model element whose plans are
only known at run time, such as a planning problem: then a **child runtime**
decides, tick by tick, which plan the child runs. The engine defines the
interface here and never imports an implementation (pRoPhEt MAS,
:mod:`alica.prophet`, is one); an application plugs implementations in
through :attr:`EngineConfig.children <alica.engine.config.EngineConfig>`,
keyed by model element type::

    from alica.model import PlanningProblem
    from alica.prophet import PLANNING

    config = EngineConfig(frequency=10.0, children={PlanningProblem: PLANNING})
    # or: alica.prophet.engine_config(frequency=10.0)

Design of the seam:

* **Three parts, three lifetimes.** A :class:`ChildKind` is given once per
  team (shared by every agent's engine); the engine attaches it when it is
  built, handing it a :class:`ChildHost`, and gets back that agent's
  :class:`ChildFactory` (one per engine and kind: where per-agent state lives,
  such as the plans a team shared). The factory makes a :class:`ChildRuntime`
  for every :class:`ChildSlot` that holds an element of its kind, when the
  agent enters the state; the runtime is stopped when the agent leaves it.
  So a factory is ``(host, slot) -> ChildRuntime`` with the host bound once.
* **The runtime decides, the engine executes.** Every visit of the slot, the
  engine calls :meth:`ChildRuntime.update`, runs (and allocates, through its
  normal rules) the plans :meth:`ChildRuntime.wanted` names, restarts the
  child when :attr:`ChildRuntime.revision` changes, and ends it with
  :meth:`ChildRuntime.outcome`. A failure of a plan the runtime made
  (:meth:`ChildRuntime.is_generated`) goes to
  :meth:`ChildRuntime.execution_failed` instead of the generic repair, and
  :meth:`ChildRuntime.may_retry_in` says whether the failure of a plan inside
  one of its plans may be retried (slot.py's repair stages).
* **A narrow host, not the engine.** A runtime sees the engine only through
  :class:`ChildHost`: the agent's name and time, the plan library and role
  set, formulas evaluated in a running plan's context, the world model as
  :class:`WorldFacts`, trace events, counters, operator settings and
  decisions on reviewed plans (:class:`PlanDecision`), team
  messages on the topic its kind owns, and the registration of the plans it
  generates (with their task priorities and pinned entry points, so that
  allocation can use them). It sees its slot as a :class:`ChildSlot` and the
  plan running there as a :class:`RunningPlan`: read-only views.
* **Typed messages on an owned topic.** A kind names its :attr:`ChildKind.topic`;
  the engine subscribes to it, sends what the runtime publishes through
  :meth:`ChildHost.publish` reliably, and hands every message received on it
  to :meth:`ChildFactory.receive`, also while no runtime of the kind exists
  (an agent entering the state late still finds the latest plan). The kind
  checks the payloads' types.
* **No silent fallback.** A plan tree that reaches an element no kind is
  configured for is an error when the engine is built, saying how to plug one
  in (:func:`missing_kind_message`).
* **No meaning in names.** What a runtime needs to know about the plans it
  generates (for pRoPhEt MAS: which task and step each state is) it keeps
  itself, from when it made them; the engine hands it plans and states, and
  a runtime never parses them.

The engine's side is :mod:`alica.engine.hosting` (``Children``: the attached
kinds of one engine, ``engine.children``; ``EngineHost``: the host);
:class:`~alica.engine.slot.Slot` is the :class:`ChildSlot` and
:class:`~alica.engine.node.PlanNode` the :class:`RunningPlan`. Only this
module (which re-exports what it uses of :mod:`alica.engine.status` and
:mod:`alica.engine.team`) and :mod:`alica.engine.config` are the engine's
public interface for child runtimes: an import-linter contract keeps
:mod:`alica.prophet` from importing the engine's internals.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, MutableMapping, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

from alica.engine.status import ChildStatus
from alica.engine.team import PlanKey, key_text
from alica.lang.fact import Fact
from alica.model import Plan, PlanLibrary, PlanningProblem, Priority, RoleSet
from alica.model.library import AbstractPlan

__all__ = [
    "ChildFactory",
    "ChildHost",
    "ChildKind",
    "ChildRuntime",
    "ChildSlot",
    "ChildStatus",
    "PlanDecision",
    "PlanKey",
    "RunningPlan",
    "WorldFacts",
    "key_text",
    "missing_kind_message",
    "reachable_elements",
]

#: An agent's entry point and state in a plan, as it believes them (``None``: idle).
Entry = tuple[str | None, str | None]

#: What the operator does with a plan proposed for review.
DecisionAction = Literal["accept", "decline", "modify"]


@dataclass(frozen=True, slots=True)
class PlanDecision:
    """The operator's decision on a plan a child runtime proposed for review (``EngineConfig.review``).

    Attributes:
        action: ``accept`` (run the plan as proposed), ``decline`` (plan again) or ``modify``
            (run the plan changed by ``order`` and ``pins``, if it is still valid).
        order: with ``modify``, the proposed plan's step indices to keep, in their new order
            (dropping and reordering steps); ``None`` keeps the steps as they are.
        pins: with ``modify``, task -> the only agent that may take it; a task is named by its
            entry point or by its index (``"0"``) in the plan as modified.

    Raises:
        ValueError: an unknown action, or an order or pins given with another action than ``modify``.
    """

    action: DecisionAction
    order: tuple[int, ...] | None = None
    pins: Mapping[str, str] = field(default_factory=dict, hash=False)

    def __post_init__(self) -> None:
        if self.action not in ("accept", "decline", "modify"):
            raise ValueError(f"a plan decision is 'accept', 'decline' or 'modify', not {self.action!r}")
        if self.action != "modify" and (self.order is not None or self.pins):
            raise ValueError(f"only 'modify' changes the order or the pins of a plan, not {self.action!r}")
        if self.order is not None:
            object.__setattr__(self, "order", tuple(int(i) for i in self.order))
        object.__setattr__(self, "pins", {str(task): str(agent) for task, agent in dict(self.pins).items()})

    def describe(self) -> dict[str, object]:
        """The decision as plain data (for a trace event)."""
        out: dict[str, object] = {"action": self.action}
        if self.order is not None:
            out["order"] = list(self.order)
        if self.pins:
            out["pins"] = dict(self.pins)
        return out


class RunningPlan(Protocol):
    """A plan instance as this agent runs it (the engine's plan node, read-only)."""

    @property
    def plan(self) -> Plan:
        """The plan."""

    @property
    def ep(self) -> str | None:
        """This agent's entry point (``None``: idle)."""

    @property
    def state(self) -> str | None:
        """This agent's state (``None``: idle)."""

    @property
    def status(self) -> ChildStatus:
        """Running, succeeded or failed."""

    @property
    def reason(self) -> str:
        """Why it failed."""

    @property
    def believed(self) -> Mapping[str, Entry]:
        """Every agent in the plan -> its entry point and state, as this agent believes them."""

    @property
    def succeeded(self) -> Mapping[str, AbstractSet[str]]:
        """Entry point -> the agents whose task succeeded there."""


class ChildSlot(Protocol):
    """The child of a state that a child runtime decides for (the engine's slot, read-only)."""

    @property
    def key(self) -> PlanKey:
        """The child's instance in the team: the same for every agent in the same state."""

    @property
    def name(self) -> str:
        """The child's name, as the state lists it."""

    @property
    def element(self) -> object:
        """The model element: a :class:`~alica.model.PlanningProblem` for pRoPhEt MAS."""

    @property
    def node(self) -> RunningPlan | None:
        """The plan the child runs now, if any."""

    @property
    def entry_task(self) -> str:
        """The task of this agent's entry point in the plan that holds the state (``""``: idle)."""

    def members(self) -> tuple[str, ...]:
        """The alive agents believed to be in the state that holds the child, sorted (this agent included)."""


class WorldFacts(Protocol):
    """The agent's replica of the shared world model, as a child runtime reads and writes it."""

    def facts(self) -> list[Fact]:
        """Every fact that holds."""

    def holds(self, predicate: str, *args: object) -> bool:
        """Whether one fact holds (without listing them all)."""

    def types(self) -> list[str]:
        """The types of the typed objects it knows."""

    def objects(self, type_name: str) -> tuple[object, ...]:
        """The objects of a type."""

    def values(self) -> list[tuple[str, tuple[object, ...], object]]:
        """The function values (not truth values) as ``(name, args, value)``: ``pos(x)``, say."""

    def assert_fact(self, predicate: str, *args: object) -> object:
        """Make a fact hold, for the whole team."""

    def retract_fact(self, predicate: str, *args: object) -> object:
        """Make a fact not hold, for the whole team."""


class ChildHost(Protocol):
    """What an agent's engine offers the child runtimes of one kind (and nothing more)."""

    @property
    def name(self) -> str:
        """The agent's name (its id in the team)."""

    def now(self) -> float:
        """The current (simulated) time."""

    @property
    def library(self) -> PlanLibrary:
        """The plan library."""

    @property
    def roleset(self) -> RoleSet:
        """The team's role set, without the priorities of generated plans."""

    @property
    def roles(self) -> Mapping[str, str]:
        """Every team member's role, by name."""

    @property
    def world(self) -> WorldFacts:
        """The agent's replica of the shared world model."""

    @property
    def counters(self) -> MutableMapping[str, int]:
        """The agent's counters (``replans``, ...), reported in the run's summary."""

    def holds(self, formula: str, plan: RunningPlan) -> bool:
        """Whether ``formula`` holds for this agent in the context of the running ``plan``."""

    def override(self, element: str) -> Mapping[str, str]:
        """What the operator set for the model element ``element`` (e.g. ``goal``, ``world``)."""

    @property
    def review(self) -> bool:
        """Whether the operator reviews every plan a runtime would run before it runs (``EngineConfig.review``)."""

    def decisions(self, element: str) -> Sequence[tuple[int, PlanDecision]]:
        """The operator's decisions on the plans proposed for the model element ``element``, oldest first.

        Each is ``(generation, decision)``: the generation of the proposal it decides.
        """

    def emit(self, event: str, **fields: Any) -> None:
        """Send a trace event."""

    def publish(self, payload: object) -> None:
        """Send a message to the team on the kind's topic (reliably)."""

    def register_plan(
        self,
        plan: Plan,
        priorities: Mapping[str, tuple[Priority, ...]],
        pins: Mapping[str, tuple[str, ...]],
    ) -> None:
        """Make a generated plan allocatable.

        Args:
            plan: the plan.
            priorities: role -> the priorities of the plan's tasks for that role.
            pins: entry point -> the only agents that may take it (others are vetoed).
        """

    def unregister_plan(self, name: str) -> None:
        """Forget a generated plan."""


class ChildRuntime(Protocol):
    """Decides what one child runs (see the module docstring for when the engine calls what)."""

    @property
    def revision(self) -> int:
        """Changes whenever the plan to run changes: the engine then restarts the child."""

    @property
    def reason(self) -> str:
        """Why the child ended, or why the plan changed."""

    def wanted(self) -> tuple[Plan, ...]:
        """The plans the child may run now, in preference order (none when it is finished)."""

    def bindings(self) -> Mapping[str, object]:
        """Values for the wanted plans' variables, on top of the child's own bindings (say, what a WaitPlan guards).

        Read when the child starts a plan; a runtime that wants other values bumps its :attr:`revision`.
        """

    def outcome(self) -> ChildStatus | None:
        """The child's status when it no longer depends on a running plan (``None``: it does)."""

    def child_status(self, node: RunningPlan) -> ChildStatus:
        """The child's status while ``node`` (one of the wanted plans) runs and has not failed."""

    def is_generated(self, plan: Plan) -> bool:
        """Whether ``plan`` is a plan this runtime made (its failure goes to :meth:`execution_failed`)."""

    def may_retry_in(self, plan: Plan) -> bool:
        """Whether a plan that failed inside ``plan`` (one this runtime runs) may be retried before it is replaced."""

    def execution_failed(self, node: RunningPlan, now: float) -> None:
        """A generated plan failed here (the engine stopped it and restarts the child)."""

    def update(self, now: float) -> None:
        """Once per visit of the child, before anything else."""

    def stop(self) -> None:
        """The agent leaves the state."""


class ChildFactory(Protocol):
    """One agent's maker of child runtimes of one kind; made by :class:`ChildKind` with the agent's host."""

    def __call__(self, slot: ChildSlot) -> ChildRuntime:
        """The runtime of ``slot``'s child (the agent enters the state)."""

    def receive(self, payload: object, now: float) -> None:
        """A team message on the kind's topic arrived."""


class ChildKind(Protocol):
    """Plugs one kind of child runtime into every engine of a team (``EngineConfig.children``)."""

    @property
    def topic(self) -> str | None:
        """The team topic the kind's runtimes own (``None``: they send nothing)."""

    def __call__(self, host: ChildHost) -> ChildFactory:
        """Attach to one agent's engine: its factory of runtimes."""


class ChildKinds(Protocol):
    """An agent's engine as a plug-in sees it from outside: the child runtime kinds it was configured with.

    :class:`~alica.engine.AgentEngine` satisfies it; a plug-in reads its own state through the factory
    it made for the agent (pRoPhEt MAS: the plans it generated).
    """

    def child_kind(self, element_type: type) -> ChildFactory | None:
        """The agent's factory of child runtimes for elements of ``element_type`` (``None``: none configured)."""
        ...


def missing_kind_message(element: AbstractPlan, where: str) -> str:
    """The error for a child whose element type has no :class:`ChildKind` configured; ``where`` holds it."""
    kind = type(element).__name__
    name = element.name
    if isinstance(element, PlanningProblem):
        how = (
            "plug pRoPhEt MAS in: EngineConfig(children={PlanningProblem: alica.prophet.PLANNING}), "
            "or build the config with alica.prophet.engine_config(...)"
        )
    else:
        how = f"give EngineConfig(children={{{kind}: ...}}) a child kind for it"
    return f"{where} holds the {kind} '{name}', but the engine has no child runtime for a {kind}: {how}"


def reachable_elements(library: PlanLibrary, root: str) -> Iterator[tuple[str, AbstractPlan]]:
    """Every element a plan tree reaches from the plan ``root``, once each, with where it is first met."""
    seen = {root}
    todo: list[tuple[str, AbstractPlan]] = [(f"plan '{root}'", library.plans[root])]
    while todo:
        where, element = todo.pop(0)
        yield where, element
        for name in library.children(element):
            if name not in seen:
                seen.add(name)
                todo.append((f"'{element.name}'", library.abstract(name)))
