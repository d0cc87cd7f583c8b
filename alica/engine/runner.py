"""A team in simulation: agents ticked in lock step over a simulated network, with faults.

Every tick, every running agent first takes in what the network delivered,
then applies its rules and ticks its behaviours; then simulated time moves on
by one engine period. With the same seed, the same team and the same faults,
two runs give the same trace.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from alica.allocation import AgentSpec, assign_roles
from alica.clock import Clock, ManualClock
from alica.comm import Delay, SimNetwork, Transport
from alica.comm.faults import describe_fault
from alica.engine.agent import AgentEngine, Observer
from alica.engine.behaviours import SkillBinder, SkillFactory
from alica.engine.child import PlanDecision
from alica.engine.config import EngineConfig
from alica.engine.sim_world import SimWorld
from alica.engine.status import ChildStatus
from alica.errors import AlicaError
from alica.lang import Registry, literal_text
from alica.lang.skills import SkillRegistry
from alica.model import Behaviour, PlanLibrary, RoleSet
from alica.worldmodel import WorldModel


def root_status(engine: AgentEngine) -> str:
    """``running``, ``success`` or ``failure``: how an agent's root plan stands."""
    if engine.root is None:
        return "running"
    return engine.root.status.value if engine.root.status is not ChildStatus.WAITING else "running"


def describe_agent(engine: AgentEngine, status: str) -> dict[str, Any]:
    """One agent of a run summary: role, status, its tasks root first, where it is, its counters."""
    path = []
    node = engine.root
    tasks = []
    while node is not None:
        if node.ep is not None:
            tasks.append(node.plan.entry_point(node.ep).task)
        path.append(f"{node.plan.name}:{node.state or 'idle'}")
        node = next((s.node for s in node.slots if s.node is not None), None)
    return {"role": engine.role, "status": status, "tasks": tasks, "path": " > ".join(path), **engine.stats}


def pick_roleset(library: PlanLibrary, roles: Iterable[str | None], name: str | None = None) -> RoleSet:
    """The role set to allocate with: ``name``, or the one holding every given role (``None``: no role given).

    Raises:
        AlicaError: no such role set, or none (or several) fit.
    """
    rolesets = library.rolesets
    if name is not None:
        if name not in rolesets:
            raise AlicaError(f"no role set named '{name}'; role sets: {', '.join(sorted(rolesets)) or 'none'}")
        return rolesets[name]
    wanted = {r for r in roles if r is not None}
    fits = [rs for _, rs in sorted(rolesets.items()) if wanted <= {r.name for r in rs.roles}]
    if not fits:
        raise AlicaError(
            f"no role set has the roles {sorted(wanted)}; role sets: {', '.join(sorted(rolesets)) or 'none'} (import one in the plan file)"
        )
    return fits[0]


@dataclass(order=True)
class _Event:
    at: float
    order: int
    label: str = field(compare=False)
    action: Callable[[], None] = field(compare=False)


class SimulatedTeam:
    """Runs a team of agents on one plan in simulated time.

    Args:
        library: the plan library.
        plan: the root plan every agent runs.
        agents: agent name -> role name, or -> :class:`AgentSpec` (role or capabilities).
        seed: seeds the network and the agents.
        config: engine settings shared by all agents.
        roleset: the role set's name (by default the one holding the agents' roles).
        loss: probability that a best-effort message is lost on a link.
        delay: base message delay in seconds; ``jitter`` adds a uniform random part.
        skills: skill factories by behaviour or skill name (test doubles, real skills).
        skill_registry: the skill declarations whose implementations run (the shipped
            catalogue and plug-ins: :func:`alica.lang.skill_plugins.default_registry`).
        fallback: factory maker for skills nothing implements, e.g. the scripted stand-ins of
            :func:`alica.testing.default_fallback`; ``None`` makes them fail.
        registry: predicates and functions of formulas.
        observers: trace observers.
        trace_messages: also trace every message sent and delivered.
        world: the simulated world the skills act on (a :class:`worldsim.World`);
            the team then runs on the world's clock and each tick steps it one period.
        perception: called with the team before every tick, to write what the
            robots sense into their world models.
        step_world: whether :meth:`tick` steps the world (``False`` when a caller
            runs several teams in one world and steps it itself).
        agent_worlds: the robot interface each agent's skills get, by agent name, when
            it is not ``world`` (robot plug-ins: each agent's driver is a world of its own).
    """

    def __init__(
        self,
        library: PlanLibrary,
        plan: str,
        agents: Mapping[str, str | AgentSpec],
        *,
        seed: int = 0,
        config: EngineConfig | None = None,
        roleset: str | None = None,
        loss: float = 0.0,
        delay: float = 0.0,
        jitter: float = 0.0,
        skills: Mapping[str, SkillFactory] | None = None,
        skill_registry: SkillRegistry | None = None,
        fallback: Callable[[Behaviour], SkillFactory] | None = None,
        registry: Registry | None = None,
        observers: Iterable[Observer] = (),
        trace_messages: bool = False,
        world: SimWorld | None = None,
        perception: Callable[[SimulatedTeam], None] | None = None,
        step_world: bool = True,
        agent_worlds: Mapping[str, object] | None = None,
    ) -> None:
        if not agents:
            raise AlicaError("a team needs at least one agent")
        if plan not in library.plans:
            raise AlicaError(f"no plan named '{plan}' to run; plans: {', '.join(sorted(library.plans))}")
        specs = {
            name: spec if isinstance(spec, AgentSpec) else AgentSpec(role=spec) for name, spec in sorted(agents.items())
        }
        self.library = library
        self.plan = plan
        self.seed = seed
        self.config = config or EngineConfig()
        self.roleset = pick_roleset(library, (s.role for s in specs.values()), roleset)
        self.roles = assign_roles(specs, self.roleset)
        self.world: Any = world
        """The world as given: hooks such as a perception read their own world type from it (issue 36 leaves
        making the team generic in its world for later); the team itself uses only :class:`SimWorld`."""
        self._sim_world = world
        self.perception = perception
        self.step_world = step_world
        self.agent_worlds = dict(agent_worlds or {})
        manual = ManualClock()
        self._manual: ManualClock | None = manual if world is None else None
        """The team's own clock when it runs without a world (it advances it every tick)."""
        self.clock: Clock = world.clock if world is not None else manual
        self.observers = list(observers)
        self.trace_messages = trace_messages
        self.network = SimNetwork(
            self.clock,
            seed=seed,
            loss=loss,
            delay=Delay(delay, jitter),
            lease=self.config.team_timeout,
            observer=self._network_event,
            trace_messages=trace_messages,
        )
        self.binder = SkillBinder(skills, skill_registry, fallback)
        self.registry = registry
        self.engines: dict[str, AgentEngine] = {}
        self.crashed: set[str] = set()
        self.faults: list[dict[str, Any]] = []
        self.ticks = 0
        self._events: list[_Event] = []
        self._order = 0
        self._after_tick: list[Callable[[float], None]] = []
        for name in self.roles:
            self.engines[name] = self._make_engine(name, self.network.attach(name))

    def _make_engine(self, name: str, transport: Transport, listen_first: float = 0.0) -> AgentEngine:
        return AgentEngine(
            name,
            self.roles,
            self.library,
            self.plan,
            self.roleset,
            transport,
            WorldModel(name, clock=self.clock, relay=False),
            self.clock,
            config=self.config,
            skills=self.binder,
            registry=self.registry,
            seed=self.seed,
            observers=tuple(self.observers),
            world=self.agent_worlds.get(name, self.world),
            listen_first=listen_first,
        )

    # -- time -----------------------------------------------------------

    def now(self) -> float:
        """The simulated time."""
        return self.clock.now()

    def tick(self) -> None:
        """One lock-step tick of every running agent, then time moves one period on (the world steps)."""
        self.tick_agents()
        if self._sim_world is not None:
            if self.step_world:
                self._sim_world.step(self.config.period)
        elif self._manual is not None:
            self._manual.advance(self.config.period)
        for hook in self._after_tick:
            hook(self.now())

    def after_tick(self, hook: Callable[[float], None]) -> None:
        """Call ``hook(now)`` at the end of every :meth:`tick`, once time moved on (to sample the world, say)."""
        self._after_tick.append(hook)

    def tick_agents(self) -> None:
        """Timed events, perception, then one lock-step tick of every running agent; time stands still."""
        self._run_events()
        if self.perception is not None:
            self.perception(self)
        running = self.running()
        for engine in running:
            engine.receive()
        for engine in running:
            engine.step()
        self.ticks += 1

    def running(self) -> list[AgentEngine]:
        """The engines of the agents that have not crashed, by name."""
        return [e for name, e in self.engines.items() if name not in self.crashed]

    def run(
        self, ticks: int | None = None, *, until_done: bool = False, max_time: float | None = None
    ) -> dict[str, Any]:
        """Tick ``ticks`` times, or until every running agent is done (or ``max_time`` passes).

        Returns:
            The :meth:`summary`.

        Raises:
            ValueError: neither ``ticks`` nor ``until_done`` was given.
        """
        if ticks is None and not until_done:
            raise ValueError("say how long to run: ticks=N or until_done=True")
        limit = max_time if max_time is not None else float("inf")
        count = 0
        while True:
            if ticks is not None and count >= ticks:
                break
            if until_done and self.done():
                break
            if self.now() >= limit:
                break
            self.tick()
            count += 1
        return self.summary()

    def done(self) -> bool:
        """Whether every running agent's root plan succeeded or finally failed."""
        running = [e for name, e in self.engines.items() if name not in self.crashed]
        return bool(running) and all(e.done for e in running)

    def at(self, when: float, label: str, action: Callable[[], None]) -> None:
        """Run ``action`` at the first tick at or after ``when``."""
        self._order += 1
        heapq.heappush(self._events, _Event(when, self._order, label, action))

    def _run_events(self) -> None:
        now = self.now() + 1e-9
        while self._events and self._events[0].at <= now:
            heapq.heappop(self._events).action()

    # -- faults ---------------------------------------------------------

    def crash(self, name: str, at: float | None = None) -> None:
        """Crash an agent now or at time ``at``: it stops acting and talking."""
        self._agent(name)
        if at is not None and at > self.now():
            self.at(at, f"crash {name}", lambda: self.crash(name))
            return
        if name in self.crashed:
            return
        self.crashed.add(name)
        self.network.crash(name)
        robot = self._sim_world.robots.get(name) if self._sim_world is not None else None
        if robot is not None:
            robot.crash()  # power loss: the robot stops where it is and drops what it holds
        self._fault("crash", agent=name)

    def recover(self, name: str, at: float | None = None) -> None:
        """Restart a crashed agent (with an empty memory) now or at time ``at``."""
        self._agent(name)
        if at is not None and at > self.now():
            self.at(at, f"recover {name}", lambda: self.recover(name))
            return
        if name not in self.crashed:
            return
        self.crashed.discard(name)
        self.network.recover(name)
        robot = self._sim_world.robots.get(name) if self._sim_world is not None else None
        if robot is not None:
            robot.recover()  # the body powers up again where it stopped
        old = self.engines[name]
        # a restarted agent listens for a broadcast interval before it allocates
        engine = self._make_engine(name, old.transport, listen_first=1.5 * self.config.broadcast_interval)
        # the operator's settings are the robot's configuration, not its memory: the restart keeps them
        engine.overrides = {problem: dict(values) for problem, values in old.overrides.items()}
        engine.decisions = {problem: list(made) for problem, made in old.decisions.items()}
        self.engines[name] = engine
        self._fault("recover", agent=name)

    def partition(self, groups: Iterable[Iterable[str]], start: float | None = None, end: float | None = None) -> None:
        """Cut the network between groups of agents from ``start`` to ``end`` (see :class:`SimNetwork`)."""
        groups = [sorted(g) for g in groups]
        for group in groups:
            for name in group:
                self._agent(name)
        self.network.partition(groups, start=start, end=end)
        self._fault("partition", groups=groups, start=self.now() if start is None else start, end=end)

    def set_facts(
        self,
        facts: Iterable[tuple[bool, str, tuple[object, ...]]],
        at: float | None = None,
        *,
        by_operator: bool = False,
    ) -> None:
        """The operator sets facts, ``(positive, predicate, args)``, in every running agent's world model.

        With ``at`` in the future, at that time. With ``by_operator`` the trace's ``operator`` event
        is the operator's action (agent ``operator``, ``what`` = ``facts``), as :meth:`set_goal` traces.
        """
        facts = [(bool(p), str(n), tuple(a)) for p, n, a in facts]
        if at is not None and at > self.now():
            self.at(at, "operator", lambda: self.set_facts(facts, by_operator=by_operator))
            return
        for name, engine in self.engines.items():
            if name in self.crashed:
                continue
            for positive, pred, args in facts:
                (engine.world_model.assert_fact if positive else engine.world_model.retract_fact)(pred, *args)
        texts = [literal_text(p, n, a) for p, n, a in facts]
        if by_operator:
            self._operator("facts", facts=texts)
            return
        record = {"t": round(self.now(), 6), "agent": "-", "event": "operator", "facts": texts}
        for observer in self.observers:
            observer(record)

    def reload(self, library: PlanLibrary) -> str:
        """Every running agent loads ``library`` and the team adopts it at one tick (hot reload).

        The agents go on with the plans they run until they agree
        (:mod:`alica.engine.reload`); a crashed agent that is restarted later
        starts with ``library`` (a restarted robot reads the files it has).

        Returns:
            The new library's digest.

        Raises:
            AlicaError: the library cannot run (no plan named as the root plan, say); nothing changed.
        """
        running = self.running()
        for engine in running:  # every check first: no agent proposes a library another refuses
            engine.check_library(library)
        digests = {engine.reload(library) for engine in running}
        self.library = library
        return digests.pop() if digests else ""

    def set_goal(self, problem: str, goal: str) -> None:
        """The operator sets the goal of planning problem ``problem`` on every agent (crashed ones too): the leader replans.

        Raises:
            AlicaError: no planning problem has that name.
        """
        for engine in self.engines.values():
            engine.set_problem(problem, goal=goal)
        self._operator("goal", problem=problem, goal=goal)

    def decide_plan(self, problem: str, generation: int, decision: PlanDecision) -> None:
        """The operator decides on the plan of ``generation`` proposed for ``problem`` (review on).

        Every agent is told, crashed ones too, so that whoever leads (now or after a
        restart) knows it; see :meth:`AgentEngine.decide_plan`.

        Raises:
            AlicaError: no planning problem has that name.
        """
        for engine in self.engines.values():
            engine.decide_plan(problem, generation, decision)
        details = decision.describe()
        self._operator(str(details.pop("action")), problem=problem, generation=generation, **details)

    def _operator(self, what: str, **fields: object) -> None:
        """An ``operator`` event: what the operator did."""
        record = {"t": round(self.now(), 6), "agent": "operator", "event": "operator", "what": what, **fields}
        for observer in self.observers:
            observer(record)

    def _agent(self, name: str) -> AgentEngine:
        try:
            return self.engines[name]
        except KeyError:
            raise AlicaError(f"no agent named '{name}' in the team; agents: {', '.join(self.engines)}") from None

    def _fault(self, kind: str, **fields: object) -> None:
        record = {
            "t": round(self.now(), 6),
            "agent": fields.pop("agent", "-"),
            "event": "fault",
            "fault": kind,
            **fields,
        }
        self.faults.append(record)
        for observer in self.observers:
            observer(record)

    def _network_event(self, event: dict[str, Any]) -> None:
        kind = event.get("event")
        if kind in ("send", "deliver", "drop"):
            if not self.trace_messages:
                return
            record = {
                "t": round(float(event.get("t", self.now())), 6),
                "agent": event.get("sender", "-"),
                "event": "message",
                **{k: v for k, v in event.items() if k not in ("t", "event")},
                "what": kind,
            }
        else:
            return  # partitions, crashes and heals are traced by the team itself
        for observer in self.observers:
            observer(record)

    # -- results --------------------------------------------------------

    def status_of(self, name: str) -> str:
        """``crashed``, ``running``, ``success`` or ``failure`` (of the root plan)."""
        if name in self.crashed:
            return "crashed"
        return root_status(self.engines[name])

    def summary(self) -> dict[str, Any]:
        """What happened: per agent and for the team, as plain data.

        ``messages`` counts publish calls (``sent``), then copies per receiver (one publish to four
        teammates makes four copies): ``delivered``, ``dropped_loss`` (lost on a lossy link),
        ``dropped_partition``, ``dropped_crash`` (the receiver was crashed), ``dropped_closed`` and
        ``superseded`` (a best-effort copy replaced by a newer one), as :class:`~alica.comm.NetStats`.
        """
        agents = {name: describe_agent(engine, self.status_of(name)) for name, engine in self.engines.items()}
        stats = self.network.stats
        statuses = [a["status"] for a in agents.values() if a["status"] != "crashed"]
        return {
            "plan": self.plan,
            "seed": self.seed,
            "ticks": self.ticks,
            "sim_time_s": round(self.now(), 6),
            "done": self.done(),
            "success": bool(statuses) and all(s == "success" for s in statuses),
            "agents": agents,
            "messages": {  # publish calls; then copies per receiver, by what became of them (NetStats)
                "sent": stats.sent,
                "delivered": stats.delivered,
                "dropped_loss": stats.dropped_loss,
                "dropped_partition": stats.dropped_partition,
                "dropped_crash": stats.dropped_crash,
                "dropped_closed": stats.dropped_closed,
                "superseded": stats.superseded,
            },
            "faults": [describe_fault(f) for f in self.faults],
        }
