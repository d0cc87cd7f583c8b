"""The designer's files as typed records: one dataclass per element.

Each record keeps the key path it was read from, so a later problem (a
reference to nothing, a cycle) can be reported at its place. References to
other files stay :class:`~alica.io.designer.json_view.Ref` values here;
:mod:`alica.io.designer.resolve` resolves them. :mod:`alica.io.designer.reader`
reads the records from JSON.
"""

from __future__ import annotations

from dataclasses import dataclass

from alica.io.designer.json_view import Ref, Scalar

#: Extensions of the designer files this reader knows, and what they hold.
KINDS = {
    "pml": "plan",
    "beh": "behaviour",
    "pty": "plan type",
    "rst": "role set",
    "tsk": "task repository",
    "cnd": "condition repository",
    "plh": "placeholder",
}

#: ``maxCardinality`` from this value up means no upper bound.
UNBOUNDED_CARDINALITY = 2147483647


@dataclass(frozen=True, slots=True)
class Cond:
    """A pre, runtime or post condition written inline (its logic is generated C++)."""

    id: int
    name: str
    comment: str
    text: str
    enabled: bool
    quantifiers: int
    variables: int
    key: str


@dataclass(frozen=True, slots=True)
class Var:
    """A variable of a plan, behaviour or plan type."""

    id: int
    name: str
    type: str
    key: str


@dataclass(frozen=True, slots=True)
class KeyMap:
    """One entry of a key mapping: a parent's blackboard key, or a constant, to a child's key."""

    parent_key: str | None
    child_key: str
    value: Scalar | None


@dataclass(frozen=True, slots=True)
class Wrapper:
    """A child of a state: a plan, behaviour, plan type or placeholder, with its key mapping."""

    id: int
    target: Ref | None
    configuration: bool
    inputs: tuple[KeyMap, ...]
    outputs: tuple[KeyMap, ...]
    key: str


@dataclass(frozen=True, slots=True)
class VarBinding:
    """A parent's variable bound to a child's: ``variable`` (a parent's id), ``sub_plan``, ``sub_variable``."""

    variable: int | None
    sub_plan: Ref | None
    sub_variable: Ref | None
    key: str


@dataclass(frozen=True, slots=True)
class StateRec:
    """A state; a terminal state is a success state when ``success`` holds, else a failure state."""

    id: int
    name: str
    comment: str
    terminal: bool
    success: bool
    post: Cond | None
    wrappers: tuple[Wrapper, ...]
    bindings: tuple[VarBinding, ...]
    key: str


@dataclass(frozen=True, slots=True)
class EntryRec:
    """An entry point: agents that take ``task`` start in ``state``."""

    id: int
    name: str
    task: Ref | None
    state: int | None
    min: int
    max: int
    success_required: bool
    dynamic: bool
    key: str


@dataclass(frozen=True, slots=True)
class TransitionRec:
    """A transition from state ``source`` to ``target`` (ids) under a named condition."""

    id: int
    name: str
    source: int | None
    target: int | None
    condition: Ref | None
    inputs: tuple[KeyMap, ...]
    outputs: tuple[KeyMap, ...]
    legacy: Cond | None
    sync: int | None
    key: str


@dataclass(frozen=True, slots=True)
class SyncRec:
    """A synchronisation of transitions (ids); the timeouts in milliseconds."""

    id: int
    name: str
    transitions: tuple[int, ...]
    talk_ms: float
    sync_ms: float
    fail: bool
    key: str


@dataclass(frozen=True, slots=True)
class PlanRec:
    """A plan file (``.pml``)."""

    file: str
    id: int
    name: str
    comment: str
    master: bool
    frequency: float
    threshold: float
    interface: bool
    inherit_blackboard: bool
    blackboard: int
    implementation: str
    variables: tuple[Var, ...]
    pre: Cond | None
    run: Cond | None
    entry_points: tuple[EntryRec, ...]
    states: tuple[StateRec, ...]
    transitions: tuple[TransitionRec, ...]
    syncs: tuple[SyncRec, ...]


@dataclass(frozen=True, slots=True)
class BehaviourRec:
    """A behaviour file (``.beh``)."""

    file: str
    id: int
    name: str
    comment: str
    frequency: float
    deferring: bool
    event_driven: bool
    interface: bool
    inherit_blackboard: bool
    blackboard: int
    implementation: str
    variables: tuple[Var, ...]
    pre: Cond | None
    run: Cond | None
    post: Cond | None


@dataclass(frozen=True, slots=True)
class AnnotatedPlan:
    """A plan listed by a plan type."""

    plan: Ref | None
    activated: bool
    key: str


@dataclass(frozen=True, slots=True)
class PlanTypeRec:
    """A plan type file (``.pty``)."""

    file: str
    id: int
    name: str
    comment: str
    plans: tuple[AnnotatedPlan, ...]
    bindings: int
    variables: tuple[Var, ...]


@dataclass(frozen=True, slots=True)
class Priority:
    """A role's priority for a task."""

    task: Ref | None
    value: float
    key: str


@dataclass(frozen=True, slots=True)
class RoleRec:
    """A role of a role set."""

    id: int
    name: str
    comment: str
    priorities: tuple[Priority, ...]
    characteristics: int
    key: str


@dataclass(frozen=True, slots=True)
class RoleSetRec:
    """A role set file (``.rst``)."""

    file: str
    id: int
    name: str
    comment: str
    default_priority: float
    default_roleset: bool
    roles: tuple[RoleRec, ...]


@dataclass(frozen=True, slots=True)
class TaskRec:
    """A task of a task repository."""

    id: int
    name: str
    comment: str
    key: str


@dataclass(frozen=True, slots=True)
class TaskRepoRec:
    """A task repository file (``.tsk``)."""

    file: str
    id: int
    name: str
    tasks: tuple[TaskRec, ...]


@dataclass(frozen=True, slots=True)
class RepoCondition:
    """A named condition of a condition repository, with its typed inputs (key, type)."""

    id: int
    name: str
    comment: str
    library: str
    inputs: tuple[tuple[str, str], ...]
    key: str


@dataclass(frozen=True, slots=True)
class ConditionRepoRec:
    """A condition repository file (``.cnd``)."""

    file: str
    id: int
    name: str
    conditions: tuple[RepoCondition, ...]


@dataclass(frozen=True, slots=True)
class PlaceholderRec:
    """A placeholder file (``.plh``): an interface bound to an implementation at deploy time."""

    file: str
    id: int
    name: str


#: Any record of a whole designer file.
FileRec = PlanRec | BehaviourRec | PlanTypeRec | RoleSetRec | TaskRepoRec | ConditionRepoRec | PlaceholderRec
