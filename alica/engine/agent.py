"""One agent's engine: its plan tree, its team view, its messages, in step mode.

The engine never sleeps and never reads the wall clock: the caller ticks it
(:meth:`AgentEngine.tick`, or :meth:`receive` then :meth:`step` when a team
is ticked in lock step) and the injected clock says what time it is.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

from alica.allocation import AllocationProblem, Assignment, allocate, utility
from alica.clock import Clock
from alica.comm import QoS, Transport
from alica.engine.behaviours import BehaviourRunner, SkillBinder, SkillContext
from alica.engine.belief import AgentBelief
from alica.engine.conditions import Formulas
from alica.engine.config import EngineConfig
from alica.engine.node import PlanNode
from alica.engine.shared import PLAN_TOPIC, PlanBoard
from alica.engine.slot import Slot
from alica.engine.status import ChildStatus
from alica.engine.sync import SyncProcess, SyncTalk
from alica.engine.team import SYNC_TOPIC, TEAM_TOPIC, WORLD_TOPIC, AuthorityClaim, PlanKey, TeamMessage, TeamView
from alica.errors import AlicaError
from alica.lang import FactBase, Registry
from alica.model import Behaviour, Plan, PlanLibrary, RoleSet, StateKind, Summand, Transition
from alica.model.plan import EntryPoint

Observer = Callable[[dict[str, Any]], None]
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _substitute(text: str, env: Mapping[str, object]) -> str:
    """``text`` with the names of ``env``'s string (and number) variables replaced by their values."""

    def value(match: re.Match[str]) -> str:
        found = env.get(match.group(0))
        return str(found) if isinstance(found, (str, int, float)) and not isinstance(found, bool) else match.group(0)

    return _NAME.sub(value, text)


class AgentEngine:
    """The ALICA engine of one agent.

    Args:
        name: the agent's name (its id; the lowest name has authority in conflicts).
        roster: every team member and its role, this agent included.
        library: the plan library.
        plan: the root plan's name.
        roleset: the role set whose priorities drive allocation.
        transport: the agent's link to its team.
        world_model: the agent's replica of the shared world model.
        clock: the time source.
        config: engine settings.
        skills: finds the implementation of each behaviour's skill.
        registry: predicates and functions for formulas (the built-ins when None).
        seed: seeds the agent's random generator (handed to skills).
        observers: called with every trace event.
        world: the robot interface handed to skills.
        listen_first: seconds to listen to the team before the first allocation; an
            agent (re)joining a running team uses it to learn its teammates' claims
            first, so it does not take a task that is already taken.
    """

    def __init__(
        self,
        name: str,
        roster: Mapping[str, str],
        library: PlanLibrary,
        plan: str,
        roleset: RoleSet,
        transport: Transport,
        world_model: Any,
        clock: Clock,
        config: EngineConfig | None = None,
        skills: SkillBinder | None = None,
        registry: Registry | None = None,
        seed: int = 0,
        observers: tuple[Observer, ...] = (),
        world: object | None = None,
        listen_first: float = 0.0,
    ) -> None:
        if plan not in library.plans:
            raise AlicaError(f"no plan named '{plan}' to run; plans: {', '.join(sorted(library.plans))}")
        self.name = name
        self.role = roster[name]
        self.library = library
        self.root_plan = library.plans[plan]
        self.base_roleset = roleset
        self.roleset = roleset
        self.plan_board = PlanBoard()
        self.problem_overrides: dict[str, dict[str, str]] = {}
        self.transport = transport
        self.world_model = world_model
        self.clock = clock
        self.now = clock.now
        self.config = config or EngineConfig()
        self.skills = skills or SkillBinder()
        self.observers = list(observers)
        self.world = world
        self.rng = random.Random(f"{seed}:{name}")
        self.start_at = clock.now() + listen_first
        self.formulas = Formulas(registry, on_error=self._formula_error)
        self.team = TeamView(name, roster, self.now(), self.config.team_timeout)
        self.own = FactBase()
        self.belief = AgentBelief(name, world_model, self.team, self.own, self.now)
        self.index: dict[PlanKey, PlanNode] = {}
        self.root: PlanNode | None = None
        self.root_failures = 0
        self.syncs: dict[tuple[PlanKey, str], SyncProcess] = {}
        self._transitions: dict[tuple[str, str], tuple[Transition, ...]] = {}
        self._tree_changed = True
        self._last_broadcast = float("-inf")
        self.stats = {
            "ticks": 0,
            "transitions": 0,
            "allocations": 0,
            "messages_in": 0,
            "messages_out": 0,
            "repairs": 0,
            "replans": 0,
        }
        for topic in (TEAM_TOPIC, SYNC_TOPIC, WORLD_TOPIC, PLAN_TOPIC):
            transport.subscribe(topic)
        self._world_changed = False
        self._refresh = getattr(world_model, "refresh", None)
        if hasattr(world_model, "on_change"):
            world_model.on_change(self._on_world_change)

    def _on_world_change(self, keys: object) -> None:
        self._world_changed = True

    # -- the tick ---------------------------------------------------------

    def tick(self) -> None:
        """One engine cycle: take in messages, then :meth:`step`."""
        self.receive()
        self.step()

    @property
    def done(self) -> bool:
        """Whether the root plan succeeded or finally failed."""
        return self.root is not None and self.root.status is not ChildStatus.RUNNING

    def receive(self) -> None:
        """Take in every message delivered by now."""
        now = self.now()
        authority = False
        for envelope in self.transport.poll():
            self.stats["messages_in"] += 1
            topic = envelope.topic
            payload = envelope.payload
            if topic == TEAM_TOPIC:
                changed, revived = self.team.integrate(payload, now)
                if revived:
                    self.emit("team", change="back", who=payload.sender)
                    self._invalidate_all()
                    self._publish(WORLD_TOPIC, self.world_model.snapshot(), QoS.RELIABLE)
                for key in changed:
                    node = self.index.get(key)
                    if node is not None:
                        node.invalidate()
                authority = authority or bool(payload.authority)
            elif topic == SYNC_TOPIC:
                self._receive_sync(payload, now)
            elif topic == WORLD_TOPIC:
                self.world_model.merge(payload)
            elif topic == PLAN_TOPIC:
                self.plan_board.receive(payload, now)
        if authority:
            self._apply_authority(now)

    def step(self) -> None:
        """Rules, then behaviours, then messages (see :mod:`alica.engine.node`)."""
        now = self.now()
        self.stats["ticks"] += 1
        lost = self.team.update(now)
        if lost:
            for who in lost:
                self.emit("team", change="lost", who=who)
            self._invalidate_all()
        if self._refresh is not None:
            self._refresh()  # values whose time to live ran out
        if self._world_changed:
            # utilities with summands read the world: allocate those plans again
            self._world_changed = False
            for node in self.index.values():
                if node.plan.utility.summands:
                    node.invalidate()
        if self.root is None and now >= self.start_at:
            self._start_root(now)
        root = self.root
        if root is not None and root.status is ChildStatus.RUNNING:
            root.visit(now)
            if root.status is ChildStatus.FAILURE:
                self._root_failed(root, now)
        if self.root is not None:
            self._tick_behaviours(self.root, now)
        self._broadcast(now)
        self._talk_syncs(now)
        delta = self.world_model.take_delta()
        if delta is not None:
            self._publish(WORLD_TOPIC, delta, QoS.RELIABLE)

    def _start_root(self, now: float) -> None:
        node = self._allocate_new(None, (self.root_plan,), (self.root_plan.name,), {"self": self.name}, now)
        if node is not None:
            self.root = node

    def _root_failed(self, root: PlanNode, now: float) -> None:
        self.root_failures += 1
        if self.root_failures == 1:
            self.emit("repair", key=root.key_text, stage="retry", plan=root.plan.name, reason=root.reason)
            root.stop()
            self.root = None
            self._start_root(now)
        else:
            self.emit("repair", key=root.key_text, stage="propagate", plan=root.plan.name, reason=root.reason)
            root.stop()

    def _tick_behaviours(self, node: PlanNode, now: float) -> None:
        belief = self.belief
        for slot in node.slots:
            runner = slot.runner
            if runner is not None:
                belief.node = node
                before = runner.status
                status = runner.tick(belief, self.formulas, slot.env, now)
                if status is not before:
                    slot.status = status
                    slot.reason = runner.reason
                    self.emit(
                        "behaviour", key=node.key_text, behaviour=slot.name, status=status.value, reason=runner.reason
                    )
            elif slot.node is not None:
                self._tick_behaviours(slot.node, now)

    # -- services for plan nodes -------------------------------------------

    def plan_named(self, name: str) -> Plan:
        """A plan of the library, or one generated at run time by a planning problem."""
        plan = self.library.plans.get(name)
        return plan if plan is not None else self.plan_board.plans[name]

    def register_generated(
        self, plan: Plan, roleset: RoleSet, pins: Mapping[str, tuple[str, ...]] | None = None
    ) -> None:
        """Make a generated plan allocatable.

        Args:
            plan: the plan.
            roleset: holds the priorities of its tasks.
            pins: entry point -> the only agents that may take it (others are vetoed).
        """
        tasks = {ep.task for ep in plan.entry_points}
        priorities = {role.name: tuple(p for p in role.priorities if p.task in tasks) for role in roleset.roles}
        self.plan_board.register(plan, priorities, pins or {})
        self.roleset = self.plan_board.roleset(self.base_roleset)

    def unregister_generated(self, name: str) -> None:
        """Forget a generated plan that was replaced."""
        self.plan_board.unregister(name)
        self.roleset = self.plan_board.roleset(self.base_roleset)

    def publish_plan(self, payload: object) -> None:
        """Send a plan share or a replan request to the team (reliable)."""
        self._publish(PLAN_TOPIC, payload, QoS.RELIABLE)

    def set_problem(self, name: str, goal: str | None = None, world: str | None = None) -> None:
        """The operator sets the goal and/or the world of planning problem ``name`` (the leader replans).

        Raises:
            AlicaError: no planning problem has that name.
        """
        if name not in self.library.problems:
            raise AlicaError(
                f"no planning problem named '{name}'; problems: {', '.join(sorted(self.library.problems)) or 'none'}"
            )
        override = dict(self.problem_overrides.get(name, {}))
        if goal is not None:
            override["goal"] = goal
        if world is not None:
            override["world"] = world
        self.problem_overrides[name] = override

    def belief_for(self, node: PlanNode) -> AgentBelief:
        """The belief base, looking at ``node``'s context."""
        self.belief.node = node
        return self.belief

    def out_transitions(self, plan: Plan, state: str) -> tuple[Transition, ...]:
        """Transitions leaving ``state`` (cached)."""
        key = (plan.name, state)
        hit = self._transitions.get(key)
        if hit is None:
            hit = self._transitions[key] = plan.out_transitions(state)
        return hit

    def tree_changed(self) -> None:
        """The plan tree changed: tell the team soon."""
        self._tree_changed = True

    def forget(self, node: PlanNode) -> None:
        """A plan node stopped."""
        if self.index.get(node.key) is node:
            del self.index[node.key]
        self._tree_changed = True

    def bind(self, node: PlanNode, ref: Any) -> dict[str, object]:
        """The variables of a child: its bindings evaluated in the parent's context.

        A binding whose value is not known yet (``pos(a)`` before ``a`` is seen)
        is handed on as its text, for the skill to resolve later, with the
        parent's variables replaced by their values (``pos(x)`` with ``x = a``
        becomes ``pos(a)``).
        """
        env: dict[str, object] = {"self": self.name}
        if not ref.bindings:
            return env
        belief = self.belief_for(node)
        for binding in ref.bindings:
            try:
                env[binding.variable] = self.formulas.value(binding.value, belief, node.env)
            except AlicaError:
                env[binding.variable] = _substitute(binding.value, node.env)
        return env

    def make_runner(self, slot: Slot) -> BehaviourRunner:
        """The runner of a behaviour child, with its parameters bound."""
        behaviour = slot.element
        assert isinstance(behaviour, Behaviour)
        params: dict[str, object] = {}
        for param in behaviour.params:
            variable = param.variable
            params[param.name] = slot.env.get(variable, param.value) if variable else param.value
        path = f"{slot.parent.key_text}/{slot.parent.state}/{behaviour.name}"
        context = SkillContext(
            self.name, self.now, self.world_model, self.belief, self.rng, self.world, behaviour, path
        )
        try:
            factory = self.skills.factory(behaviour)
        except AlicaError as exc:
            message = str(exc)

            def factory(name: str, params: Mapping[str, object], context: SkillContext) -> Any:
                raise AlicaError(message)

        return BehaviourRunner(behaviour, params, factory, context)

    def sync_process(self, node: PlanNode, name: str) -> SyncProcess:
        """This agent's process of synchronisation ``name`` in ``node``."""
        key = (node.key, name)
        process = self.syncs.get(key)
        if process is None:
            sync = next(s for s in node.plan.synchronisations if s.name == name)
            expiry = max(4 * sync.talk_timeout, 4 * self.config.period)
            process = self.syncs[key] = SyncProcess(self.name, node.key, sync, expiry)
        return process

    def drop_syncs(self, node: PlanNode) -> None:
        """The agent left ``node``'s state: forget its synchronisations."""
        for key in [k for k in self.syncs if k[0] == node.key]:
            del self.syncs[key]

    def _receive_sync(self, talk: SyncTalk, now: float) -> None:
        node = self.index.get(talk.key)
        if node is None or not any(s.name == talk.sync for s in node.plan.synchronisations):
            return
        self.sync_process(node, talk.sync).receive(talk, now)

    def _talk_syncs(self, now: float) -> None:
        for process in list(self.syncs.values()):
            process.expire(now)
            talk = process.talk(now)
            if talk is not None:
                self._publish(SYNC_TOPIC, talk, QoS.BEST_EFFORT)

    # -- allocation -----------------------------------------------------

    def _summand_fn(
        self, node_env: Mapping[str, object], context: PlanNode | None
    ) -> Callable[[Plan, Summand, str, EntryPoint], float]:
        pins = self.plan_board.pins

        def summand(plan: Plan, term: Summand, agent: str, ep: EntryPoint) -> float:
            pinned = pins.get(plan.name)
            if pinned and ep.name in pinned and agent not in pinned[ep.name]:
                return -1.0  # a generated task only some robots can start (alica.prophet.tasks)
            env = dict(node_env)
            env.update({"self": agent, "task": ep.task, "entry": ep.name})
            if context is not None:
                self.belief.node = context
            try:
                value = self.formulas.value(term.expression, self.belief, env)
            except AlicaError as exc:
                self._formula_error(term.expression, str(exc))
                return 0.0
            return float(value)  # type: ignore[arg-type]

        return summand

    def members_of(self, parent: PlanNode | None) -> tuple[str, ...]:
        """Alive agents believed to be in ``parent``'s state (all alive agents for the root), sorted."""
        alive = self.team.alive()
        if parent is None:
            return alive
        believed, state = parent.believed, parent.state
        return tuple(a for a in alive if a == self.name or (believed.get(a) or (None, None))[1] == state)

    def _problem(
        self,
        agents: tuple[str, ...],
        plans: tuple[Plan, ...],
        successes: Mapping[str, Mapping[str, int]],
        old: Assignment | None,
        env: Mapping[str, object],
        context: PlanNode | None,
    ) -> AllocationProblem:
        roles = self.team.roles
        needs_summands = any(p.utility.summands for p in plans)
        return AllocationProblem(
            agents=agents,
            roles={a: roles[a] for a in agents},
            roleset=self.roleset,
            plans=plans,
            successes=successes,
            old=old,
            summand=self._summand_fn(env, context) if needs_summands else None,
            allow_idle=self.config.allow_idle,
        )

    def start_plan(self, slot: Slot, plans: tuple[Plan, ...], now: float) -> PlanNode | None:
        """Allocate the agents of ``slot``'s state to one of ``plans`` and start it (the allocation rule)."""
        key = (*slot.parent.key, slot.parent.state or "", slot.name)
        return self._allocate_new(slot, plans, key, slot.env, now)

    def _allocate_new(
        self, slot: Slot | None, plans: tuple[Plan, ...], key: PlanKey, env: dict[str, object], now: float
    ) -> PlanNode | None:
        parent = slot.parent if slot is not None else None
        members = self.members_of(parent)
        # Teammates already in this plan keep their entry points (their claims trump predictions).
        fixed: dict[str, tuple[str | None, str | None]] = {}
        successes: dict[str, dict[str, int]] = {}
        names = {p.name for p in plans}
        chosen: str | None = None
        for agent in members:
            claim = self.team.claim(agent, key) if agent != self.name else None
            if claim is not None and claim.plan in names and (chosen is None or claim.plan == chosen):
                chosen = claim.plan
                fixed[agent] = (claim.entry, claim.state)
                counts = successes.setdefault(claim.plan, {})
                if claim.entry is not None:
                    counts[claim.entry] = counts.get(claim.entry, 0) + 1
        if chosen is not None:
            plans = tuple(p for p in plans if p.name == chosen)
        agents = tuple(a for a in members if a not in fixed)
        result = allocate(self._problem(agents, plans, successes, None, env, parent))
        self.stats["allocations"] += 1
        assignment = result.assignment
        if assignment is None:
            self.emit("allocation", key="/".join(key), outcome="none", why=result.why)
            if slot is not None:
                slot.reason = f"no valid assignment: {result.why}"
            return None
        plan = self.plan_named(assignment.plan)
        node = PlanNode(self, key, slot, plan, env, now)
        self.index[key] = node
        for agent, entry in fixed.items():
            node.believed[agent] = entry
        for agent, ep in assignment.entries:
            if agent != self.name:
                node.believed[agent] = (ep, plan.entry_point(ep).state if ep is not None else None)
                node.predicted_at[agent] = now
        self.emit(
            "allocation",
            key=node.key_text,
            plan=plan.name,
            reason="initial",
            utility=round(assignment.utility, 9),
            entries=assignment.as_dict(),
        )
        node.set_entry(assignment.entry_of(self.name), now)
        return node

    def reallocate(self, node: PlanNode, now: float) -> None:
        """The dynamic allocation rule, then the reuse of agents whose task succeeded."""
        if node.status is not ChildStatus.RUNNING or now < node.overridden_until:
            return
        self._reallocate(node, now)
        if node.status is ChildStatus.RUNNING:
            self._reuse_succeeded(node, now)

    def _reuse_succeeded(self, node: PlanNode, now: float) -> None:
        """Agents whose task succeeded take success-required tasks nobody has done or is doing.

        Every agent computes this from the same view, like any allocation: the
        free agents (in success states) are allocated, by the same utility, to
        the entry points that need a success and have nobody working on them.
        """
        plan = node.plan
        successes = node.successes()
        free, busy = [], set()
        for agent in node.members():
            entry = node.believed.get(agent)
            if entry is None or entry[1] is None:
                continue
            kind = plan.state(entry[1]).kind
            if kind is StateKind.SUCCESS:
                free.append(agent)
            elif kind is StateKind.NORMAL and entry[0] is not None:
                busy.add(entry[0])
        if not free:
            return
        needy = tuple(
            replace(ep, min=0, max=max(1, ep.max - successes.get(ep.name, 0)))
            for ep in plan.entry_points
            if ep.success_required and successes.get(ep.name, 0) < max(ep.min, 1) and ep.name not in busy
        )
        if not needy:
            return
        reduced = replace(plan, entry_points=needy)
        result = allocate(
            self._problem(tuple(free), (reduced,), {}, None, node.env, node.slot.parent if node.slot else None)
        )
        best = result.assignment
        if best is None or all(ep is None for _, ep in best.entries):
            return
        moves = tuple((a, ep) for a, ep in best.entries if ep is not None)
        self.emit("allocation", key=node.key_text, plan=plan.name, reason="reuse", entries=dict(moves))
        node.apply(Assignment(plan.name, moves, best.utility), now, "reuse")

    def _reallocate(self, node: PlanNode, now: float) -> None:
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
        plans: tuple[Plan, ...] = (
            (plan,) if node.slot is None else node.slot.startable(node.slot.candidates(), keep=plan)
        )
        if plan not in plans:
            plans = (plan, *plans)
        successes = {plan.name: node.successes()}
        old = Assignment(plan.name, tuple(sorted(current.items())), 0.0)
        problem = self._problem(agents_t, plans, successes, old, node.env, node.slot.parent if node.slot else None)
        now_utility = utility(problem, plan, current) if agents_t else 0.0
        result = allocate(problem)
        self.stats["allocations"] += 1
        best = result.assignment
        if best is None:
            if now_utility <= -1:
                node.fail(f"no valid assignment any more: {result.why}")
            return
        gain = best.utility - now_utility
        if now_utility > -1 and gain <= plan.utility.threshold:
            return
        same = best.plan == plan.name and all(best.entry_of(a) == current[a] for a in agents_t)
        if same:
            return
        self.emit(
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
            slot.start(now, only=self.plan_named(best.plan))
            return
        node.apply(best, now, "utility")
        self._check_conflicts(node, now)

    def _check_conflicts(self, node: PlanNode, now: float) -> None:
        config = self.config
        contested = node.conflicts(now, config.cycle_window) >= config.cycle_count
        if not contested:
            contested = any(
                (c := self.team.claim(a, node.key)) is not None and c.contested
                for a in node.members()
                if a != self.name
            )
        if not contested or now < node.authority_until:
            return
        if node.members()[0] == self.name:
            window = (
                config.authority_min
                if node.authority_window == 0
                else min(config.authority_max, node.authority_window * config.authority_growth)
            )
            node.authority_window = window
            node.authority_until = now + window
            node.history.clear()
            self.emit(
                "authority",
                key=node.key_text,
                window=window,
                entries=dict(sorted((a, e[0]) for a, e in node.believed.items())),
            )
            self.tree_changed()
        else:
            node.contested_until = now + config.authority_min
            self.tree_changed()

    def _apply_authority(self, now: float) -> None:
        for sender, claim in self.team.authority_claims():
            if sender >= self.name or claim.until <= now:
                continue
            node = self.index.get(claim.key)
            if node is None or node.plan.name != claim.plan or node.status is not ChildStatus.RUNNING:
                continue
            node.overridden_until = claim.until
            entries = dict(claim.entries)
            if self.name not in entries:
                continue
            if all(node.believed.get(a, (None, None))[0] == ep for a, ep in entries.items()):
                continue
            self.emit("allocation", key=node.key_text, plan=claim.plan, reason="authority", by=sender, entries=entries)
            node.apply(Assignment(claim.plan, tuple(sorted(entries.items())), 0.0), now, "authority")

    def _invalidate_all(self) -> None:
        for node in self.index.values():
            node.invalidate()

    # -- messages -----------------------------------------------------------

    def _publish(self, topic: str, payload: object, qos: QoS) -> None:
        self.transport.publish(topic, payload, qos)
        self.stats["messages_out"] += 1

    def claims(self) -> list[Any]:
        """This agent's claims, root first."""
        out = []
        todo = [self.root] if self.root is not None else []
        while todo:
            node = todo.pop()
            if node.status is not ChildStatus.FAILURE:
                out.append(node.claim())
            todo.extend(reversed([s.node for s in node.slots if s.node is not None]))
        return out

    def _broadcast(self, now: float) -> None:
        config = self.config
        since = now - self._last_broadcast + 1e-9  # ticks land on the interval up to rounding
        if not ((self._tree_changed and since >= config.min_broadcast_gap) or since >= config.broadcast_interval):
            return
        self._tree_changed = False
        self._last_broadcast = now
        authority = tuple(
            AuthorityClaim(
                n.key, n.plan.name, tuple(sorted((a, e[0]) for a, e in n.believed.items())), n.authority_until
            )
            for n in self.index.values()
            if n.authority_until > now
        )
        self._publish(
            TEAM_TOPIC, TeamMessage(self.name, now, self.role, tuple(self.claims()), authority), QoS.BEST_EFFORT
        )

    # -- trace --------------------------------------------------------------

    def emit(self, event: str, **fields: Any) -> None:
        """Send a trace event to the observers."""
        if event == "transition":
            self.stats["transitions"] += 1
        elif event == "repair":
            self.stats["repairs"] += 1
        if not self.observers:
            return
        record = {"t": round(self.now(), 6), "agent": self.name, "event": event, **fields}
        for observer in self.observers:
            observer(record)

    def _formula_error(self, text: str, message: str) -> None:
        self.emit("warning", formula=text, message=message)
