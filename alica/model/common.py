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


@dataclass(frozen=True, slots=True)
class Variable:
    """A named value of a plan or behaviour, bound by a parent or solved by constraints."""

    name: str
    type: str = "any"
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class Constraint:
    """A formula over variables that the constraint solver must satisfy.

    Args:
        name: unique within its plan.
        text: the formula, e.g. IMPERA Eq. 7.
        variables: the variables it constrains.
    """

    name: str
    text: str
    variables: tuple[str, ...] = ()
    span: SourceSpan | None = span_field()


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
