"""Plans: state machines for a team, with entry points, transitions and utility."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from alica.model.common import (
    UNBOUNDED,
    Condition,
    Constraint,
    StateKind,
    Variable,
    find_named,
    format_cardinality,
    span_field,
)
from alica.source import SourceSpan


@dataclass(frozen=True, slots=True)
class Binding:
    """Binds a variable of a child (plan or behaviour) to a term of the parent."""

    variable: str
    value: str
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class ChildRef:
    """A behaviour, plan, plan type or planning problem run inside a state.

    Names are unique across all four kinds, so a name alone identifies the child.
    """

    name: str
    bindings: tuple[Binding, ...] = ()
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<ChildRef {self.name}>"


@dataclass(frozen=True, slots=True)
class State:
    """A step of a plan. Its children run in parallel while an agent is in it.

    Args:
        name: unique within the plan.
        kind: normal, success or failure.
        children: behaviours, plans, plan types and planning problems.
        post: for terminal states, the condition that holds on arrival.
    """

    name: str
    kind: StateKind = StateKind.NORMAL
    children: tuple[ChildRef, ...] = ()
    post: Condition | None = None
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<State {self.name} {self.kind.value}>"

    @property
    def terminal(self) -> bool:
        """Success and failure states are terminal."""
        return self.kind.terminal


@dataclass(frozen=True, slots=True)
class Transition:
    """A move from one state to another when a condition holds.

    Args:
        name: unique within the plan (``Source->Target`` when not written).
        source: the state it leaves.
        target: the state it enters.
        condition: the guard; ``None`` means always true.
        synchronisation: name of the synchronisation it belongs to, if any.
    """

    name: str
    source: str
    target: str
    condition: Condition | None = None
    synchronisation: str | None = None
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<Transition {self.source}->{self.target}>"


@dataclass(frozen=True, slots=True)
class Synchronisation:
    """Transitions of different agents that must fire together.

    Args:
        name: unique within the plan.
        transitions: names of the synchronised transitions.
        talk_timeout: seconds before readiness messages are resent.
        sync_timeout: seconds after which the synchronisation gives up.
        fail_on_timeout: whether giving up fails the plan.
    """

    name: str
    transitions: tuple[str, ...]
    talk_timeout: float = 0.03
    sync_timeout: float = 10.0
    fail_on_timeout: bool = False
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class EntryPoint:
    """Where agents committing to a task enter a plan.

    Args:
        name: unique within the plan; defaults to the task's name.
        task: the task agents take by entering here.
        state: the initial state (``None`` only in invalid documents).
        min: minimum number of agents.
        max: maximum number of agents (``UNBOUNDED`` for no limit).
        success_required: whether the plan needs this task to succeed.
    """

    name: str
    task: str
    state: str | None
    min: int = 0
    max: float = UNBOUNDED
    success_required: bool = False
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<EntryPoint {self.name} task={self.task} [{self.min}..{format_cardinality(self.max)}]>"


@dataclass(frozen=True, slots=True)
class Summand:
    """A domain-specific term of a utility function: a numeric formula in [0, 1]."""

    name: str
    weight: float
    expression: str
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class UtilityFunction:
    """U(p) of IMPERA Definition 6.3, with ALICA's similarity term and threshold.

    Args:
        priority_weight: w0, the weight of the role-task priority term.
        summands: the weighted domain terms f_i.
        similarity_weight: weight of keeping the current assignment.
        threshold: the gain a new assignment must exceed to replace the current one.

    The weights must sum to 1.
    """

    priority_weight: float = 1.0
    summands: tuple[Summand, ...] = ()
    similarity_weight: float = 0.0
    threshold: float = 0.1
    span: SourceSpan | None = span_field()

    @property
    def weight_sum(self) -> float:
        """Sum of all weights; 1 in a valid plan."""
        return self.priority_weight + self.similarity_weight + sum(s.weight for s in self.summands)


@dataclass(frozen=True, slots=True)
class PlanningSignature:
    """How a skill plan looks to the planner (IMPERA Section 8.1 pseudo-PDDL).

    Args:
        parameters: typed parameters, e.g. ``?r - robot``.
        precondition: a formula over the parameters.
        effect: a conjunction of literals over the parameters.
        cost: the action's cost.
        duration: how long the skill is expected to take, seconds (``None``: not declared). A temporal
            planner (``planner: temporal``) plans with it for the team's time, the makespan.
    """

    parameters: tuple[Variable, ...] = ()
    precondition: Condition | None = None
    effect: Condition | None = None
    cost: float = 1.0
    duration: float | None = None
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class Plan:
    """A multi-agent plan: one state machine per task, entered through entry points."""

    name: str
    entry_points: tuple[EntryPoint, ...]
    states: tuple[State, ...]
    transitions: tuple[Transition, ...] = ()
    synchronisations: tuple[Synchronisation, ...] = ()
    variables: tuple[Variable, ...] = ()
    pre: Condition | None = None
    run: Condition | None = None
    utility: UtilityFunction = UtilityFunction()
    constraints: tuple[Constraint, ...] = ()
    signature: PlanningSignature | None = None
    frequency: float = 0.0
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<Plan {self.name}>"

    def state(self, name: str) -> State:
        """The state called ``name``.

        Raises:
            KeyError: no such state.
        """
        return find_named(self.states, name, f"plan '{self.name}'", "state")

    def entry_point(self, name: str) -> EntryPoint:
        """The entry point called ``name`` (by default its task's name).

        Raises:
            KeyError: no such entry point.
        """
        return find_named(self.entry_points, name, f"plan '{self.name}'", "entry point")

    def out_transitions(self, state: str) -> tuple[Transition, ...]:
        """Transitions leaving ``state``, in declaration order."""
        return tuple(t for t in self.transitions if t.source == state)

    @property
    def min_cardinality(self) -> int:
        """Agents needed to start the plan: the sum of the entry points' minima."""
        return sum(ep.min for ep in self.entry_points)

    @property
    def max_cardinality(self) -> float:
        """Agents the plan can use: the sum of the entry points' maxima."""
        return sum(ep.max for ep in self.entry_points)

    def succeeded(self, successes: Mapping[str, int]) -> bool:
        """Plan success: each success-required entry point has enough successful agents.

        Args:
            successes: entry point name -> number of agents in a success state.
        """
        return all(successes.get(ep.name, 0) >= max(ep.min, 1) for ep in self.entry_points if ep.success_required)

    def reachable_states(self, entry_point: str) -> frozenset[str]:
        """States an agent entering at ``entry_point`` can reach."""
        start = self.entry_point(entry_point).state
        if start is None:
            return frozenset()
        seen = {start}
        todo = [start]
        while todo:
            current = todo.pop()
            for t in self.out_transitions(current):
                if t.target not in seen:
                    seen.add(t.target)
                    todo.append(t.target)
        return frozenset(seen)


@dataclass(frozen=True, slots=True)
class PlanType:
    """Alternative plans for the same job; allocation picks the best, repair the next."""

    name: str
    plans: tuple[str, ...]
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<PlanType {self.name} {list(self.plans)}>"
