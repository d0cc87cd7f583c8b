"""The blocks-world demo (IMPERA Section 8.2): a team plans at run time and stacks blocks in pybullet.

The shipped mission ``plans/blocksworld/mission.yaml`` holds the planning
problem StackBlocks. World comes from the simulated state: an overhead
perception (:class:`alica.worldsim.perception.FactPerception` with
:func:`alica.worldsim.scenarios.blocks_facts`) writes the IPC facts into every
robot's world model. Goal is the goal configuration. The team robots
``r1..rN`` plan, allocate and execute with the real skills (mobile
manipulators driving with OMPL paths and grasping with the Panda arm).
Opponents ``o1..oK`` are a second team on their own network, running
BlocksWorldOpponent: each picks a random applicable skill on a stack that
no other robot blocks.

The run ends when the goal holds in the simulated world, or when the time
limit passes.
"""

from __future__ import annotations

import functools
import itertools
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.app.demos.blocks_pictures import write_picture
from alica.app.demos.common import StepCounter, plan_yaml_text, planning_leader
from alica.errors import AlicaError
from alica.io.loader import plans_dir
from alica.model import PlanLibrary

if TYPE_CHECKING:
    from alica.app.center.live import LiveSession
    from alica.app.ros2_output import Ros2Output
    from alica.engine import SimulatedTeam
    from alica.engine.agent import Observer

Stacks = list[list[str]]
PROBLEM = "StackBlocks"
#: Simulated seconds the run goes on once the goal holds, for the team to notice it.
SETTLE_S = 2.0
#: The shipped mission plan.
MISSION = plans_dir() / "blocksworld" / "mission.yaml"


@dataclass(frozen=True, slots=True)
class DemoConfig:
    """What to run.

    Attributes:
        agents: team robots (r1..rN).
        opponents: opponent robots (o1..oK).
        blocks: blocks in random configurations (ignored where ``start``/``goal`` are given).
        seed: seeds the configurations, the world, the networks and the agents.
        start: the initial stacks (bottom first); random from the seed when None.
        goal: the goal stacks; random from the seed when None.
        time_limit: simulated seconds before the run gives up.
        frequency: engine ticks per simulated second.
        planner: the planner of StackBlocks: None for the mission's (``temporal``: for the team's time, the
            skills' declared durations refined by what the team measures), or ``builtin`` (the fewest steps).
    """

    agents: int = 2
    opponents: int = 0
    blocks: int = 4
    seed: int = 0
    start: Stacks | None = None
    goal: Stacks | None = None
    time_limit: float = 600.0
    frequency: float = 10.0
    planner: str | None = None


@dataclass(slots=True)
class DemoResult:
    """What a demo run gave (see :meth:`as_json` for the keys the CLI prints).

    ``steps`` and ``tasks`` count, per team robot, the plan steps it carried
    out over the whole run and the tasks (entry points of generated plans)
    those steps belonged to; ``plans`` is the number of plans made (one per
    planning generation) and ``plan_length`` the length of the last one.
    """

    success: bool
    sim_time_s: float
    wall_time_s: float
    plan_length: int
    replans: int
    messages: int
    tasks: dict[str, int]
    start: Stacks
    goal: Stacks
    goal_literals: int
    satisfied: int
    plan_yaml: str = ""
    crashed: list[str] = field(default_factory=list)
    steps: dict[str, int] = field(default_factory=dict)
    plans: int = 0
    processes: bool = False
    """Whether the team ran as one process per robot around a world server (``--processes``)."""
    reason: str = ""
    """With processes: why the run ended early, if it did (no agent left, one hangs)."""

    @property
    def steps_executed(self) -> int:
        """Steps the team carried out over the whole run (over every plan made)."""
        return sum(self.steps.values())

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second."""
        return self.sim_time_s / self.wall_time_s if self.wall_time_s > 0 else float("inf")

    def as_json(self) -> dict[str, Any]:
        """The summary as plain data."""
        return {
            "success": self.success,
            "sim_time_s": round(self.sim_time_s, 3),
            "wall_time_s": round(self.wall_time_s, 3),
            "real_time_factor": round(self.real_time_factor, 2),
            "replans": self.replans,
            "messages": self.messages,
            "plan_length": self.plan_length,
            "plans": self.plans,
            "steps_executed": self.steps_executed,
            "steps": self.steps,
            "tasks": self.tasks,
            "goal_literals": self.goal_literals,
            "satisfied": self.satisfied,
            "start": self.start,
            "goal": self.goal,
            "crashed": self.crashed,
            **({"processes": True, "reason": self.reason} if self.processes else {}),
        }


def goal_facts(stacks: Stacks) -> list[tuple[str, ...]]:
    """The facts of a configuration: ``ontable`` for each bottom block, ``on`` for the others."""
    out: list[tuple[str, ...]] = []
    for stack in stacks:
        out.append(("ontable", stack[0]))
        out.extend(("on", upper, lower) for lower, upper in itertools.pairwise(stack))
    return out


def goal_text(stacks: Stacks) -> str:
    """The goal formula of a configuration: ``ontable(a) and on(b, a) and ...``."""
    return " and ".join(f"{f[0]}({', '.join(f[1:])})" for f in goal_facts(stacks))


def check_stacks(stacks: object, what: str) -> Stacks:
    """A configuration as lists of block names.

    Raises:
        AlicaError: not a list of non-empty lists of distinct names.
    """
    if not isinstance(stacks, list) or not stacks or not all(isinstance(s, list) and s for s in stacks):
        raise AlicaError(
            f"{what} must be a list of stacks, each a non-empty list of block names (bottom first), e.g. [[a, b], [c]]"
        )
    names = [str(b) for s in stacks for b in s]
    if len(set(names)) != len(names):
        raise AlicaError(f"{what} names a block twice: {names}")
    if not all(n.isidentifier() and n == n.lower() for n in names):
        raise AlicaError(f"{what}: block names must be lower-case identifiers, got {names}")
    return [[str(b) for b in s] for s in stacks]


def configurations(config: DemoConfig) -> tuple[Stacks, Stacks]:
    """The initial and goal stacks: given, or random from the seed (a goal different from the start).

    Raises:
        AlicaError: start and goal name different blocks.
    """
    if config.start is None or config.goal is None:
        from alica.worldsim.scenarios import random_stacks
    start = config.start if config.start is not None else random_stacks(config.blocks, config.seed)
    if config.goal is not None:
        goal = config.goal
    else:
        blocks = sorted(b for s in start for b in s)
        k = 1
        while True:
            candidate = _renamed(random_stacks(len(blocks), config.seed * 7919 + k), blocks)
            if sorted(map(sorted, candidate)) != sorted(map(sorted, start)) or sorted(goal_facts(candidate)) != sorted(
                goal_facts(start)
            ):
                goal = candidate
                break
            k += 1
    if sorted(b for s in start for b in s) != sorted(b for s in goal for b in s):
        raise AlicaError(f"the start {start} and the goal {goal} must hold the same blocks")
    return start, goal


def with_planner(library: PlanLibrary, problem: str, planner: str | None) -> PlanLibrary:
    """``library`` with planning problem ``problem`` planned by ``planner`` (None: the library's own).

    Raises:
        AlicaError: the planner is not one of the registered back-ends.
    """
    from alica.prophet.planners import PLANNERS

    if planner is None or library.problems[problem].planner == planner:
        return library
    if planner not in PLANNERS:
        raise AlicaError(f"unknown planner '{planner}': use one of {', '.join(sorted(PLANNERS))}")
    documents = tuple(
        replace(d, problems=tuple(replace(p, planner=planner) if p.name == problem else p for p in d.problems))
        for d in library.documents
    )
    return PlanLibrary(documents)


def _renamed(stacks: Stacks, names: Sequence[str]) -> Stacks:
    """Random stacks of ``a, b, ...`` with the blocks named like ``names`` (sorted)."""
    order = sorted(b for s in stacks for b in s)
    mapping = dict(zip(order, names, strict=True))
    return [[mapping[b] for b in s] for s in stacks]


def run_demo(
    config: DemoConfig,
    *,
    observers: Iterable[Observer] = (),
    on_second: Callable[[float, int, int, int], None] | None = None,
    actions: Iterable[tuple[float, Callable[[SimulatedTeam], None]]] = (),
    out: Path | None = None,
    gui: bool = False,
    live: LiveSession | None = None,
    ros2: Ros2Output | None = None,
) -> DemoResult:
    """Run the demo in simulated time.

    Args:
        config: what to run.
        observers: trace observers (every event of the team and the opponents).
        on_second: called once per simulated second with (time, goal literals satisfied, of how many, replans).
        actions: ``(time, action(team))`` to run at those simulated times (faults, say).
        out: a folder for the trace (``trace.jsonl``), pictures (``initial.png``,
            ``final.png``) and the generated plan (``plan.yaml``).
        gui: show the pybullet window.
        live: the control center of the run (``--center``): it serves the page and paces the run.
        ros2: where the robots' ROS 2 topics go (``--ros2``, ``--record``; :mod:`alica.app.ros2_output`),
            after every tick in simulated time; the caller closes it.

    Raises:
        AlicaError: a bad configuration.
    """
    from alica.app.run_skills import share_poses
    from alica.app.trace_world import WorldTrace, tee, world_header
    from alica.engine import JsonlTrace, SimulatedTeam, trace_header
    from alica.io import load_library
    from alica.lang.skill_plugins import default_registry
    from alica.prophet import engine_config, latest_plans
    from alica.skills.motion import configure_ompl
    from alica.worldsim.scenarios import blocks_perception, blocksworld

    configure_ompl(config.seed)  # OMPL's generator is per process: seed it before any planner exists
    if config.agents < 1 or config.opponents < 0:
        raise AlicaError(
            f"the demo needs at least 1 agent and 0 or more opponents, got {config.agents} and {config.opponents}"
        )
    start, goal = configurations(config)
    library = with_planner(load_library(MISSION), PROBLEM, config.planner)
    world = blocksworld(
        [list(s) for s in start], agents=config.agents, seed=config.seed, opponents=config.opponents, gui=gui
    )
    counter = StepCounter(library.abstract(PROBLEM).elements, PROBLEM)  # type: ignore[union-attr]
    header = trace_header(
        plans=[f"alica:plans/{MISSION.relative_to(plans_dir()).as_posix()}"],
        root="BlocksWorldMission",
        agents={
            **{f"r{i + 1}": "Manipulator" for i in range(config.agents)},
            **{f"o{i + 1}": "Opponent" for i in range(config.opponents)},
        },
        roots={f"o{i + 1}": "BlocksWorldOpponent" for i in range(config.opponents)},
        seed=config.seed,
        frequency=config.frequency,
        demo="blocks",
        start=[list(s) for s in start],
        goal=[list(s) for s in goal],
        **world_header(world, "blocks"),
    )
    trace = JsonlTrace(out / "trace.jsonl", header=header) if out is not None else None
    hub = live.start(header, library) if live is not None else None
    sinks = [s for s in (trace, hub) if s is not None]
    watchers: list[Observer] = [counter, *observers, *sinks]
    settings = engine_config(frequency=config.frequency)
    perception = blocks_perception()
    registry = default_registry()
    team = SimulatedTeam(
        library,
        "BlocksWorldMission",
        {f"r{i + 1}": "Manipulator" for i in range(config.agents)},
        seed=config.seed,
        config=settings,
        skill_registry=registry,
        observers=watchers,
        world=world,
        perception=perception,
        step_world=False,
    )
    text = goal_text(goal)
    for engine in team.engines.values():
        engine.set_problem(PROBLEM, goal=text)
    rivals = None
    if config.opponents:
        rivals = SimulatedTeam(
            library,
            "BlocksWorldOpponent",
            {f"o{i + 1}": "Opponent" for i in range(config.opponents)},
            seed=config.seed + 1,
            config=settings,
            skill_registry=registry,
            observers=watchers,
            world=world,
            step_world=False,
        )
    for when, action in actions:
        team.at(when, "demo action", functools.partial(action, team))
    wanted = set(goal_facts(goal))
    if out is not None:
        write_picture(world, out / "initial.png", goal=goal, title="initial: the start configuration")
    sample = None
    if sinks:
        sample = WorldTrace(
            tee(sinks),
            world,
            alive=lambda name: name not in team.crashed and (rivals is None or name not in rivals.crashed),
        )
        sample(world.now())
    share = share_poses(team)  # every team robot tells its team where it believes it is
    publish = ros2.attach_team(team, library, hook=False) if ros2 is not None else None
    wall = time.perf_counter()
    next_report = 0.0
    satisfied = 0
    reached: float | None = None
    try:
        while True:
            team.tick_agents()
            if rivals is not None:
                rivals.tick_agents()
            world.step(settings.period)
            now = world.now()
            share(now)
            if sample is not None:
                sample(now)
            if publish is not None:
                publish(now)
            if live is not None:
                live.pace(team)
            facts = perception.facts
            satisfied = len(wanted & facts)
            if on_second is not None and now >= next_report:
                next_report = now + 1.0
                on_second(now, satisfied, len(wanted), counter.replans)
            if satisfied == len(wanted) and facts:
                if reached is None:
                    reached = now
                if team.done() or now - reached >= SETTLE_S:
                    break  # the team has a moment to see the goal and finish its plan
            else:
                reached = None
            if now >= config.time_limit:
                break
        wall = time.perf_counter() - wall
        counter.finish(team, perception.facts)
        if on_second is not None:
            on_second(world.now(), satisfied, len(wanted), counter.replans)
        created = next(iter(latest_plans(e).values()), None) if (e := planning_leader(team)) is not None else None
        plan_yaml = plan_yaml_text(created, MISSION, out) if created is not None else ""
        if out is not None:
            write_picture(world, out / "final.png", goal=goal, title=f"final: after {world.now():.1f} s simulated")
            if plan_yaml:
                (out / "plan.yaml").write_text(plan_yaml, encoding="utf-8")
        return DemoResult(
            success=satisfied == len(wanted),
            sim_time_s=reached if reached is not None else world.now(),
            wall_time_s=wall,
            plan_length=counter.plan_length,
            replans=counter.replans,
            messages=team.network.stats.sent,
            tasks={name: len(counter.tasks.get(name, ())) for name in team.engines},
            steps={name: counter.steps.get(name, 0) for name in team.engines},
            plans=len(counter.plans),
            start=start,
            goal=goal,
            goal_literals=len(wanted),
            satisfied=satisfied,
            plan_yaml=plan_yaml,
            crashed=sorted(team.crashed),
        )
    finally:
        if trace is not None:
            trace.close()
        world.close()
