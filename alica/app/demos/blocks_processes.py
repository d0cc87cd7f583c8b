"""The blocks-world demo as one process per robot (``alica demo blocksworld --processes``).

The same mission, configurations, goal and scoring as the in-process demo
(:mod:`alica.app.demos.blocksworld`): this process runs the pybullet blocks
world as a lock-step world server (:class:`alica.app.world_server.WorldServer`);
each team robot ``r1``..``rN`` is one ``alica agent`` process driving its
remote robot (``--world ENDPOINT``), given the goal on its command line
(``--goal GetBlocks=...``) and the blocks-world facts from the world's state
(``--perception blocks``, the overhead-camera stand-in of the in-process demo).
Timed faults (``--crash``/``--recover``) happen at simulated seconds: a crash
is a ``kill -9`` of the robot's agent, a recovery starts it again.

Opponents run only in the in-process demo: they are a second team on the same
world, which a world server serving one team's key prefix does not host.
"""

from __future__ import annotations

import contextlib
import json
import tempfile
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.app.demos.blocksworld import (
    MISSION,
    PROBLEM,
    SETTLE_S,
    DemoConfig,
    DemoResult,
    configurations,
    goal_facts,
    goal_text,
    write_picture,
)
from alica.app.demos.common import StepCounter
from alica.app.demos.served import stalled, stop_serving
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.app.processes import ProcessTeam
    from alica.app.ros2_options import Ros2Arguments


class _Look:
    """Between two world steps (the world's thread): faults due, the goal's literals, whether the run ends."""

    def __init__(
        self,
        world: Any,
        team: ProcessTeam,
        wanted: set[tuple[str, ...]],
        limit: float,
        pending: list[tuple[float, Callable[[Any], None]]],
        on_second: Callable[[float, int, int, int], None] | None,
        counter: StepCounter,
    ) -> None:
        self.world, self.team, self.wanted, self.limit = world, team, wanted, limit
        self.pending, self.on_second, self.counter = pending, on_second, counter
        self.seen = -1.0
        self.stepped = time.monotonic()
        self.next_second = 0.0
        self.reached: float | None = None
        self.satisfied = 0
        self.ended = ""

    def step(self) -> bool:
        from alica.worldsim.queries import blocks_facts

        now = self.world.now()
        self.team.exited()
        if now == self.seen:
            self.ended = stalled(now, time.monotonic() - self.stepped, self.team.all_down())
            return bool(self.ended)
        self.seen, self.stepped = now, time.monotonic()
        while self.pending and now >= self.pending[0][0]:
            self.pending.pop(0)[1](self.team)
        self.satisfied = len(self.wanted & blocks_facts(self.world))
        if self.on_second is not None and now >= self.next_second:
            self.next_second = now + 1.0
            self.on_second(now, self.satisfied, len(self.wanted), self.counter.replans)
        if self.satisfied == len(self.wanted):
            if self.reached is None:
                self.reached = now
            return self.team.done() or now - self.reached >= SETTLE_S
        self.reached = None
        return now >= self.limit


def run_demo_processes(
    config: DemoConfig,
    *,
    on_second: Callable[[float, int, int, int], None] | None = None,
    actions: Iterable[tuple[float, Callable[[Any], None]]] = (),
    out: Path | None = None,
    ros2: Ros2Arguments | None = None,
) -> DemoResult:
    """Run the blocks-world demo once with one ``alica agent`` process per team robot (see the module docstring).

    ``ros2`` (``--ros2``, ``--record``) is passed on to every agent: each is a ROS 2 node of its own, and
    records into its own rosbag2 folder.

    Args:
        config: what to run (no opponents).
        on_second: called once per simulated second with (time, goal literals satisfied, of how many, replans).
        actions: ``(time, action(team))`` at simulated seconds; ``team`` is the
            :class:`~alica.app.processes.ProcessTeam` (``crash``/``recover`` by name).
        out: a folder for the merged trace, the agents' own traces and logs, and the pictures.

    Raises:
        AlicaError: a bad configuration, or opponents.
    """
    from alica.app.processes import ProcessTeam
    from alica.app.world_server import WorldServer
    from alica.comm.zenoh_transport import free_endpoints
    from alica.io import load_library
    from alica.worldsim.scenarios import blocksworld

    if config.agents < 1:
        raise AlicaError(f"the demo needs at least 1 agent, got {config.agents}")
    if config.opponents:
        raise AlicaError(
            "--processes runs the team's robots as processes; opponents run only in the in-process demo "
            "(leave out --opponents or --processes)"
        )
    start, goal = configurations(config)
    library = load_library(MISSION)
    if config.planner is not None and config.planner != library.problems[PROBLEM].planner:
        raise AlicaError(
            f"--processes runs the mission's planner as shipped; --planner {config.planner} runs only in the "
            "in-process demo (leave out --planner or --processes)"
        )
    counter = StepCounter(library.abstract(PROBLEM).elements, PROBLEM)  # type: ignore[union-attr]
    world = blocksworld([list(s) for s in start], agents=config.agents, seed=config.seed)
    names = [f"r{i + 1}" for i in range(config.agents)]
    wanted = set(goal_facts(goal))
    pending = sorted(actions, key=lambda action: action[0])
    server: WorldServer | None = None
    try:
        (endpoint,) = free_endpoints(1)
        server = WorldServer(world, listen=[endpoint], lockstep=True, frequency=config.frequency, agents=names)
        options = [
            "--world",
            endpoint,
            "--perception",
            "blocks",
            "--frequency",
            repr(config.frequency),
            "--seed",
            str(config.seed),
            "--goal",
            f"{PROBLEM}={goal_text(goal)}",
            "--time-limit",
            repr(config.time_limit + SETTLE_S + 5.0),  # simulated seconds: the agents end by themselves
        ]
        if out is not None:
            write_picture(world, out / "initial.png", goal=goal, title="initial: the start configuration")
        with contextlib.ExitStack() as stack:
            if out is not None:
                workdir = out / "agents"
                workdir.mkdir(parents=True, exist_ok=True)
            else:
                workdir = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="alica-blocks-")))
            roster = ",".join(f"{n}:Manipulator" for n in names)
            team = ProcessTeam(
                str(MISSION),
                roster,
                names,
                options,
                workdir,
                per_incarnation=ros2.for_agent if ros2 is not None else None,
            )
            look = _Look(world, team, wanted, config.time_limit, pending, on_second, counter)
            wall = time.perf_counter()
            team.launch()
            try:
                server.serve(until=look.step)
            finally:
                stop_serving(team, server)
            wall = time.perf_counter() - wall
            summary = team.summary("BlocksWorldMission", config.seed)
            merged = (out if out is not None else workdir) / "trace.jsonl"
            team.trace(merged)
            for line in merged.read_text(encoding="utf-8").splitlines():
                event = json.loads(line)
                if isinstance(event, dict) and "event" in event:
                    counter(event)
        if out is not None:
            write_picture(world, out / "final.png", goal=goal, title=f"final: after {world.now():.1f} s simulated")
        satisfied = look.satisfied
        return DemoResult(
            success=satisfied == len(wanted),
            sim_time_s=look.reached if look.reached is not None else world.now(),
            wall_time_s=wall,
            plan_length=counter.plan_length,
            replans=counter.replans,
            messages=int(summary["messages"]["sent"]),
            tasks={name: len(counter.tasks.get(name, ())) for name in names},
            steps={name: counter.steps.get(name, 0) for name in names},
            plans=len(counter.plans),
            start=start,
            goal=goal,
            goal_literals=len(wanted),
            satisfied=satisfied,
            crashed=sorted(n for n, a in summary["agents"].items() if a["status"] == "crashed"),
            processes=True,
            reason=look.ended,
        )
    finally:
        if server is not None:
            server.close()
        world.close()
