"""The plans child runtimes generated at run time, which allocation uses like the library's own.

A child runtime (:mod:`alica.engine.child`; a planning problem's, say)
registers each plan it generates with the priorities of its tasks per role and
the entry points only some agents may take; the engine allocates generated
plans with the role set extended by those priorities and vetoes the agents a
pinned entry point does not allow.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from alica.model import Plan, Priority, RoleSet


class GeneratedPlans:
    """The generated plans an agent knows now, with their tasks' priorities and pinned entry points.

    Args:
        base: the team's role set; :attr:`roleset` adds the generated tasks' priorities to it.
    """

    def __init__(self, base: RoleSet) -> None:
        self.base = base
        self.roleset = base
        """The role set to allocate with: ``base`` with the priorities of every registered plan's tasks."""
        self.plans: dict[str, Plan] = {}
        self.priorities: dict[str, Mapping[str, tuple[Priority, ...]]] = {}
        self.pins: dict[str, Mapping[str, tuple[str, ...]]] = {}

    def register(
        self, plan: Plan, priorities: Mapping[str, tuple[Priority, ...]], pins: Mapping[str, tuple[str, ...]]
    ) -> None:
        """Make a generated plan known, with its tasks' priorities per role and its pinned entry points."""
        self.plans[plan.name] = plan
        self.priorities[plan.name] = priorities
        if pins:
            self.pins[plan.name] = pins
        self.roleset = self._with_priorities()

    def rebase(self, base: RoleSet) -> None:
        """The team's role set changed (a hot reload): allocate with ``base`` and the generated priorities."""
        self.base = base
        self.roleset = self._with_priorities()

    def unregister(self, name: str) -> None:
        """Forget a generated plan."""
        self.plans.pop(name, None)
        self.priorities.pop(name, None)
        self.pins.pop(name, None)
        self.roleset = self._with_priorities()

    def _with_priorities(self) -> RoleSet:
        base = self.base
        if not self.priorities:
            return base
        roles = []
        for role in base.roles:
            extra = tuple(p for name in sorted(self.priorities) for p in self.priorities[name].get(role.name, ()))
            roles.append(replace(role, priorities=role.priorities + extra) if extra else role)
        return replace(base, roles=tuple(roles))
