"""The lunar demo as one process per robot (``alica demo lunar --processes``).

The same mission, robots, skills, operator and scoring as the in-process demo
(:mod:`alica.app.demos.lunar`), but the team is a team of processes:

* this process runs the pybullet world as a **world server**
  (:class:`alica.app.world_server.WorldServer`, lock-step by default: simulated
  time moves one period when every robot's agent has finished its tick, so a
  seed repeats its outcome);
* each robot is one ``alica agent`` process (:class:`alica.app.processes.ProcessTeam`)
  whose skills drive a remote robot of that server (``--world ENDPOINT``) and
  which talks to its teammates over zenoh;
* the **operator** reads the found samples from a replica of the team's world
  model (it listens to the team's world-model messages, as a control center
  would) and sends the goal and ``chosen`` as operator's commands
  (:mod:`alica.comm.center_feed`);
* what the team knows at the start is given on each agent's command line
  (``--object g:location``, ``--value pos(g)=[x, y]``, ``--fact handempty(r)@0``).

A ``--crash NAME@T`` is a ``kill -9`` of that robot's agent at simulated second
``T`` (``NAME@grasp`` when it first lifts a sample); the world server then
powers its robot down (its gripper opens). The scoring (delivered samples,
coverage, distances) reads the simulated world, as the in-process demo's does.
"""

from __future__ import annotations

import contextlib
import math
import queue
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from alica.app.demos.common import StepCounter
from alica.app.demos.lunar import (
    BASE,
    MISSION,
    PLAN,
    PROBLEM,
    ROLES,
    SETTLE_S,
    LunarConfig,
    LunarResult,
    _lifts_sample,
    _Run,
    check_config,
)
from alica.app.demos.served import stalled, stop_serving
from alica.errors import AlicaError
from alica.io.loader import plans_dir

if TYPE_CHECKING:
    from alica.app.processes import ProcessTeam
    from alica.app.ros2_options import Ros2Arguments
    from alica.app.world_server import WorldServer
    from alica.comm.center_feed import CenterLink
    from alica.comm.zenoh_transport import ZenohTransport
    from alica.engine import SimulatedTeam
    from alica.skills.mapping import LogOddsGrid
    from alica.worldmodel import WorldModel
    from alica.worldsim.world import World

#: The name of the operator's session on the team's network (it listens; it is not in the team's roster).
OPERATOR = "operator"


class TeamListener:
    """The operator's view of a team of processes: a replica of its world model and a link for commands.

    The replica listens on ``listen`` (every agent connects to it) to the team's world-model messages and merges
    them; the command link reaches the agents at ``agents`` (their listen endpoints) and also takes their trace
    events (for the step counter).
    """

    def __init__(self, listen: str, prefix: str, clock: Any) -> None:
        from alica.comm.zenoh_transport import ZenohTransport
        from alica.engine.team import WORLD_TOPIC
        from alica.worldmodel import WorldModel

        self.prefix = prefix
        self.transport: ZenohTransport = ZenohTransport(OPERATOR, listen=[listen], team=prefix, clock=clock)
        self.transport.subscribe(WORLD_TOPIC)
        self.replica: WorldModel = WorldModel(OPERATOR, clock=clock, relay=False)
        self.link: CenterLink | None = None
        self.events: queue.SimpleQueue[dict[str, Any]] = queue.SimpleQueue()

    def open_link(self, agents: list[str]) -> bool:
        """Open the command link to the agents' endpoints, once one of them listens; whether it is open.

        Events before it opened come with the agents' histories.
        """
        from alica.comm.center_feed import CenterLink

        if self.link is not None:
            return True

        def history(answer: dict[str, Any]) -> None:
            for event in answer.get("events", []):
                if isinstance(event, dict):
                    self.events.put(event)

        try:
            self.link = CenterLink(agents, self.prefix, history, lambda _name, event: self.events.put(event))
        except ValueError:
            return False  # no agent listens yet: the next look tries again
        return True

    def update(self) -> None:
        """Merge what the team published into the replica."""
        from alica.worldmodel import Delta

        for envelope in self.transport.poll():
            if isinstance(envelope.payload, Delta):
                self.replica.merge(envelope.payload)

    def send(self, command: dict[str, Any]) -> bool:
        """An operator's command to every agent; whether a link to the team was up to take it."""
        if self.link is None or not self.link.alive:
            return False
        self.link.send(command)
        return True

    def close(self) -> None:
        if self.link is not None:
            self.link.close()
        self.transport.close()


class _ProcessRun(_Run):
    """The in-process demo's loop body, called by the world server between its steps (same thread as the world)."""

    def __init__(
        self,
        config: LunarConfig,
        processes: ProcessTeam,
        world: World,
        base: tuple[float, float],
        listener: TeamListener,
        counter: StepCounter,
        on_second: Callable[[dict[str, Any]], None] | None,
    ) -> None:
        super().__init__(config, cast("SimulatedTeam", None), world, base)
        self.processes = processes
        self.endpoints = [agent.listen for agent in processes.agents.values()]
        self.listener = listener
        self.counter = counter
        self.on_second = on_second
        self.at_grasp = {c.robot for c in config.crashes if c.at is None}
        self.timed = sorted((c.at, c.robot) for c in config.crashes if c.at is not None)
        self.crashed: set[str] = set()
        self.last = {n: world.robots[n].pose[:2] for n in config.robots}
        self.next_second = 0.0
        self.seen = -1.0
        self.stepped_at = time.monotonic()
        self.ended = ""
        self.pending: tuple[str, float] | None = None  # a goal the link could not send yet

    # -- what the in-process run reads from its team -----------------------------------------------

    def read(self) -> bool:
        self.listener.update()
        return self.operator.read_models([self.listener.replica])

    def command(self, goal: str, now: float) -> None:
        self.pending = (goal, now)
        self._send_pending()

    def _send_pending(self) -> None:
        if self.pending is None:
            return
        goal, _ = self.pending
        if self.listener.send({"what": "goal", "problem": PROBLEM, "goal": goal}) and self.listener.send(
            {"what": "facts", "facts": [[True, "chosen", []]]}
        ):
            self.pending = None

    def team_map(self) -> LogOddsGrid | None:
        from alica.skills.mapping import team_map

        return team_map(self.listener.replica)

    # -- the loop ----------------------------------------------------------------------------------

    def step(self) -> bool:
        """One look between two world steps; True to end the run."""
        if self.listener.link is None and self.world.now() > 0.0:  # every agent runs: the first step came
            self.listener.open_link(self.endpoints)
        while True:
            try:
                self.counter(self.listener.events.get_nowait())
            except queue.Empty:
                break
        world = self.world
        now = world.now()
        self.processes.exited()
        if now == self.seen:  # no step since the last look
            self.ended = stalled(now, time.monotonic() - self.stepped_at, self.processes.all_down())
            return bool(self.ended)
        self.seen, self.stepped_at = now, time.monotonic()
        while self.timed and now >= self.timed[0][0]:
            self._crash(self.timed.pop(0)[1])
        for name in self.config.robots:
            x, y = world.robots[name].pose[:2]
            self.distance[name] += math.hypot(x - self.last[name][0], y - self.last[name][1])
            self.last[name] = (x, y)
            if name in self.at_grasp and name not in self.crashed and _lifts_sample(world, name):
                self.at_grasp.discard(name)
                self._crash(name)
            if name in self.crashed and name not in self.crash_places:
                self.crash_places[name] = (x, y)
        if now >= self.next_second:
            self.next_second = now + 1.0
            for name in self.config.robots:
                self.tracks[name].append(self.last[name])
            self._send_pending()
            if self._operate(now):
                self.ended = self.operator.reason
                return True
            if self.on_second is not None:
                self.on_second(self.progress(now, self.counter))
        if self.operator.chosen and len(self.delivered()) == len(self.operator.chosen):
            if self.reached is None:
                self.reached = now
            return now - self.reached >= SETTLE_S
        return now >= self.config.time_limit or self.processes.done()

    def _crash(self, name: str) -> None:
        self.crashed.add(name)
        self.processes.crash(name)  # kill -9: the world server sees its token go and powers the robot down


def run_lunar_processes(
    config: LunarConfig,
    *,
    on_second: Callable[[dict[str, Any]], None] | None = None,
    out: Path | None = None,
    prefix: str = "alica",
    lockstep: bool = True,
    ros2: Ros2Arguments | None = None,
) -> LunarResult:
    """Run the lunar mission once with one ``alica agent`` process per robot (see the module docstring).

    ``ros2`` (``--ros2``, ``--record``) is passed on to every agent: each is a ROS 2 node of its own, and
    records into its own rosbag2 folder.

    Raises:
        AlicaError: a bad configuration, or one the processes cannot run (network loss, delay, partitions).
    """
    from alica.app.processes import ProcessTeam
    from alica.app.world_server import WorldServer
    from alica.comm.zenoh_transport import free_endpoints
    from alica.engine import trace_header
    from alica.io import load_library
    from alica.worldsim.scenarios import lunar

    check_config(config)
    unsupported = [o for o, used in (("--loss", config.loss), ("--delay", config.delay)) if used]
    if config.partitions:
        unsupported.append("--partition")
    if unsupported:
        raise AlicaError(
            f"--processes runs the robots over a real network: {', '.join(unsupported)} only work in the "
            "in-process demo (leave out --processes)"
        )
    library = load_library(MISSION)
    counter = StepCounter(library.abstract(PROBLEM).elements, PROBLEM)  # type: ignore[union-attr]
    world = lunar(config.seed, rocks=config.rocks, samples=config.samples, size=config.size)
    names = list(config.robots)
    server: WorldServer | None = None
    listener: TeamListener | None = None
    try:
        world_endpoint, operator_endpoint = free_endpoints(2)
        server = WorldServer(
            world,
            listen=[world_endpoint],
            prefix=prefix,
            lockstep=lockstep,
            frequency=config.frequency,
            agents=names,
        )
        listener = TeamListener(operator_endpoint, prefix, world.clock)
        gx, gy = (round(float(v), 3) for v in world.objects[BASE].position()[:2])
        options = [
            "--world",
            world_endpoint,
            "--connect",
            operator_endpoint,
            "--key-prefix",
            prefix,
            "--frequency",
            repr(config.frequency),
            "--seed",
            str(config.seed),
            "--fact",
            "start@0",
            "--object",
            f"{BASE}:location",
            "--value",
            f"pos({BASE})=[{gx}, {gy}]",
            "--time-limit",
            repr(config.time_limit + SETTLE_S + 5.0),  # simulated seconds: the agents end by themselves
        ]
        own = {n: ["--fact", f"handempty({n})@0"] for n in names if world.robots[n].arm is not None}
        roster = ",".join(f"{n}:{ROLES[n]}" for n in names)
        with contextlib.ExitStack() as stack:
            if out is not None:  # each agent's trace and log stay beside the merged trace
                workdir = out / "agents"
                workdir.mkdir(parents=True, exist_ok=True)
            else:
                workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="alica-lunar-")))
            team = ProcessTeam(
                str(MISSION),
                roster,
                names,
                options,
                workdir,
                own=own,
                per_incarnation=ros2.for_agent if ros2 is not None else None,
            )
            base = (gx, gy)
            run = _ProcessRun(config, team, world, base, listener, counter, on_second)
            wall, cpu = time.perf_counter(), time.process_time()
            team.launch()
            try:
                server.serve(until=run.step)
            finally:
                stop_serving(team, server)
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            summary = team.summary(PLAN, config.seed)
            if out is not None:
                header = trace_header(
                    plans=[f"alica:plans/{MISSION.relative_to(plans_dir()).as_posix()}"],
                    root=PLAN,
                    agents={name: ROLES[name] for name in names},
                    seed=config.seed,
                    frequency=config.frequency,
                    demo="lunar",
                    processes=True,
                    field={"samples": config.samples, "rocks": config.rocks, "size": config.size},
                )
                team.trace(out / "trace.jsonl", header)
                from alica.app.demos.lunar_map import draw_map

                draw_map(
                    world, run.team_map(), run.operator, run.tracks, run.crash_places, out / "map.png", run.targets
                )
        operator = run.operator
        delivered = run.delivered()
        success = bool(operator.chosen) and len(delivered) == len(operator.chosen)
        reason = "" if success else (operator.reason or run.ended or run.why_not(counter))
        agents = summary["agents"]
        return LunarResult(
            success=success,
            reason=reason,
            sim_time_s=run.reached if run.reached is not None else world.now(),
            wall_time_s=wall,
            coverage=run.coverage(),
            found={name: operator.found[name] for name in operator.order},
            chosen=list(operator.chosen),
            delivered=delivered,
            replans=counter.replans,
            plans=len(counter.plans),
            messages=int(summary["messages"]["sent"]),
            robots={
                name: {**robot, "cpu_percent": agents[name].get("cpu_percent")}
                for name, robot in run.robots_json(counter, run.crashed).items()
            },
            crashed=sorted(run.crashed),
            replicas=_replicas(summary, run.crashed),
            world_server={
                "steps": server.stats.steps,
                "calls": server.stats.calls,
                "refused": server.stats.refused,
                "rejected": sum(server.stats.rejected.values()),
                # this process: the world, its server and the operator (its zenoh threads too), of one core
                "cpu_percent": round(100.0 * cpu / max(wall, 1e-9), 2),
            },
        )
    finally:
        if listener is not None:
            listener.close()
        if server is not None:
            server.close()
        world.close()


def _replicas(summary: dict[str, Any], crashed: set[str]) -> dict[str, Any]:
    """Whether the running agents agree at the end on the found samples, and each one's found samples."""
    found: dict[str, list[str]] = {}
    for name, agent in summary["agents"].items():
        if name in crashed or agent.get("world_facts") is None:
            continue
        found[name] = sorted(f[6:-1] for f in agent["world_facts"] if f.startswith("found(") and "," not in f)
    # (not the whole world models' digests: robots share their poses until each agent's SIGTERM, at its own tick)
    agree = len({tuple(v) for v in found.values()}) <= 1
    return {"agree": agree, "found": found}
