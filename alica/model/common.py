"""Pieces shared by every model element: enums, source spans, small values."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import Enum
from typing import TypeVar

from alica.source import SourceSpan

T = TypeVar("T")

#: Written as ``"*"`` (YAML) or ``"*"``/``"inf"`` in files: no upper bound.
UNBOUNDED = math.inf


def span_field() -> SourceSpan | None:
    """A ``span`` field: where the element was written, ignored by ``==``."""
    return field(default=None, compare=False, repr=False, kw_only=True)


class StateKind(Enum):
    """What kind of state a plan state is."""

    NORMAL = "normal"
    """An ordinary state: the agent runs its children until a transition fires."""
    SUCCESS = "success"
    """A terminal state that counts as success of the agent's task."""
    FAILURE = "failure"
    """A terminal state that makes the plan fail for this agent."""

    @property
    def terminal(self) -> bool:
        """Whether the state ends the agent's part in the plan."""
        return self is not StateKind.NORMAL


class ConditionKind(Enum):
    """Where a condition is attached."""

    PRE = "pre"
    """Must hold before a plan or behaviour is started."""
    RUN = "run"
    """Must keep holding while a plan or behaviour runs."""
    POST = "post"
    """Holds once a terminal state is reached or a behaviour finished."""
    TRANSITION = "transition"
    """Guards a transition between two states."""


@dataclass(frozen=True, slots=True)
class Condition:
    """A formula of the logic language attached to an element.

    The text is kept as written; :mod:`alica.lang` parses it once.
    """

    kind: ConditionKind
    text: str
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<{self.kind.value} {self.text!r}>"


#: Variable types with a numeric range; any other type but ``any`` is an object type.
NUMERIC_TYPES: frozenset[str] = frozenset({"real", "int", "point"})
#: The type of a variable that is only bound by a parent, never solved on its own.
ANY_TYPE = "any"


@dataclass(frozen=True, slots=True)
class Variable:
    """A named value of a plan or behaviour, bound by a parent or solved by constraints.

    Read in a formula as ``x`` it is a static variable (one value for the team);
    read as ``x(a)`` with an agent ``a`` it is a per-agent variable (one value per
    agent of the plan).

    Args:
        name: unique within its plan or behaviour.
        type: ``any`` (bound by a parent only), ``real``, ``int``, ``point`` (a 2-D
            point, both coordinates in the range), or an object type such as
            ``Frontier`` (a finite set of values).
        low: for real, int and point variables, the smallest value (point: of x and y).
        high: the largest value.
        candidates: for object types, a formula whose value is the list of candidate
            values, e.g. ``frontiers()``; ``None`` means every object of the type.
    """

    name: str
    type: str = ANY_TYPE
    low: float | None = None
    high: float | None = None
    candidates: str | None = None
    span: SourceSpan | None = span_field()

    @property
    def numeric(self) -> bool:
        """Whether the variable is real, int or point, a value in a range."""
        return self.type in NUMERIC_TYPES

    @property
    def object_type(self) -> bool:
        """Whether the variable's values are objects of a type (a finite set)."""
        return self.type != ANY_TYPE and self.type not in NUMERIC_TYPES


@dataclass(frozen=True, slots=True)
class Constraint:
    """A formula over variables that the constraint solver must satisfy, and a utility it maximises.

    A constraint is active while its plan runs.

    Args:
        name: unique within its plan.
        text: the hard formula, a truth value, e.g. IMPERA Eq. 7; ``""`` when only
            a utility is given.
        variables: the variables it constrains.
        utility: a numeric formula the solver maximises, e.g. the information
            gain of the chosen frontiers; ``""`` for none.
        span: where the formula's text starts (else the constraint's).
        utility_span: where the utility's text starts.
    """

    name: str
    text: str
    variables: tuple[str, ...] = ()
    utility: str = ""
    span: SourceSpan | None = span_field()
    utility_span: SourceSpan | None = span_field()


def find_named(items: Iterable[T], name: str, owner: str, kind: str) -> T:
    """The item of ``items`` whose ``name`` is ``name``.

    Raises:
        KeyError: none is, with a message naming ``owner`` and ``kind``.
    """
    for item in items:
        if item.name == name:  # type: ignore[attr-defined]
            return item
    raise KeyError(f"{owner} has no {kind} '{name}'")


def format_cardinality(value: float) -> str:
    """``3`` or ``*`` for unbounded."""
    return "*" if value == UNBOUNDED else str(int(value))
