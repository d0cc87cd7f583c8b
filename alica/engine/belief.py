"""The belief base an agent's formulas read.

It combines, in this order:

1. the running plan's context: ``succeeded`` and ``failed`` (0-ary: all
   children of the current state succeeded / some child failed),
   ``succeeded(X)`` and ``failed(X)`` for the child ``X`` of the current
   state, ``elapsed`` (seconds in the current state);
2. team knowledge: ``role(a)``, ``alive(a)``, ``in_task(a, task)`` and
   ``in_state(a, state)`` for the agents of the current plan, and the objects
   of type ``Agent`` (alive agents);
3. the agent's own facts (a :class:`~alica.lang.FactBase`);
4. the shared world model.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Protocol

from alica.lang import BeliefBase, FactBase
from alica.model import Plan

if TYPE_CHECKING:
    from alica.engine.team import TeamView


class PlanContext(Protocol):
    """A running plan as the belief base reads it (the engine's :class:`~alica.engine.node.PlanNode`)."""

    @property
    def plan(self) -> Plan:
        """The plan."""
        ...

    @property
    def believed(self) -> Mapping[str, tuple[str | None, str | None]]:
        """Every agent in the plan -> its entry point and state, as this agent believes them."""
        ...

    @property
    def state_entered_at(self) -> float:
        """When this agent entered its current state."""
        ...

    def children_status(self, want: str) -> bool:
        """``success``: every child of the current state succeeded; ``failure``: some child failed."""
        ...

    def child_status(self, name: str, want: str) -> bool:
        """Whether the child ``name`` of the current state succeeded / failed."""
        ...


_CONTEXT = frozenset({"succeeded", "failed", "elapsed"})
_TEAM = frozenset({"role", "alive", "in_task", "in_state"})


class AgentBelief:
    """An agent's belief base; :meth:`at` sets the plan whose context formulas read (:attr:`node`).

    Args:
        agent: the agent's name (bound to ``self`` in formulas).
        world: the shared world model (any :class:`~alica.lang.BeliefBase`).
        team: the agent's team view.
        own: the agent's private facts.
        clock_now: a function giving the current time.
    """

    __slots__ = ("_now", "agent", "node", "own", "team", "world")

    def __init__(
        self, agent: str, world: BeliefBase, team: TeamView, own: FactBase, clock_now: Callable[[], float]
    ) -> None:
        self.agent = agent
        self.world = world
        self.team = team
        self.own = own
        self.node: PlanContext | None = None
        self._now = clock_now

    def at(self, node: PlanContext | None) -> AgentBelief:
        """This belief base, looking at ``node``'s context (``None``: no plan's)."""
        self.node = node
        return self

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        """See the module docstring for the order of sources."""
        if name in _CONTEXT:
            value = self._context(name, args)
            if value is not None:
                return value
        elif name in _TEAM:
            value = self._team(name, args)
            if value is not None:
                return value
        value = self.own.lookup(name, args)
        if value is not None:
            return value
        return self.world.lookup(name, args)

    def objects(self, type_name: str) -> Iterable[object]:
        """``Agent``: the alive agents; other types from own facts, then the world model."""
        if type_name == "Agent":
            return self.team.alive()
        own = self.own.objects(type_name)
        if own:
            return own
        return self.world.objects(type_name)

    def _context(self, name: str, args: tuple[object, ...]) -> object | None:
        node = self.node
        if node is None:
            return None
        if name == "elapsed":
            return self._now() - node.state_entered_at if not args else None
        if len(args) > 1:
            return None
        want = "success" if name == "succeeded" else "failure"
        if not args:
            return node.children_status(want)
        return node.child_status(str(args[0]), want)

    def _team(self, name: str, args: tuple[object, ...]) -> object | None:
        team = self.team
        if name == "role" and len(args) == 1:
            return team.roles.get(str(args[0]))
        if name == "alive" and len(args) == 1:
            return team.is_alive(str(args[0]))
        node = self.node
        if node is None or len(args) != 2:
            return None
        entry = node.believed.get(str(args[0]))
        if entry is None:
            return False
        if name == "in_task":
            return entry[0] is not None and node.plan.entry_point(entry[0]).task == args[1]
        return entry[1] == args[1]
