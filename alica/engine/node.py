"""A running plan in an agent's plan tree: its assignment, the agent's state, the rules.

Each tick the engine visits the tree top-down. For one plan node:

1. **integrate**: teammates' claims (the plans, entry points and states they
   say they are in) override what this agent predicted for them; agents that
   left the parent state, or went silent, are taken out;
2. **allocate**: when the assignment's inputs changed, the best assignment is
   computed again; the agent switches only when the utility gains more than
   the plan's threshold (or the current assignment became invalid). An
   authority's assignment, while it lasts, replaces this step;
3. **children**: the rules of the child plans run; a child plan that fails
   shows as ``failed`` to this plan's conditions;
4. **transitions**: the first out-transition of the agent's state whose
   condition holds fires (synchronised ones only together with the other
   agents), up to ``max_rule_applications`` in a row; a failed child is
   repaired only when none fires (see :mod:`alica.engine.slot`);
5. **abort**: a failure state, a run-time condition that no longer holds, or a
   failed child no transition handles makes the plan fail for this agent
   (the last not with automatic failure handling off); the plan succeeds when
   every success-required entry point has enough agents in success states.

Behaviours are ticked after the rules (see :meth:`AgentEngine.tick`).

A node does not hold the engine: it is given :class:`NodeParts`, the shared
context and the small interfaces declared here (the plan tree, allocation,
the start of children, child runtimes, solved values, synchronisations), each
satisfied by one of the engine's collaborators.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

from alica.engine.parts import AgentContext, NoSolution
from alica.engine.slot import Slot
from alica.engine.status import ChildStatus
from alica.engine.sync import SyncTable
from alica.engine.team import Claim, PlanKey, key_text
from alica.model import ChildRef, Plan, PlanLibrary, StateKind, Transition

if TYPE_CHECKING:
    from alica.allocation import Assignment
    from alica.engine.behaviours import BehaviourRunner
    from alica.engine.child import ChildRuntime

Entry = tuple[str | None, str | None]


class Tree(Protocol):
    """The agent's plan tree as its nodes and slots see it (:class:`~alica.engine.tree.PlanTree`)."""

    @property
    def library(self) -> PlanLibrary:
        """The plan library."""
        ...

    @property
    def inputs(self) -> int:
        """Moves on whenever something an allocation reads may have changed."""
        ...

    def plan(self, name: str) -> Plan:
        """A plan of the library, or one a child runtime generated."""
        ...

    def changed(self) -> None:
        """The plan tree changed: tell the team soon."""
        ...

    def forget(self, node: PlanNode) -> None:
        """``node`` stopped."""
        ...

    def left_with_success(self, node: PlanNode) -> None:
        """``node`` stops after this agent's task succeeded in it: keep claiming the success."""
        ...

    def out_transitions(self, plan: Plan, state: str) -> tuple[Transition, ...]:
        """The transitions leaving ``state``."""
        ...


class Allocation(Protocol):
    """The allocation rules as plan nodes and slots call them (:class:`~alica.engine.allocate.Allocator`)."""

    def members(self, parent: PlanNode | None) -> tuple[str, ...]:
        """Alive agents believed to be in ``parent``'s state (all alive agents for the root), sorted."""
        ...

    def start(self, slot: Slot | None, plans: tuple[Plan, ...], env: dict[str, object], now: float) -> PlanNode | None:
        """Allocate the agents of ``slot``'s state to one of ``plans`` and start it (``None``: no assignment)."""
        ...

    def reallocate(self, node: PlanNode, now: float) -> None:
        """The dynamic allocation rule for a running plan."""
        ...

    def carry(self, node: PlanNode) -> None:
        """``node`` restarts for want of agents: keep what succeeded in it for the new instance."""
        ...


class Launch(Protocol):
    """What a state's children get when the agent enters the state (:class:`~alica.engine.launch.Launcher`)."""

    def bind(self, node: PlanNode, ref: ChildRef) -> dict[str, object]:
        """The variables of child ``ref`` of ``node``'s state.

        Raises:
            NoSolution: a binding reads a solved variable and the constraints have no solution now.
        """
        ...

    def runner(self, slot: Slot) -> BehaviourRunner:
        """The runner of a behaviour child, with its parameters bound."""
        ...


class Runtimes(Protocol):
    """The child runtimes the engine was configured with (:class:`~alica.engine.hosting.Children`)."""

    def runtime(self, slot: Slot) -> ChildRuntime:
        """The runtime of a child that is neither a behaviour, a plan nor a plan type."""
        ...


class Watch(Protocol):
    """Behaviours started with solved values, watched for new ones (:class:`~alica.engine.solving.Solving`)."""

    def track(self, slot: Slot) -> None:
        """Restart ``slot``'s behaviour when the solved values it was started with change."""
        ...

    def unwatch(self, slot: Slot) -> None:
        """The slot stopped."""
        ...


@dataclass(frozen=True, slots=True)
class NodeParts:
    """Everything a plan node and its slots work with: made once by the engine, shared by every node.

    Attributes:
        ctx: the agent's name, clock, settings, team view, formulas, belief base and trace.
        tree: the plan tree the node is part of.
        allocation: the allocation rules.
        launch: binds a child's variables and builds a behaviour's runner.
        runtimes: makes the runtime of a planning problem's child.
        solved: watches behaviours whose variables the constraint solver gives.
        syncs: the agent's synchronisation processes.
    """

    ctx: AgentContext
    tree: Tree
    allocation: Allocation
    launch: Launch
    runtimes: Runtimes
    solved: Watch
    syncs: SyncTable


class PlanNode:
    """One plan instance as one agent runs it.

    Args:
        parts: what the node works with (the same for every node of the agent).
        key: the plan instance's key in the team.
        slot: the child of the parent state it runs in; ``None`` for the root.
        plan: the plan.
        env: its variables, bound by the parent.
        now: the start time.
    """

    def __init__(
        self, parts: NodeParts, key: PlanKey, slot: Slot | None, plan: Plan, env: dict[str, object], now: float
    ) -> None:
        self.parts = parts
        self.key = key
        self.key_text = key_text(key)
        self.slot = slot
        self.plan = plan
        self.env = env
        self.believed: dict[str, Entry] = {}
        self.predicted_at: dict[str, float] = {}
        self.succeeded: dict[str, set[str]] = {}
        self.ep: str | None = None
        self.state: str | None = None
        self.slots: list[Slot] = []
        self.status = ChildStatus.RUNNING
        self.reason = ""
        self.started_at = now
        self.state_entered_at = now
        self.dirty = False
        self.history: deque[tuple[float, str, str, str | None, str | None]] = deque(maxlen=64)
        self.contested_until = -1.0
        self.authority_until = -1.0
        self.authority_window = 0.0
        self.overridden_until = -1.0
        self.understaffed = False
        """The plan failed for want of agents (no valid assignment with the teammates alive now)."""
        self.former: set[str] = set()
        """Teammates that were in this instance and left it (their successes here still count)."""
        self.stopped = False
        """The agent left this plan instance (a node replaced in mid-visit stops there)."""
        self._members: tuple[str, ...] | None = None

    def __repr__(self) -> str:
        return f"<PlanNode {self.key_text} {self.ep}/{self.state} {self.status.value}>"

    @property
    def failed(self) -> bool:
        """Whether the plan failed for this agent (its status may change during a visit: read it again)."""
        return self.status is ChildStatus.FAILURE

    # -- team ----------------------------------------------------------

    def members(self) -> tuple[str, ...]:
        """Alive agents believed to be in the parent state (all alive agents for the root), sorted."""
        if self._members is None:
            self._members = self.parts.allocation.members(self.slot.parent if self.slot is not None else None)
        return self._members

    def invalidate(self) -> None:
        """Inputs of the assignment changed: integrate and allocate again on the next visit."""
        self.dirty = True
        self._members = None

    def successes(self) -> dict[str, int]:
        """Agents whose task succeeded, per entry point."""
        return {ep: len(agents) for ep, agents in self.succeeded.items() if agents}

    def own_successes(self) -> tuple[str, ...]:
        """Entry points in which this agent's task succeeded here."""
        me = self.parts.ctx.name
        return tuple(sorted(ep for ep, agents in self.succeeded.items() if me in agents))

    def claim(self) -> Claim:
        """What this agent says about this plan in its team message."""
        return Claim(
            self.key,
            self.plan.name,
            self.ep,
            self.state,
            self.own_successes(),
            self.contested_until > self.parts.ctx.now(),
        )

    def integrate(self, now: float) -> bool:
        """Take teammates' claims and the team's liveness into the believed assignment.

        Returns:
            Whether anything changed.
        """
        ctx = self.parts.ctx
        me = ctx.name
        team = ctx.team
        members = set(self.members())
        changed = False
        for agent in [a for a in self.believed if a != me and a not in members]:
            del self.believed[agent]
            self.former.add(agent)
            changed = True
        protection = ctx.config.assignment_protection
        for agent in sorted(self.former):
            if agent in members or not team.is_alive(agent):
                continue
            # a teammate that left this instance (its parent moved on) still counts where it succeeded;
            # only one that was in this instance: a new instance of the same key starts without it
            claim = team.claim(agent, self.key)
            if claim is not None and claim.plan == self.plan.name:
                changed |= self._count_successes(agent, claim)
        for agent in sorted(members - {me}):
            claim = team.claim(agent, self.key)
            current = self.believed.get(agent)
            predicted = self.predicted_at.get(agent)
            expired = predicted is not None and now - predicted > protection
            if claim is not None and claim.plan == self.plan.name:
                changed |= self._count_successes(agent, claim)
                new = (claim.entry, claim.state)
                if current == new:
                    self.predicted_at.pop(agent, None)
                elif predicted is None or expired or team.changed_at(agent) > predicted:
                    # the teammate's own word trumps a prediction, once it is news or the prediction expired
                    self.believed[agent] = new
                    self.predicted_at.pop(agent, None)
                    if current is None or current[0] != new[0]:
                        self.history.append((now, "message", agent, current[0] if current else None, new[0]))
                    changed = True
            elif current is not None and team.has_spoken(agent):
                since = predicted if predicted is not None else self.started_at
                if now - since > protection:
                    del self.believed[agent]
                    self.predicted_at.pop(agent, None)
                    changed = True
                else:
                    self.predicted_at[agent] = since
            elif expired:
                self.predicted_at.pop(agent, None)
        if changed:
            self._children_membership_changed()
        return changed

    def _count_successes(self, agent: str, claim: Claim) -> bool:
        """Record the entry points ``agent`` says its task succeeded in here; whether any is new."""
        new = False
        for ep in claim.success:
            done = self.succeeded.setdefault(ep, set())
            if agent not in done:
                done.add(agent)
                new = True
        return new

    def _children_membership_changed(self) -> None:
        for slot in self.slots:
            if slot.node is not None:
                slot.node.invalidate()

    # -- own entry point and state --------------------------------------

    def set_entry(self, ep: str | None, now: float) -> None:
        """Take entry point ``ep`` (``None``: idle) and enter its initial state."""
        self.ep = ep
        me = self.parts.ctx.name
        if ep is None:
            self._leave_state()
            self.state = None
            self.believed[me] = (None, None)
            return
        state = self.plan.entry_point(ep).state
        assert state is not None  # validated plans have an initial state per entry point
        self.enter_state(state, now)

    def enter_state(self, state: str, now: float) -> None:
        """Leave the current state (stopping its children) and enter ``state``."""
        self._leave_state()
        parts = self.parts
        me = parts.ctx.name
        self.state = state
        self.state_entered_at = now
        self.believed[me] = (self.ep, state)
        model = self.plan.state(state)
        if model.kind is StateKind.SUCCESS and self.ep is not None:
            self.succeeded.setdefault(self.ep, set()).add(me)
            self.dirty = True  # free now: maybe needed for another task
        parts.tree.changed()
        for ref in model.children:
            self.slots.append(self.start_child(ref, now))

    def start_child(self, ref: ChildRef, now: float) -> Slot:
        """Start child ``ref`` of the current state (its variables bound now); the caller keeps the slot."""
        parts = self.parts
        try:
            env, unsolved = parts.launch.bind(self, ref), ""
        except NoSolution as exc:
            env, unsolved = {"self": parts.ctx.name}, str(exc)
        slot = Slot(self, ref, env)
        if unsolved:
            slot.fail_unsolved(unsolved)  # a status the plan reacts to ('failed'), not an exception
        elif slot.is_behaviour:
            slot.runner = parts.launch.runner(slot)
            slot.status = slot.runner.status
            parts.solved.track(slot)
        else:
            slot.start(now)
        return slot

    def _leave_state(self) -> None:
        for slot in self.slots:
            slot.stop()
        self.slots = []
        self.parts.syncs.drop(self.key)

    def stop(self) -> None:
        """Stop every child: the agent leaves this plan (what it succeeded in here is still claimed, see ``left``)."""
        self.stopped = True
        self.parts.tree.left_with_success(self)
        self._leave_state()
        self.parts.tree.forget(self)

    # -- conditions ------------------------------------------------------

    def children_status(self, want: str) -> bool:
        """``succeeded``: every child succeeded (false without children); ``failed``: some child failed."""
        if want == "success":
            return bool(self.slots) and all(s.status is ChildStatus.SUCCESS for s in self.slots)
        return any(s.status is ChildStatus.FAILURE for s in self.slots)

    def child_status(self, name: str, want: str) -> bool:
        """Whether the child ``name`` of the current state succeeded / failed."""
        target = ChildStatus.SUCCESS if want == "success" else ChildStatus.FAILURE
        return any(s.name == name and s.status is target for s in self.slots)

    # -- the rules -------------------------------------------------------

    def visit(self, now: float) -> None:
        """Apply the rules to this plan and its children (see the module docstring)."""
        if self.status is ChildStatus.FAILURE:
            return
        parts = self.parts
        config = parts.ctx.config
        if 0 <= self.overridden_until <= now:
            # an authority's window ended: look at the allocation again
            self.overridden_until = -1.0
            self.dirty = True
        # a prediction not confirmed by the teammate's claim within the protection time expires
        if (
            self.predicted_at
            and not self.dirty
            and now - min(self.predicted_at.values()) > config.assignment_protection
        ):
            self.dirty = True
        if self.slot is not None and self.slot.choice_changed():
            self.dirty = True  # a plan of the type may run now, or may not any more
        if self.dirty:
            self.dirty = False
            self.integrate(now)
            parts.allocation.reallocate(self, now)
            if self.failed or self.stopped:
                return
        for slot in list(self.slots):
            slot.visit(now)
        if self.state is None:
            self._check_success()
            return
        fired = False
        for _ in range(config.max_rule_applications):
            if self.plan.state(self.state).terminal:
                break
            transition = self._transition_rule(now)
            if transition is None:
                break
            fired = True
            parts.ctx.emit(
                "transition",
                key=self.key_text,
                plan=self.plan.name,
                source=transition.source,
                target=transition.target,
                name=transition.name,
            )
            self.enter_state(transition.target, now)
        if self.failed:
            return
        if not fired:
            for slot in list(self.slots):
                slot.repair_pending(now)
        self._abort_rule(fired)
        if not self.failed:
            self._check_success()

    def _transition_rule(self, now: float) -> Transition | None:
        parts = self.parts
        ctx = parts.ctx
        state = self.state
        assert state is not None  # the rules run in a state
        belief = ctx.belief.at(self)
        for transition in parts.tree.out_transitions(self.plan, state):
            condition = transition.condition.text if transition.condition else None
            holds = ctx.formulas.holds(condition, belief, self.env)
            if transition.synchronisation is None:
                if holds:
                    return transition
                continue
            process = parts.syncs.process(self.key, self.plan, transition.synchronisation)
            process.update_mine(transition.name, holds, now)
            if holds and process.complete():
                ctx.emit("sync", key=self.key_text, sync=process.sync.name, transition=transition.name, outcome="fired")
                process.reset()
                return transition
            if process.timed_out(now):
                process.reset()
                if process.sync.fail_on_timeout:
                    self.fail(f"synchronisation '{process.sync.name}' timed out after {process.sync.sync_timeout} s")
                    return None
                ctx.emit(
                    "sync", key=self.key_text, sync=process.sync.name, transition=transition.name, outcome="timeout"
                )
        return None

    def _abort_rule(self, fired: bool) -> None:
        assert self.state is not None
        state = self.plan.state(self.state)
        if state.kind is StateKind.FAILURE:
            self.fail(f"reached failure state '{state.name}'")
            return
        ctx = self.parts.ctx
        run = self.plan.run
        if run is not None and not ctx.formulas.holds(run.text, ctx.belief.at(self), self.env):
            self.fail(f"run-time condition '{run.text}' no longer holds")
            return
        if not fired and ctx.config.auto_failure_handling:
            for slot in self.slots:
                if slot.status is ChildStatus.FAILURE:
                    self.fail(
                        f"child '{slot.name}' of state '{state.name}' failed and no transition handles it ({slot.reason})"
                    )
                    return

    def plan_succeeded(self) -> bool:
        """Plan success: every success-required entry point has enough agents in success states.

        A plan with no success-required entry point succeeds once any agent's task succeeded.
        """
        successes = self.successes()
        if any(ep.success_required for ep in self.plan.entry_points):
            return self.plan.succeeded(successes)
        return bool(successes)

    def _check_success(self) -> None:
        if self.status is ChildStatus.RUNNING and self.plan_succeeded():
            self.status = ChildStatus.SUCCESS
            self.parts.ctx.emit("success", key=self.key_text, plan=self.plan.name)

    def fail(self, reason: str) -> None:
        """The plan failed for this agent; the parent repairs it."""
        if self.status is ChildStatus.FAILURE:
            return
        self.status = ChildStatus.FAILURE
        self.reason = reason
        self.parts.ctx.emit("failure", key=self.key_text, plan=self.plan.name, reason=reason)

    # -- allocation results ---------------------------------------------

    def apply(self, assignment: Assignment, now: float, reason: str) -> None:
        """Adopt an assignment: predictions for teammates, a new entry point for this agent if it changed."""
        me = self.parts.ctx.name
        for agent, ep in assignment.entries:
            if agent == me:
                continue
            current = self.believed.get(agent)
            if current is None or current[0] != ep:
                state = self.plan.entry_point(ep).state if ep is not None else None
                self.believed[agent] = (ep, state)
                self.predicted_at[agent] = now
                self.history.append((now, reason, agent, current[0] if current else None, ep))
        self._children_membership_changed()
        if me in assignment.agents:
            mine = assignment.entry_of(me)
            if mine != self.ep or (self.state is None and mine is not None):
                self.history.append((now, reason, me, self.ep, mine))
                self.set_entry(mine, now)
        self.parts.tree.changed()

    def conflicts(self, now: float, window: float) -> int:
        """Times, within ``window`` seconds, that a teammate's message undid a utility-driven change."""
        count = 0
        last_utility: dict[str, tuple[str | None, str | None]] = {}
        for t, reason, agent, old, new in self.history:
            if now - t > window:
                continue
            if reason == "utility":
                last_utility[agent] = (old, new)
            elif reason == "message" and agent in last_utility and last_utility[agent] == (new, old):
                count += 1
                del last_utility[agent]
        return count
