"""One agent's engine: its plan tree, its team view, its messages, in step mode.

The engine never sleeps and never reads the wall clock: the caller ticks it
(:meth:`AgentEngine.tick`, or :meth:`receive` then :meth:`step` when a team
is ticked in lock step) and the injected clock says what time it is.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from alica.clock import Clock
from alica.comm import QoS, Transport
from alica.engine.allocate import Allocator
from alica.engine.behaviours import BehaviourRunner, SkillBinder, SkillContext
from alica.engine.belief import AgentBelief
from alica.engine.child import ChildFactory, PlanDecision
from alica.engine.conditions import Formulas
from alica.engine.config import EngineConfig
from alica.engine.generated import GeneratedPlans
from alica.engine.hosting import Children
from alica.engine.node import PlanNode
from alica.engine.slot import Repairs, Slot
from alica.engine.solving import Solving, binding_names
from alica.engine.status import ChildStatus
from alica.engine.sync import SyncProcess, SyncTalk
from alica.engine.team import (
    SYNC_TOPIC,
    TEAM_TOPIC,
    WORLD_TOPIC,
    AuthorityClaim,
    Claim,
    PlanKey,
    TeamMessage,
    TeamView,
)
from alica.errors import AlicaError
from alica.lang import FactBase, Registry
from alica.model import Behaviour, ChildRef, Plan, PlanLibrary, RoleSet, Transition
from alica.worldmodel import Delta, ReplicaLike

Observer = Callable[[dict[str, Any]], None]
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _substitute(text: str, env: Mapping[str, object]) -> str:
    """``text`` with the names of ``env``'s string (and number) variables replaced by their values."""

    def value(match: re.Match[str]) -> str:
        found = env.get(match.group(0))
        return str(found) if isinstance(found, (str, int, float)) and not isinstance(found, bool) else match.group(0)

    return _NAME.sub(value, text)


@dataclass(slots=True)
class _Left:
    """A success claimed for a plan instance the agent left, while its parent stays where it moved on to."""

    claim: Claim
    parent: PlanNode
    entered: float | None = None


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
        world_model: ReplicaLike,
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
        self.generated = GeneratedPlans(roleset)
        self.overrides: dict[str, dict[str, str]] = {}
        self.decisions: dict[str, list[tuple[int, PlanDecision]]] = {}
        """Planning problem -> the operator's decisions on its proposed plans, ``(generation, decision)``, in order."""
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
        self.formulas = Formulas(registry, on_error=self.formula_error)
        self.team = TeamView(name, roster, self.now(), self.config.team_timeout)
        self.own = FactBase()
        self.belief = AgentBelief(name, world_model, self.team, self.own, self.now)
        self.index: dict[PlanKey, PlanNode] = {}
        self.root: PlanNode | None = None
        self.root_repairs = Repairs()
        self._failed_root: PlanNode | None = None
        self._next_root_try = float("-inf")
        self.left: dict[PlanKey, _Left] = {}
        """Plan instances this agent left after its task succeeded there: still claimed (no entry point,
        the successes) while the parent stays in the state it moved on to, so a teammate learns the success
        even when the parent moved on in the step the task succeeded."""
        self.carried: dict[PlanKey, tuple[str, dict[str, set[str]]]] = {}
        """Plan instances restarted for want of agents: the plan and who succeeded in which entry point."""
        self.allocator = Allocator(self)
        self.solving = Solving(self)
        self.scratch: dict[str, object] = {}
        """The agent's scratch space, shared by its behaviours (``SkillContext.scratch``); lost in a crash."""
        """Plan variables solved at run time (:mod:`alica.engine.solving`)."""
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
        }
        for topic in (TEAM_TOPIC, SYNC_TOPIC, WORLD_TOPIC):
            transport.subscribe(topic)
        self.children = Children(self)
        """The child runtimes' kinds (planning problems: pRoPhEt MAS), from ``config.children``."""
        for topic in self.children.routes:
            transport.subscribe(topic)
        self._world_changed = False
        self.inputs = 0
        """Moves on whenever something an allocation reads may have changed: teammates' claims and liveness,
        the world, this agent's own plan tree. A child that found no assignment tries again when it moved."""
        self._liveliness = transport.tracks_liveliness
        """The transport reports who is alive (liveliness tokens): a teammate gone is taken out at once."""
        self._peers: frozenset[str] = frozenset()
        self._greeted: set[str] = set()
        world_model.on_change(self._on_world_change)

    def child_kind(self, element_type: type) -> ChildFactory | None:
        """This agent's factory of child runtimes for elements of ``element_type`` (``None``: none configured);
        see :class:`~alica.engine.child.ChildKinds`."""
        return self.children.factory(element_type)

    def _on_world_change(self, keys: object) -> None:
        self._world_changed = True
        self.inputs += 1

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
            if topic == TEAM_TOPIC and isinstance(payload, TeamMessage):
                changed, revived = self.team.integrate(payload, now)
                if changed:
                    self.inputs += 1
                if revived:
                    self._welcome(payload.sender)
                elif payload.sender not in self._greeted:
                    self._greet(payload.sender)
                if changed and self.root is None:
                    self._next_root_try = now  # a teammate's plans changed: maybe the root can start now
                for key in changed:
                    node = self.index.get(key)
                    if node is not None:
                        node.invalidate()
                authority = authority or bool(payload.authority)
                continue
            if self.team.heard(envelope.sender, envelope.sent_at, now):
                self._welcome(envelope.sender)  # any message is a sign of life
            elif envelope.sender not in self._greeted:
                self._greet(envelope.sender)
            if topic == SYNC_TOPIC and isinstance(payload, SyncTalk):
                self._receive_sync(payload, now)
            elif topic == WORLD_TOPIC:
                if isinstance(payload, Delta):  # anything else is no world: dropped, never merged
                    self.world_model.merge(payload)
            elif topic in self.children.routes:
                self.children.routes[topic].receive(payload, now)
        if authority:
            self.allocator.apply_authority(now)

    def _greet(self, who: str) -> None:
        """The first message of a teammate: send it what this agent knows of the world, if anything.

        A teammate that joins a running team (or restarts before it was missed)
        has not seen the changes sent before it subscribed.
        """
        self._greeted.add(who)
        if who in self.team.mates:
            snapshot = self.world_model.snapshot()
            if len(snapshot):
                self._publish(WORLD_TOPIC, snapshot, QoS.RELIABLE)

    def _welcome(self, who: str) -> None:
        """A teammate taken out spoke again: take it back into the assignments and send it the world."""
        self._greeted.add(who)
        self.emit("team", change="back", who=who)
        self.inputs += 1
        self._invalidate_all()
        self._next_root_try = self.now()
        self._publish(WORLD_TOPIC, self.world_model.snapshot(), QoS.RELIABLE)

    def step(self) -> None:
        """Rules, then behaviours, then messages (see :mod:`alica.engine.node`)."""
        now = self.now()
        self.stats["ticks"] += 1
        lost = self.team.update(now)
        if self._liveliness:
            peers = self.transport.peers()
            for who in sorted(self._peers - peers):
                if self.team.depart(who, now):
                    lost.append(who)
                self._greeted.discard(who)  # when it comes back, it gets the world again
            self._peers = peers
        if lost:
            self.inputs += 1
            for who in lost:
                self.emit("team", change="lost", who=who)
            self._invalidate_all()
        self.world_model.refresh()  # values whose time to live ran out
        if self._world_changed:
            # utilities with summands read the world: allocate those plans again
            self._world_changed = False
            for node in self.index.values():
                if node.plan.utility.summands:
                    node.invalidate()
        if self.root is None and now >= self.start_at:
            failed = self._failed_root
            if failed is not None and self.root_repairs.waited_out(now, self.config.rejoin_wait):
                self._give_up_root(failed)
            elif now >= self._next_root_try:
                self._start_root(now)
        root = self.root
        if root is not None and root.status is ChildStatus.RUNNING:
            root.visit(now)
            if root.failed:
                self._root_failed(root, now)
        self.solving.refresh(now)
        if self.root is not None:
            self._tick_behaviours(self.root, now)
        self._broadcast(now)
        self._talk_syncs(now)
        delta = self.world_model.take_delta()
        if delta is not None:
            self._publish(WORLD_TOPIC, delta, QoS.RELIABLE)

    def _start_root(self, now: float) -> None:
        node = self.allocator.start(None, (self.root_plan,), {"self": self.name}, now)
        if node is not None:
            self.root = node
            self._failed_root = None
            self.root_repairs.waiting_since = None
        else:
            # try again when a teammate comes back or speaks, at the latest after a heartbeat
            self._next_root_try = now + self.config.broadcast_interval

    def _give_up_root(self, failed: PlanNode) -> None:
        """The root plan found no valid assignment for ``rejoin_wait`` seconds: the mission failed."""
        failed.reason += f" (no valid assignment for {self.config.rejoin_wait:g} s)"
        self.emit("repair", key=failed.key_text, stage="propagate", plan=failed.plan.name, reason=failed.reason)
        self.root = failed
        self._failed_root = None

    def _root_failed(self, root: PlanNode, now: float) -> None:
        """The root plan failed: the repair stages of :mod:`alica.engine.slot` (the root has no alternative)."""

        def restart(only: Plan | None) -> bool:
            self.root = None
            self._failed_root = root
            if self.root_repairs.waiting_since is None:
                self.root_repairs.waiting_since = now  # a restart that finds no assignment waits, for a while
            self._start_root(now)
            return self.root is not None

        self.root_repairs.repair(
            root,
            restart,
            lambda: self.root_plan.name not in self.root_repairs.dropped,
            auto=self.config.auto_failure_handling,
        )

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

    @property
    def roleset(self) -> RoleSet:
        """The role set allocation uses: the base role set with the priorities of the generated plans' tasks."""
        return self.generated.roleset

    def plan_named(self, name: str) -> Plan:
        """A plan of the library, or one generated at run time by a child runtime."""
        plan = self.library.plans.get(name)
        return plan if plan is not None else self.generated.plans[name]

    # -- child runtimes ------------------------------------------------------

    def publish(self, topic: str, payload: object) -> None:
        """Send a child runtime's message to the team on its kind's topic (reliable)."""
        self._publish(topic, payload, QoS.RELIABLE)

    def set_problem(self, name: str, goal: str | None = None, world: str | None = None) -> None:
        """The operator sets the goal and/or the world of planning problem ``name`` (the leader replans).

        Raises:
            AlicaError: no planning problem has that name.
        """
        if name not in self.library.problems:
            raise AlicaError(
                f"no planning problem named '{name}'; problems: {', '.join(sorted(self.library.problems)) or 'none'}"
            )
        override = dict(self.overrides.get(name, {}))
        if goal is not None:
            override["goal"] = goal
        if world is not None:
            override["world"] = world
        self.overrides[name] = override

    def decide_plan(self, problem: str, generation: int, decision: PlanDecision) -> None:
        """The operator decides on the plan of ``generation`` proposed for planning problem ``problem``.

        With review on (``EngineConfig.review``) the problem's leader proposes each plan and
        waits; it reads the decision on its next update: it runs the plan (accept), plans again
        (decline), or runs the plan as changed if it is still valid (modify; else it proposes it
        again with the error). A decision for an older generation is ignored. The decision is
        kept (also by an agent that is not the leader now: it may lead later).

        Raises:
            AlicaError: no planning problem has that name.
            TypeError: ``decision`` is not a :class:`~alica.engine.child.PlanDecision`.
        """
        if problem not in self.library.problems:
            raise AlicaError(
                f"no planning problem named '{problem}'; problems: {', '.join(sorted(self.library.problems)) or 'none'}"
            )
        if not isinstance(decision, PlanDecision):
            raise TypeError(f"a plan decision is a PlanDecision, not {decision!r}")
        self.decisions.setdefault(problem, []).append((int(generation), decision))

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
        self.inputs += 1

    def forget(self, node: PlanNode) -> None:
        """A plan node stopped."""
        if self.index.get(node.key) is node:
            del self.index[node.key]
        self._tree_changed = True

    def bind(self, node: PlanNode, ref: ChildRef) -> dict[str, object]:
        """The variables of a child: its bindings evaluated in the parent's context.

        A binding to a variable of the parent plan that has a type (``real[..]``,
        an object type, ...) takes the value the constraint solver gives this
        agent (:mod:`alica.engine.solving`). A binding whose value is not known
        yet (``pos(a)`` before ``a`` is seen) is handed on as its text, for the
        skill to resolve later, with the parent's variables replaced by their
        values (``pos(x)`` with ``x = a`` becomes ``pos(a)``).

        Raises:
            NoSolution: a binding reads a solved variable and the constraints have no solution now.
        """
        env: dict[str, object] = {"self": self.name}
        if not ref.bindings:
            return env
        solved = self.solving.bound_names(node, binding_names(ref))
        if solved:
            values = self.solving.values(node, tuple(sorted(set(solved.values()))))
            env.update({child: values[parent] for child, parent in solved.items()})
        belief = self.belief_for(node)
        for binding in ref.bindings:
            if binding.variable in solved:
                continue
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
        context.solver = self.solving.asker(slot)
        context.scratch = self.scratch
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

    def _invalidate_all(self) -> None:
        for node in self.index.values():
            node.invalidate()

    # -- messages -----------------------------------------------------------

    def _publish(self, topic: str, payload: object, qos: QoS) -> None:
        self.transport.publish(topic, payload, qos)
        self.stats["messages_out"] += 1

    def claims(self) -> list[Claim]:
        """This agent's claims, root first, then the instances it left with a success (``left``)."""
        out = []
        todo = [self.root] if self.root is not None else []
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

    def left_with_success(self, node: PlanNode) -> None:
        """``node`` stops after this agent's task succeeded in it: keep claiming the success (``left``)."""
        done = node.own_successes()
        parent = node.slot.parent if node.slot is not None else None
        if done and parent is not None:
            self.left[node.key] = _Left(Claim(node.key, node.plan.name, None, None, done), parent)

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

    def formula_error(self, text: str, message: str) -> None:
        """A formula could not be evaluated: a warning in the trace."""
        self.emit("warning", formula=text, message=message)
