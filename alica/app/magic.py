"""MAGiC on a team: the adapter from a transport to MAGiC's link, and a lock-step simulated team.

:class:`TransportLink` lets a MAGiC agent (:mod:`alica.prophet.magic`) talk
over any :class:`~alica.comm.Transport`: its messages go reliably on one
topic (:data:`TOPIC`), and who is reachable is the transport's
:meth:`~alica.comm.Transport.peers`. A team tells its liveness by its own
periodic messages; a link stands in for them with :meth:`TransportLink.heartbeat`
(best-effort, on ``TOPIC + "/alive"``; not MAGiC messages, not counted).

:func:`run_lockstep` runs one round over :class:`~alica.comm.SimNetwork` on a
:class:`~alica.clock.ManualClock`: every tick, the leader and then each worker
handle their messages and take a bounded number of search steps, then the
clock moves one tick on. It is deterministic for a seed; loss, delay and a
worker crashed at a given tick are options. A driver with one worker per
process (over a middleware transport) returns the same :class:`MagicRun`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass

from alica.clock import ManualClock
from alica.comm import Delay, QoS, SimNetwork, Transport
from alica.prophet.magic import MagicLeader, MagicMessage, MagicWorker, RoundOutcome
from alica.prophet.planner import Plan, PlanStatus

TOPIC = "alica/magic"
"""The topic MAGiC's messages travel on."""
ALIVE = f"{TOPIC}/alive"
"""The topic of :meth:`TransportLink.heartbeat`."""


class TransportLink:
    """A :class:`~alica.prophet.magic.MagicLink` over a transport.

    The link polls the transport itself: give it a transport no one else polls.

    Args:
        transport: the agent's transport (subscribed to :data:`TOPIC` and :data:`ALIVE` here).
        topic: the topic of MAGiC's messages.
    """

    def __init__(self, transport: Transport, topic: str = TOPIC) -> None:
        self._transport = transport
        self._topic = topic
        self._alive = f"{topic}/alive"
        transport.subscribe(topic)
        transport.subscribe(self._alive)

    @property
    def name(self) -> str:
        """The agent's id."""
        return self._transport.agent_id

    def send(self, payload: MagicMessage) -> None:
        """Publish ``payload`` reliably on the link's topic."""
        self._transport.publish(self._topic, payload, QoS.RELIABLE)

    def receive(self) -> list[object]:
        """The payloads that arrived on the link's topic (other topics are drained and dropped)."""
        return [envelope.payload for envelope in self._transport.poll() if envelope.topic == self._topic]

    def reachable(self) -> frozenset[str]:
        """The transport's peers."""
        return self._transport.peers()

    def heartbeat(self) -> None:
        """Tell the team this agent is alive (best-effort; stands in for the team's own periodic messages)."""
        self._transport.publish(self._alive, None, QoS.BEST_EFFORT)


@dataclass(frozen=True, slots=True)
class MagicRun:
    """One MAGiC round on a team, as a driver saw it.

    Attributes:
        status: ``SOLVED`` with a plan; else why there is none (``TIMEOUT`` when the driver's bound ran out).
        plan: the validated plan, or ``None``.
        agents: the number of agents (leader included).
        messages: MAGiC messages sent in the round by every agent (shares, results, finals).
        received: MAGiC messages of the round received by every agent.
        solver: the agent whose share found the plan.
        search: that share's first search, as text.
        lost: teammates the leader did not wait for.
        first_plan_s: time from the start until the leader took the plan (simulated
            seconds in lock step, wall seconds with processes); ``None`` without a plan.
        first_plan_tick: the tick of the leader's plan in lock step (``None`` with processes or without a plan).
        ticks: ticks until every agent was done (lock step; 0 with processes).
        expansions: states expanded by all agents together.
        wall_s: wall seconds of the whole run (all agents, in one process in lock step).
        outcome: the leader's view of the round.
    """

    status: PlanStatus
    plan: Plan | None
    agents: int
    messages: int
    received: int
    solver: str | None
    search: str | None
    lost: tuple[str, ...]
    first_plan_s: float | None
    first_plan_tick: int | None
    ticks: int
    expansions: int
    wall_s: float
    outcome: RoundOutcome | None

    @property
    def cost(self) -> float | None:
        """The plan's cost, if any."""
        return None if self.plan is None else self.plan.cost

    @property
    def bound(self) -> int:
        """IMPERA's bound on the messages of a round, ``3 * (agents - 1)``."""
        return 3 * (self.agents - 1)


def agent_names(n: int) -> tuple[str, ...]:
    """The ids of an n-agent team, the leader (the lowest id) first: ``agent1`` ... ``agentN``.

    Raises:
        ValueError: ``n < 1``.
    """
    if n < 1:
        raise ValueError(f"MAGiC needs at least one agent, got {n}")
    return tuple(f"agent{i}" for i in range(1, n + 1))


def run_lockstep(
    domain: str,
    problem: str,
    agents: int,
    *,
    seed: int = 0,
    steps_per_tick: int = 1,
    tick: float = 0.05,
    loss: float = 0.0,
    delay: float = 0.0,
    lease: float = 0.5,
    crash: Mapping[str, int] | None = None,
    seconds: float | None = None,
    max_ticks: int = 100_000,
    progress_every: int = 10,
) -> MagicRun:
    """One MAGiC round over a simulated network, the agents stepped in lock step.

    Each tick every agent that is up sends a heartbeat; the round starts on the
    first tick at which the leader hears every teammate (or after ``lease /
    tick`` ticks: the ones it does not hear get no share). Then, every tick,
    the leader and then each worker (in id order) handle their messages and
    take ``steps_per_tick`` planner events; the clock moves ``tick`` seconds.
    After the leader's outcome, the workers go on until each has its final
    (or is down), so that every message of the round is counted.

    Args:
        domain: the PDDL domain text.
        problem: the PDDL problem text.
        agents: the team size n (the leader included).
        seed: the seed of the network and of the shares' tie-breaking.
        steps_per_tick: planner events per agent and tick (each up to ``progress_every`` expansions).
        tick: simulated seconds per tick.
        loss: the probability that a transmission is lost (reliable messages are sent again).
        delay: the one-way delay of every link, in seconds.
        lease: seconds after which the leader no longer counts a silent teammate as reachable.
        crash: worker id -> the tick at which it crashes (e.g. ``{"agent2": 3}``; not the leader).
        seconds: each share's time budget in simulated seconds; ``None``: none.
        max_ticks: a bound on the ticks; reached, the run ends with ``TIMEOUT``.
        progress_every: expansions between two planner events.

    Returns:
        The run.

    Raises:
        ValueError: bad sizes, or ``crash`` names the leader or an unknown agent.
        PddlError: the domain or the problem is not valid PDDL.
    """
    names = agent_names(agents)
    crash = dict(crash or {})
    unknown = sorted(set(crash) - set(names[1:]))
    if unknown:
        raise ValueError(f"cannot crash {', '.join(unknown)}: the workers are {', '.join(names[1:]) or 'none'}")
    if steps_per_tick < 1 or max_ticks < 1:
        raise ValueError("steps_per_tick and max_ticks must be at least 1")
    wall = time.perf_counter()
    clock = ManualClock()
    network = SimNetwork(clock, seed=seed, loss=loss, delay=Delay(delay), lease=lease)
    links = {name: TransportLink(network.attach(name)) for name in names}
    leader = MagicLeader(
        links[names[0]], domain, problem, seed=seed, seconds=seconds, clock=clock.now, progress_every=progress_every
    )
    workers = [MagicWorker(links[n], clock=clock.now, progress_every=progress_every) for n in names[1:]]
    down: set[str] = set()
    warmup = max(1, round(lease / tick))
    ended: int | None = None
    ticks = 0
    for ticks in range(1, max_ticks + 1):
        for name, when in crash.items():
            if when == ticks and name not in down:
                network.crash(name)
                down.add(name)
        for name in names:
            if name not in down:
                links[name].heartbeat()
        if leader.round_id == 0:
            if links[names[0]].reachable() >= set(names[1:]) - down or ticks >= warmup:
                leader.start(names)
        if leader.round_id > 0 and names[0] not in down:
            if leader.step(steps_per_tick) is not None and ended is None:
                ended = ticks
        for worker in workers:
            if worker.name not in down:
                worker.step(steps_per_tick)
        clock.advance(tick)
        outcome = leader.outcome
        if outcome is not None and all(w.name in down or w.final or w.name not in outcome.informed for w in workers):
            break
    outcome = leader.outcome
    sent = leader.counts.sent + sum(w.counts.sent for w in workers)
    received = leader.counts.received + sum(w.counts.received for w in workers)
    expansions = (outcome.expansions if outcome else 0) + sum(w.expansions for w in workers)
    return MagicRun(
        status=outcome.status if outcome else PlanStatus.TIMEOUT,
        plan=outcome.plan if outcome else None,
        agents=agents,
        messages=sent,
        received=received,
        solver=outcome.solver if outcome else None,
        search=str(outcome.search) if outcome and outcome.search else None,
        lost=outcome.lost if outcome else (),
        first_plan_s=outcome.seconds if outcome and outcome.plan is not None else None,
        first_plan_tick=ended if outcome and outcome.plan is not None else None,
        ticks=ticks,
        expansions=expansions,
        wall_s=time.perf_counter() - wall,
        outcome=outcome,
    )
