"""One agent's engine: its plan tree, its team view, its messages, in step mode.

The engine never sleeps and never reads the wall clock: the caller ticks it
(:meth:`AgentEngine.tick`, or :meth:`receive` then :meth:`step` when a team
is ticked in lock step) and the injected clock says what time it is.

The engine keeps the tick, the root plan's start and repair, the team's
messages and the operator's settings. It builds its collaborators once and
hands each only what it needs (:mod:`alica.engine.parts` says how): the plan
tree (:mod:`alica.engine.tree`) whose nodes run the rules
(:mod:`alica.engine.node`, :mod:`alica.engine.slot`), allocation
(:mod:`alica.engine.allocate`), constraint queries (:mod:`alica.engine.solving`),
the start of a state's children (:mod:`alica.engine.launch`), the child
runtimes' host (:mod:`alica.engine.hosting`) and the synchronisations
(:class:`~alica.engine.sync.SyncTable`).
"""

from __future__ import annotations

import random
from collections.abc import Callable, Mapping
from typing import Any

from alica.clock import Clock
from alica.comm import QoS, Transport
from alica.engine.allocate import Allocator
from alica.engine.behaviours import SkillBinder
from alica.engine.belief import AgentBelief
from alica.engine.carry_over import CarryOver
from alica.engine.child import ChildFactory, PlanDecision
from alica.engine.conditions import Formulas
from alica.engine.config import EngineConfig
from alica.engine.generated import GeneratedPlans
from alica.engine.hosting import Children
from alica.engine.launch import Launcher
from alica.engine.node import NodeParts, PlanNode
from alica.engine.parts import AgentContext
from alica.engine.reload import Loaded, Reloads
from alica.engine.slot import Repairs
from alica.engine.solving import Solving
from alica.engine.status import ChildStatus
from alica.engine.sync import SyncTable, SyncTalk
from alica.engine.team import SYNC_TOPIC, TEAM_TOPIC, WORLD_TOPIC, TeamMessage, TeamView
from alica.engine.tree import PlanTree
from alica.errors import AlicaError
from alica.lang import FactBase, Registry
from alica.model import Plan, PlanLibrary, RoleSet
from alica.worldmodel import Delta, ReplicaLike

Observer = Callable[[dict[str, Any]], None]


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
        self.generated = GeneratedPlans(roleset)
        """The plans child runtimes generated; its ``roleset`` is the one allocation uses, ``base`` the team's."""
        self.overrides: dict[str, dict[str, str]] = {}
        """Planning problem -> what the operator set for it (:meth:`set_problem`)."""
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
        self.stats = {
            "ticks": 0,
            "transitions": 0,
            "allocations": 0,
            "messages_in": 0,
            "messages_out": 0,
            "repairs": 0,
        }
        self.formulas = Formulas(registry, on_error=lambda text, why: self.emit("warning", formula=text, message=why))
        self.team = TeamView(name, roster, self.now(), self.config.team_timeout)
        self.reloads = Reloads(name, library, self.config, self.team, self.emit)
        """The team's agreement on the plan library (hot reload, :mod:`alica.engine.reload`)."""
        self.own = FactBase()
        self.belief = AgentBelief(name, world_model, self.team, self.own, self.now)
        self.scratch: dict[str, object] = {}
        """The agent's scratch space, shared by its behaviours (``SkillContext.scratch``); lost in a crash."""
        # the collaborators: none holds the engine (see alica.engine.parts)
        ctx = AgentContext(name, self.now, self.config, self.team, self.formulas, self.belief, self.stats, self.emit)
        self.tree = PlanTree(library, self.generated)
        self.index = self.tree.index
        """Every running plan instance of the agent, by key (the plan tree's index)."""
        self.allocator = Allocator(ctx, self.tree, self.generated)
        self.solving = Solving(ctx, world_model)
        """Plan variables solved at run time (:mod:`alica.engine.solving`)."""
        self.syncs = SyncTable(name, self.config.period)
        for topic in (TEAM_TOPIC, SYNC_TOPIC, WORLD_TOPIC):
            transport.subscribe(topic)
        self.children = Children(ctx, self, self.root_plan.name)
        """The child runtimes' kinds (planning problems: pRoPhEt MAS), from ``config.children``."""
        for topic in self.children.routes:
            transport.subscribe(topic)
        launch = Launcher(ctx, self.solving, self.skills, world_model, self.rng, world, self.scratch)
        self.tree.attach(NodeParts(ctx, self.tree, self.allocator, launch, self.children, self.solving, self.syncs))
        self.root: PlanNode | None = None
        self.root_repairs = Repairs()
        self._failed_root: PlanNode | None = None
        self._next_root_try = float("-inf")
        self._last_broadcast = float("-inf")
        self._world_changed = False
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
        self.tree.moved()

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
                    self.tree.moved()
                if revived:
                    self._welcome(payload.sender)
                elif payload.sender not in self._greeted:
                    self._greet(payload.sender)
                if changed and self.root is None:
                    self._next_root_try = now  # a teammate's plans changed: maybe the root can start now
                for key in changed:
                    node = self.tree.get(key)
                    if node is not None:
                        node.invalidate()
                authority = authority or bool(payload.authority)
                continue
            if self.team.heard(envelope.sender, envelope.sent_at, now):
                self._welcome(envelope.sender)  # any message is a sign of life
            elif envelope.sender not in self._greeted:
                self._greet(envelope.sender)
            if topic == SYNC_TOPIC and isinstance(payload, SyncTalk):
                node = self.tree.get(payload.key)
                if node is not None:
                    self.syncs.receive(payload, node.plan, now)
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
        self.tree.moved()
        self.tree.invalidate_all()
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
            self.tree.moved()
            for who in lost:
                self.emit("team", change="lost", who=who)
            self.tree.invalidate_all()
        announced = self.reloads.adopt
        due = self.reloads.due(now)
        if self.reloads.adopt is not announced:
            self.tree.news = True  # the leader's announcement goes out in this tick's team message
        if due is not None:
            self._adopt(due, now)
        self.world_model.refresh()  # values whose time to live ran out
        if self._world_changed:
            # utilities with summands read the world: allocate those plans again
            self._world_changed = False
            for node in self.tree.index.values():
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
        for talk in self.syncs.talk(now):
            self._publish(SYNC_TOPIC, talk, QoS.BEST_EFFORT)
        delta = self.world_model.take_delta()
        if delta is not None:
            self._publish(WORLD_TOPIC, delta, QoS.RELIABLE)

    # -- hot reload ---------------------------------------------------------

    def reload(self, library: PlanLibrary) -> str:
        """Adopt ``library`` with the team: at the tick every agent adopts it (see :mod:`alica.engine.reload`).

        The agent goes on with the library it runs until the team agrees; its plan tree is
        then carried over (:mod:`alica.engine.carry_over`) and the world model is untouched.

        Returns:
            The new library's digest (the running one's when nothing changed).

        Raises:
            AlicaError: the library cannot run here: it has no plan named as the root plan,
                or it reaches an element no child runtime is configured for.
        """
        self.check_library(library)
        digest = self.reloads.propose(library, self.now())
        self.tree.news = True  # tell the team now
        return digest

    def check_library(self, library: PlanLibrary) -> None:
        """Whether this agent could run ``library``.

        Raises:
            AlicaError: it has no plan named as the agent's root plan, or it reaches an element no
                child runtime is configured for.
        """
        root = self.root_plan.name
        if root not in library.plans:
            raise AlicaError(
                f"the new plans have no plan named '{root}', the root plan this agent runs: not reloaded "
                f"(plans: {', '.join(sorted(library.plans)) or 'none'})"
            )
        self.children.check(library, root)

    def _adopt(self, loaded: Loaded, now: float) -> None:
        """Switch to a library the team agreed on, carrying the plan tree over."""
        old = self.reloads.digest
        library = loaded.library
        self.reloads.adopted(loaded)
        self.library = library
        self.root_plan = library.plans[self.root_plan.name]
        base = self.generated.base
        self.generated.rebase(library.rolesets.get(base.name, base))
        self.skills.forget(loaded.changes.names("behaviour"))
        carry = CarryOver(self.tree, loaded.changes, now, self.emit)
        carry.apply(library, self.root)
        self.tree.news = True
        self.emit(
            "reload",
            status="adopted",
            library=old,
            adopted=loaded.digest,
            changes=loaded.changes.describe(),
            restarted=carry.restarted,
        )

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
                belief.at(node)
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

    # -- messages -----------------------------------------------------------

    def _publish(self, topic: str, payload: object, qos: QoS) -> None:
        self.transport.publish(topic, payload, qos)
        self.stats["messages_out"] += 1

    def _broadcast(self, now: float) -> None:
        config = self.config
        since = now - self._last_broadcast + 1e-9  # ticks land on the interval up to rounding
        tree = self.tree
        if not ((tree.news and since >= config.min_broadcast_gap) or since >= config.broadcast_interval):
            return
        tree.news = False
        self._last_broadcast = now
        reloads = self.reloads
        message = TeamMessage(
            self.name,
            now,
            self.role,
            tuple(tree.claims(self.root)),
            tree.authority(now),
            reloads.digest,
            reloads.proposed,
            reloads.adopt,
        )
        self._publish(TEAM_TOPIC, message, QoS.BEST_EFFORT)

    # -- trace --------------------------------------------------------------

    def emit(self, event: str, **fields: object) -> None:
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
