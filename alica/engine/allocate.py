"""One agent's allocation rules: who takes which entry point of a plan, computed from the team view.

* **Initial allocation** (:meth:`Allocator.start`): the agents of a state are
  allocated to one of the plans a child may run; teammates already in the plan
  keep their entry points (their claims trump predictions).
* **Dynamic allocation** (:meth:`Allocator.reallocate`): while a plan runs,
  its agents are allocated again when the team or the world changed, and the
  plan switches to a better assignment (or a better plan of the child's plan
  type) when the utility gains more than the plan's threshold; then agents
  whose task succeeded take success-required tasks nobody has done.
* **Conflicts** flipping an allocation back and forth are settled by
  authority: the lowest agent imposes its assignment for a window
  (:meth:`Allocator.apply_authority` takes in such claims).

Every agent computes the same result from the same view, so the team agrees
without a central controller (:mod:`alica.allocation` solves the problems).

The allocator reads the agent's shared context (:class:`~alica.engine.parts.AgentContext`:
team view, formulas, belief, settings) and the generated plans' priorities and
pins; of the plan tree it needs only :class:`Nodes` (make and find plan nodes,
say the tree changed). It keeps, itself, what succeeded in plan instances
restarted for want of agents (:meth:`Allocator.carry`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

from alica.allocation import AllocationProblem, Assignment, allocate, utility
from alica.engine.generated import GeneratedPlans
from alica.engine.parts import AgentContext
from alica.engine.status import ChildStatus
from alica.engine.team import PlanKey
from alica.errors import AlicaError
from alica.model import Plan, StateKind, Summand
from alica.model.plan import EntryPoint

if TYPE_CHECKING:
    from alica.engine.node import PlanNode
    from alica.engine.slot import Slot


class Nodes(Protocol):
    """The plan tree as allocation uses it (:class:`~alica.engine.tree.PlanTree`)."""

    def new_node(self, key: PlanKey, slot: Slot | None, plan: Plan, env: dict[str, object], now: float) -> PlanNode:
        """A new plan node, indexed by ``key``."""
        ...

    def get(self, key: PlanKey) -> PlanNode | None:
        """The running plan node of instance ``key``, if any."""
        ...

    def plan(self, name: str) -> Plan:
        """A plan of the library, or one a child runtime generated."""
        ...

    def changed(self) -> None:
        """The plan tree changed: tell the team soon."""
        ...


class Allocator:
    """The allocation rules of one agent's engine (see the module docstring).

    Args:
        ctx: the agent's name, team view, formulas, belief, settings and trace.
        nodes: makes and finds the plan tree's nodes.
        generated: the plans child runtimes generated, with their tasks' priorities and pins.
    """

    def __init__(self, ctx: AgentContext, nodes: Nodes, generated: GeneratedPlans) -> None:
        self.ctx = ctx
        self.nodes = nodes
        self.generated = generated
        self._unallocated: dict[PlanKey, str] = {}
        """Plan instance -> why its last allocation found no assignment (reported once while it stays the same)."""
        self.carried: dict[PlanKey, tuple[str, dict[str, set[str]]]] = {}
        """Plan instances restarted for want of agents: the plan and who succeeded in which entry point."""

    def carry(self, node: PlanNode) -> None:
        """``node`` restarts for want of agents: the new instance starts with what succeeded in it."""
        self.carried[node.key] = (node.plan.name, {ep: set(agents) for ep, agents in node.succeeded.items()})

    def members(self, parent: PlanNode | None) -> tuple[str, ...]:
        """Alive agents believed to be in ``parent``'s state (all alive agents for the root), sorted."""
        me = self.ctx.name
        alive = self.ctx.team.alive()
        if parent is None:
            return alive
        believed, state = parent.believed, parent.state
        return tuple(a for a in alive if a == me or (believed.get(a) or (None, None))[1] == state)

    def _summand_fn(
        self, node_env: Mapping[str, object], context: PlanNode | None
    ) -> Callable[[Plan, Summand, str, EntryPoint], float]:
        ctx = self.ctx
        pins = self.generated.pins

        def summand(plan: Plan, term: Summand, agent: str, ep: EntryPoint) -> float:
            pinned = pins.get(plan.name)
            if pinned and ep.name in pinned and agent not in pinned[ep.name]:
                return -1.0  # a generated task only some robots can start
            env = dict(node_env)
            env.update({"self": agent, "task": ep.task, "entry": ep.name})
            belief = ctx.belief.at(context) if context is not None else ctx.belief
            try:
                value = ctx.formulas.value(term.expression, belief, env)
            except AlicaError as exc:
                ctx.emit("warning", formula=term.expression, message=str(exc))
                return 0.0
            return float(value)  # type: ignore[arg-type]

        return summand

    def _problem(
        self,
        agents: tuple[str, ...],
        plans: tuple[Plan, ...],
        successes: Mapping[str, Mapping[str, int]],
        old: Assignment | None,
        env: Mapping[str, object],
        context: PlanNode | None,
    ) -> AllocationProblem:
        roles = self.ctx.team.roles
        needs_summands = any(p.utility.summands for p in plans)
        return AllocationProblem(
            agents=agents,
            roles={a: roles[a] for a in agents},
            roleset=self.generated.roleset,
            plans=plans,
            successes=successes,
            old=old,
            summand=self._summand_fn(env, context) if needs_summands else None,
            allow_idle=self.ctx.config.allow_idle,
        )

    def start(self, slot: Slot | None, plans: tuple[Plan, ...], env: dict[str, object], now: float) -> PlanNode | None:
        """Allocate the agents of ``slot``'s state (the team, for the root) to one of ``plans`` and start it.

        Returns:
            The new plan node, or ``None`` when there is no valid assignment (``slot.reason`` says why).
        """
        ctx = self.ctx
        me = ctx.name
        parent = slot.parent if slot is not None else None
        key: PlanKey = (*slot.parent.key, slot.parent.state or "", slot.name) if slot is not None else (plans[0].name,)
        members = self.members(parent)
        # Teammates already in this plan keep their entry points (their claims trump predictions).
        fixed: dict[str, tuple[str | None, str | None]] = {}
        successes: dict[str, dict[str, int]] = {}
        names = {p.name for p in plans}
        chosen: str | None = None
        for agent in members:
            claim = ctx.team.claim(agent, key) if agent != me else None
            if claim is not None and claim.plan in names and (chosen is None or claim.plan == chosen):
                chosen = claim.plan
                fixed[agent] = (claim.entry, claim.state)
                # the teammate fills its entry point, and the tasks it already did count as done: a
                # plan restarted while a teammate's task succeeded does not wait for that task again
                counts = successes.setdefault(claim.plan, {})
                for ep in sorted({*claim.success, *((claim.entry,) if claim.entry is not None else ())}):
                    counts[ep] = counts.get(ep, 0) + 1
        if chosen is not None:
            plans = tuple(p for p in plans if p.name == chosen)
        # what this agent knew had succeeded in the instance before it restarted for want of agents
        carried = self.carried.get(key)
        if carried is not None and carried[0] in {p.name for p in plans}:
            counts = successes.setdefault(carried[0], {})
            for ep, done in sorted(carried[1].items()):
                if me in done:
                    counts[ep] = counts.get(ep, 0) + 1
        agents = tuple(a for a in members if a not in fixed)
        result = allocate(self._problem(agents, plans, successes, None, env, parent))
        ctx.count("allocations")
        assignment = result.assignment
        if assignment is None:
            if self._unallocated.get(key) != result.why:
                self._unallocated[key] = result.why
                ctx.emit("allocation", key="/".join(key), outcome="none", why=result.why)
            if slot is not None:
                slot.reason = f"no valid assignment: {result.why}"
            return None
        self._unallocated.pop(key, None)
        plan = self.nodes.plan(assignment.plan)
        node = self.nodes.new_node(key, slot, plan, env, now)
        carried = self.carried.pop(key, None)
        if carried is not None and carried[0] == plan.name:
            for ep, done in carried[1].items():
                node.succeeded.setdefault(ep, set()).update(done)
        for agent, entry in fixed.items():
            node.believed[agent] = entry
        for agent, ep in assignment.entries:
            if agent != me:
                node.believed[agent] = (ep, plan.entry_point(ep).state if ep is not None else None)
                node.predicted_at[agent] = now
        ctx.emit(
            "allocation",
            key=node.key_text,
            plan=plan.name,
            reason="initial",
            utility=round(assignment.utility, 9),
            entries=assignment.as_dict(),
        )
        node.set_entry(assignment.entry_of(me), now)
        return node

    def reallocate(self, node: PlanNode, now: float) -> None:
        """The dynamic allocation rule, then the reuse of agents whose task succeeded."""
        if node.status is not ChildStatus.RUNNING or now < node.overridden_until:
            return
        self._reallocate(node, now)
        if node.status is ChildStatus.RUNNING:
            self._reuse_succeeded(node, now)

    def _reuse_succeeded(self, node: PlanNode, now: float) -> None:
        """Agents whose task succeeded take another entry point of the plan (the C++ engine's ``runMultiAgentPlan``).

        Every agent computes this from the same view, like any allocation: the
        free agents (in success states) are allocated, by the same utility,
        first to the success-required entry points that still need a success
        and have nobody working on them, then to any entry point with room left
        (its ``max`` less the agents that succeeded or work there, e.g. an idle
        task with min 0). An agent never goes back to an entry point in which it
        succeeded, and an agent whose success state runs children (a guard, say:
        the C++ engine's terminal states run none) stays there for the latter;
        with no room anywhere it stays in its success state.
        """
        plan = node.plan
        successes = node.successes()
        free: list[str] = []
        working: dict[str, int] = {}
        for agent in node.members():
            entry = node.believed.get(agent)
            if entry is None or entry[1] is None:
                continue
            kind = plan.state(entry[1]).kind
            if kind is StateKind.SUCCESS:
                free.append(agent)
            elif kind is StateKind.NORMAL and entry[0] is not None:
                working[entry[0]] = working.get(entry[0], 0) + 1
        if not free:
            return
        needy = tuple(
            replace(ep, min=0, max=max(1, ep.max - successes.get(ep.name, 0)))
            for ep in plan.entry_points
            if ep.success_required and successes.get(ep.name, 0) < max(ep.min, 1) and ep.name not in working
        )
        moves = self._place(node, tuple(free), needy)
        for _, ep in moves:
            working[ep] = working.get(ep, 0) + 1
        placed = {a for a, _ in moves}
        for agent in free:
            entry = node.believed[agent]
            if agent in placed or (entry[1] is not None and plan.state(entry[1]).children):
                continue  # a success state that runs children keeps its agent busy (C++ terminal states have none)
            roomy = tuple(
                replace(ep, min=0, max=room)
                for ep in plan.entry_points
                if agent not in node.succeeded.get(ep.name, ())
                and (room := ep.max - successes.get(ep.name, 0) - working.get(ep.name, 0)) > 0
            )
            move = self._place(node, (agent,), roomy)
            for _, ep in move:
                working[ep] = working.get(ep, 0) + 1
            moves += move
        if not moves:
            return
        moves = tuple(sorted(moves))
        self.ctx.emit("allocation", key=node.key_text, plan=plan.name, reason="reuse", entries=dict(moves))
        node.apply(Assignment(plan.name, moves, 0.0), now, "reuse")

    def _place(
        self, node: PlanNode, agents: tuple[str, ...], entries: tuple[EntryPoint, ...]
    ) -> tuple[tuple[str, str], ...]:
        """The best moves of ``agents`` to ``entries`` by the plan's utility (an agent may also stay)."""
        if not agents or not entries:
            return ()
        reduced = replace(node.plan, entry_points=entries)
        context = node.slot.parent if node.slot else None
        best = allocate(self._problem(agents, (reduced,), {}, None, node.env, context)).assignment
        if best is None:
            return ()
        return tuple((a, ep) for a, ep in best.entries if ep is not None)

    def _reallocate(self, node: PlanNode, now: float) -> None:
        ctx = self.ctx
        plan = node.plan
        members = node.members()
        current: dict[str, str | None] = {}
        agents = []
        for agent in members:
            entry = node.believed.get(agent)
            if entry is not None and entry[1] is not None and plan.state(entry[1]).terminal:
                continue  # done here: counted in the successes
            agents.append(agent)
            current[agent] = entry[0] if entry is not None else None
        agents_t = tuple(agents)
        # a plan whose run-time condition fails scores -1: the child takes an alternative of its
        # plan type whose conditions hold, if any (else the abort rule fails the plan)
        runs = plan.run is None or ctx.formulas.holds(plan.run.text, ctx.belief.at(node), node.env)
        plans: tuple[Plan, ...] = (
            (plan,) if node.slot is None else node.slot.startable(node.slot.candidates(), keep=plan if runs else None)
        )
        if runs and plan not in plans:
            plans = (plan, *plans)
        if not plans:
            return
        successes = {plan.name: node.successes()}
        old = Assignment(plan.name, tuple(sorted(current.items())), 0.0)
        problem = self._problem(agents_t, plans, successes, old, node.env, node.slot.parent if node.slot else None)
        now_utility = (utility(problem, plan, current) if agents_t else 0.0) if runs else -1.0
        result = allocate(problem)
        ctx.count("allocations")
        best = result.assignment
        if best is None:
            if runs and now_utility <= -1:
                node.understaffed = True
                node.fail(f"no valid assignment any more: {result.why}")
            return
        gain = best.utility - now_utility
        if now_utility > -1 and gain <= plan.utility.threshold:
            return
        same = best.plan == plan.name and all(best.entry_of(a) == current[a] for a in agents_t)
        if same:
            return
        ctx.emit(
            "allocation",
            key=node.key_text,
            plan=best.plan,
            reason="utility",
            utility=round(best.utility, 9),
            previous=round(now_utility, 9),
            entries=best.as_dict(),
        )
        if best.plan != plan.name and node.slot is not None:
            slot = node.slot
            node.stop()
            slot.node = None
            slot.start(now, only=self.nodes.plan(best.plan))
            return
        node.apply(best, now, "utility")
        self._check_conflicts(node, now)

    def _check_conflicts(self, node: PlanNode, now: float) -> None:
        ctx = self.ctx
        config = ctx.config
        contested = node.conflicts(now, config.cycle_window) >= config.cycle_count
        if not contested:
            contested = any(
                (c := ctx.team.claim(a, node.key)) is not None and c.contested for a in node.members() if a != ctx.name
            )
        if not contested or now < node.authority_until:
            return
        if node.members()[0] == ctx.name:
            window = (
                config.authority_min
                if node.authority_window == 0
                else min(config.authority_max, node.authority_window * config.authority_growth)
            )
            node.authority_window = window
            node.authority_until = now + window
            node.history.clear()
            ctx.emit(
                "authority",
                key=node.key_text,
                window=window,
                entries=dict(sorted((a, e[0]) for a, e in node.believed.items())),
            )
            self.nodes.changed()
        else:
            node.contested_until = now + config.authority_min
            self.nodes.changed()

    def apply_authority(self, now: float) -> None:
        """Adopt the assignments that lower agents impose by authority on plans this agent runs."""
        ctx = self.ctx
        for sender, claim in ctx.team.authority_claims():
            if sender >= ctx.name or claim.until <= now:
                continue
            node = self.nodes.get(claim.key)
            if node is None or node.plan.name != claim.plan or node.status is not ChildStatus.RUNNING:
                continue
            node.overridden_until = claim.until
            entries = dict(claim.entries)
            if ctx.name not in entries:
                continue
            if all(node.believed.get(a, (None, None))[0] == ep for a, ep in entries.items()):
                continue
            ctx.emit("allocation", key=node.key_text, plan=claim.plan, reason="authority", by=sender, entries=entries)
            node.apply(Assignment(claim.plan, tuple(sorted(entries.items())), 0.0), now, "authority")
