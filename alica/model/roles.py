"""Tasks, roles and role sets: who prefers which task."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from alica.model.common import find_named, span_field
from alica.source import SourceSpan


@dataclass(frozen=True, slots=True)
class Task:
    """A function within a plan that agents commit to through an entry point."""

    name: str
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<Task {self.name}>"


@dataclass(frozen=True, slots=True)
class Priority:
    """Pref(role, task): how much a role wants a task; negative means it cannot."""

    task: str
    value: float
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class Role:
    """A description of capabilities with a preference for each task.

    Args:
        name: the role's name, e.g. ``Scout``.
        priorities: the role-task priorities, each in [-1, 1]; a negative
            value means the role cannot take the task.
        requires: capabilities an agent must have to take the role.
        description: free text.
    """

    name: str
    priorities: tuple[Priority, ...] = ()
    requires: frozenset[str] = frozenset()
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<Role {self.name}>"

    @property
    def priority_map(self) -> Mapping[str, float]:
        """The priorities as a mapping."""
        return {p.task: p.value for p in self.priorities}


@dataclass(frozen=True, slots=True)
class RoleSet:
    """The roles of a team and their role-task priorities.

    Args:
        name: the role set's name.
        roles: its roles.
        default_priority: priority of a task a role does not mention.
    """

    name: str
    roles: tuple[Role, ...]
    default_priority: float = 0.0
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<RoleSet {self.name} {[r.name for r in self.roles]}>"

    def role(self, name: str) -> Role:
        """The role called ``name``.

        Raises:
            KeyError: no such role.
        """
        return find_named(self.roles, name, f"role set '{self.name}'", "role")

    def priority(self, role: str, task: str) -> float:
        """Pref(role, task), falling back to the default priority."""
        return self.role(role).priority_map.get(task, self.default_priority)
