"""One agent's plan tree: the plan instances it runs, by key, and what it claims of them to the team.

:class:`PlanTree` keeps the bookkeeping the plan nodes report to (a node
started, changed state, stopped, left with a success), makes the nodes
(allocation asks it to), and builds the claims of the agent's team message.
It satisfies :class:`alica.engine.node.Tree` (what the nodes and slots see of
it) and :class:`alica.engine.allocate.Nodes` (what allocation sees).

**Left with a success.** A plan instance the agent left after its task
succeeded there stays claimed (no entry point, the successes) while the
parent stays in the state it moved on to, so a teammate learns the success
even when the parent moved on in the step the task succeeded.
"""

from __future__ import annotations

from dataclasses import dataclass

from alica.engine.generated import GeneratedPlans
from alica.engine.node import NodeParts, PlanNode
from alica.engine.slot import Slot
from alica.engine.status import ChildStatus
from alica.engine.team import AuthorityClaim, Claim, PlanKey
from alica.errors import AlicaError
from alica.model import Plan, PlanLibrary, Transition


@dataclass(slots=True)
class _Left:
    """A success claimed for a plan instance the agent left, while its parent stays where it moved on to."""

    claim: Claim
    parent: PlanNode
    entered: float | None = None


class PlanTree:
    """The plan instances one agent runs (see the module docstring).

    Args:
        library: the plan library.
        generated: the plans child runtimes generated at run time.
    """

    def __init__(self, library: PlanLibrary, generated: GeneratedPlans) -> None:
        self.library = library
        self.generated = generated
        self.index: dict[PlanKey, PlanNode] = {}
        """Every running plan instance of the agent, by key."""
        self.left: dict[PlanKey, _Left] = {}
        """Plan instances this agent left after its task succeeded there (see the module docstring)."""
        self.inputs = 0
        """Moves on whenever something an allocation reads may have changed: teammates' claims and liveness,
        the world, this agent's own plan tree. A child that found no assignment tries again when it moved."""
        self.news = True
        """The tree changed since the last team message."""
        self._parts: NodeParts | None = None
        self._transitions: dict[tuple[str, str], tuple[Transition, ...]] = {}

    def attach(self, parts: NodeParts) -> None:
        """Give the tree what its nodes work with (the engine does, once, after making the parts)."""
        self._parts = parts

    def use(self, library: PlanLibrary) -> None:
        """Read plans from ``library`` from now on (a hot reload; the nodes are carried over by the caller)."""
        self.library = library
        self._transitions.clear()
        self.changed()

    # -- nodes ---------------------------------------------------------

    def new_node(self, key: PlanKey, slot: Slot | None, plan: Plan, env: dict[str, object], now: float) -> PlanNode:
        """A new plan node, indexed by ``key``."""
        if self._parts is None:
            raise AlicaError("the plan tree has no parts yet: PlanTree.attach comes first")
        node = self.index[key] = PlanNode(self._parts, key, slot, plan, env, now)
        return node

    def get(self, key: PlanKey) -> PlanNode | None:
        """The running plan node of instance ``key``, if any."""
        return self.index.get(key)

    def plan(self, name: str) -> Plan:
        """A plan of the library, or one generated at run time by a child runtime."""
        plan = self.library.plans.get(name)
        return plan if plan is not None else self.generated.plans[name]

    def out_transitions(self, plan: Plan, state: str) -> tuple[Transition, ...]:
        """Transitions leaving ``state`` (cached)."""
        key = (plan.name, state)
        hit = self._transitions.get(key)
        if hit is None:
            hit = self._transitions[key] = plan.out_transitions(state)
        return hit

    # -- what the nodes report ----------------------------------------------

    def moved(self) -> None:
        """Something an allocation reads may have changed (:attr:`inputs`)."""
        self.inputs += 1

    def changed(self) -> None:
        """The plan tree changed: tell the team soon."""
        self.news = True
        self.inputs += 1

    def forget(self, node: PlanNode) -> None:
        """A plan node stopped."""
        if self.index.get(node.key) is node:
            del self.index[node.key]
        self.news = True

    def left_with_success(self, node: PlanNode) -> None:
        """``node`` stops after this agent's task succeeded in it: keep claiming the success (``left``)."""
        done = node.own_successes()
        parent = node.slot.parent if node.slot is not None else None
        if done and parent is not None:
            self.left[node.key] = _Left(Claim(node.key, node.plan.name, None, None, done), parent)

    def invalidate_all(self) -> None:
        """Every node integrates and allocates again on its next visit."""
        for node in self.index.values():
            node.invalidate()

    # -- what the agent tells the team -------------------------------------------

    def claims(self, root: PlanNode | None) -> list[Claim]:
        """This agent's claims, ``root`` first, then the instances it left with a success (``left``)."""
        out = []
        todo = [root] if root is not None else []
        while todo:
            node = todo.pop()
            if node.status is not ChildStatus.FAILURE:
                out.append(node.claim())
            todo.extend(reversed([s.node for s in node.slots if s.node is not None]))
        for key, left in list(self.left.items()):
            parent = left.parent
            if left.entered is None:
                left.entered = parent.state_entered_at  # the state the parent moved on to
            if self.index.get(parent.key) is not parent or parent.state_entered_at != left.entered:
                del self.left[key]  # the parent ended or moved on again: the instance is history
            elif key not in self.index:
                out.append(left.claim)
        return out

    def authority(self, now: float) -> tuple[AuthorityClaim, ...]:
        """The assignments this agent imposes by authority now."""
        return tuple(
            AuthorityClaim(
                n.key, n.plan.name, tuple(sorted((a, e[0]) for a, e in n.believed.items())), n.authority_until
            )
            for n in self.index.values()
            if n.authority_until > now
        )
