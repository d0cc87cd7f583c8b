"""What an agent keeps of the plans its team generated at run time (planning problems).

The engine itself does not plan: the runtime of a planning problem
(:mod:`alica.prophet.runtime`) does. The engine carries its messages on
:data:`PLAN_TOPIC`, keeps the latest plan shared for each planning problem
(so that an agent entering the state late still finds it) and the replan
requests teammates sent, and registers generated plans with their tasks'
priorities so that allocation can use them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any, Protocol

from alica.engine.team import PlanKey
from alica.model import Plan, Priority, RoleSet

#: Topic of plan shares and replan requests (reliable).
PLAN_TOPIC = "prophet/plan"


class Share(Protocol):
    """A plan shared by a leader (see :class:`alica.prophet.runtime.PlanShare`)."""

    key: PlanKey
    generation: int
    version: int

    def supersedes(self, other: Any) -> bool:
        """Whether this share replaces ``other``."""


class PlanBoard:
    """The latest share per planning problem, the pending replan requests, the generated plans."""

    def __init__(self) -> None:
        self.shares: dict[PlanKey, Any] = {}
        self.received_at: dict[PlanKey, float] = {}
        self.generations: dict[PlanKey, int] = {}
        self.requests: dict[PlanKey, list[Any]] = {}
        self.plans: dict[str, Plan] = {}
        self.priorities: dict[str, Mapping[str, tuple[Priority, ...]]] = {}
        self.pins: dict[str, Mapping[str, tuple[str, ...]]] = {}
        self.latest: dict[PlanKey, Any] = {}
        """The latest generated plan (``alica.prophet.tasks.CreatedTasks``) per planning problem, kept after it ends."""

    def receive(self, payload: Any, now: float) -> None:
        """Take in a share (kept if it supersedes the one known) or a replan request."""
        key = payload.key
        self.generations[key] = max(self.generations.get(key, 0), payload.generation)
        if getattr(payload, "is_request", False):
            self.requests.setdefault(key, []).append(payload)
            return
        current = self.shares.get(key)
        if current is None or payload.supersedes(current):
            self.shares[key] = payload
            self.received_at[key] = now
        elif (payload.generation, payload.version) == (current.generation, current.version):
            self.received_at[key] = now  # the leader repeats it: still current

    def take_requests(self, key: PlanKey) -> list[Any]:
        """The replan requests for ``key`` received since the last call."""
        return self.requests.pop(key, [])

    def register(
        self, plan: Plan, priorities: Mapping[str, tuple[Priority, ...]], pins: Mapping[str, tuple[str, ...]]
    ) -> None:
        """Make a generated plan known, with its tasks' priorities per role and its pinned entry points."""
        self.plans[plan.name] = plan
        self.priorities[plan.name] = priorities
        if pins:
            self.pins[plan.name] = pins

    def unregister(self, name: str) -> None:
        """Forget a generated plan."""
        self.plans.pop(name, None)
        self.priorities.pop(name, None)
        self.pins.pop(name, None)

    def roleset(self, base: RoleSet) -> RoleSet:
        """``base`` with the priorities of every registered generated plan's tasks."""
        if not self.priorities:
            return base
        roles = []
        for role in base.roles:
            extra = tuple(p for name in sorted(self.priorities) for p in self.priorities[name].get(role.name, ()))
            roles.append(replace(role, priorities=role.priorities + extra) if extra else role)
        return replace(base, roles=tuple(roles))
