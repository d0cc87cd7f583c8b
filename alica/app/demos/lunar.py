"""The lunar demo (IMPERA Sections 6.4, 7 and 8.1): explore, find, choose, plan, fetch.

The shipped mission ``plans/lunar/impera.yaml`` (Fig. 17) runs on the
robots ``scout``, ``stummel`` and ``amparo`` of
:func:`alica.worldsim.scenarios.lunar`, with the real skills: the team maps and
explores the unknown field (the Explore plan, Fig. 7), detects drill samples
on the way (Verify2DObject), and once the operator has chosen the samples to
bring back, pRoPhEt MAS plans MoveToObject / Pickup / Putdown at run time
(GetObjects) and the team carries them to the collection point ``g``.

What the team knows at the start is the mission's data, not the simulator's
state: where ``g`` is (``pos(g)``, an object of type ``location``) and, for
every robot with an arm, that its hand is empty (``handempty(r)``, what its
gripper senses). Everything else comes from the skills' sensors.

The operator (this module) starts the team (fact ``start``), reads the found
samples from the team's world model like a control centre would, and chooses:
the kinds of ``collect`` (``green-white-red`` ...), the samples named in
``goal``, or else the first ``pick`` samples found. It then sets the goal of
GetObjects (``at(s, g) and ...``) and asserts ``chosen``. When nothing is
left to explore before all are found, it chooses among what was found.

The run ends when every chosen sample rests within :data:`DELIVERED_WITHIN`
metres of ``g`` in the simulated world (ground truth, read only to score the
run), when the mission ends, or at the time limit.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.app.demos.common import StepCounter, plan_yaml_text
from alica.errors import AlicaError
from alica.io.loader import plans_dir

if TYPE_CHECKING:
    import numpy as np

    from alica.app.center.live import LiveSession
    from alica.app.ros2_output import Ros2Output
    from alica.engine import SimulatedTeam
    from alica.engine.agent import Observer
    from alica.prophet.tasks import CreatedTasks
    from alica.skills.mapping import LogOddsGrid
    from alica.worldmodel.protocol import WorldModelLike
    from alica.worldsim.robots import Robot
    from alica.worldsim.world import World

MISSION = plans_dir() / "lunar" / "impera.yaml"
PLAN = "ImperaMission"
PROBLEM = "GetObjects"
#: The robots of the lunar world and their roles.
ROLES = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"}
#: The collection point.
BASE = "g"
#: A sample counts as delivered when it rests within this many metres of g (on the ground, in no gripper).
DELIVERED_WITHIN = 1.0
#: A crash "at the grasp" comes when the held sample's bottom is this many metres above the ground (the lift).
LIFTED_ABOVE = 0.05
#: Simulated seconds the run goes on once every chosen sample is delivered, for the team to notice it.
SETTLE_S = 2.0
#: Simulated seconds between two readings of the map's coverage (for the progress line).
COVERAGE_EVERY = 5.0


@dataclass(frozen=True, slots=True)
class Crash:
    """A robot crashes at simulated second ``at``, or (``at`` None) when it first lifts a sample it grasped."""

    robot: str
    at: float | None = None


@dataclass(frozen=True, slots=True)
class Partition:
    """The network is cut between ``groups`` from ``start`` to ``end`` (for good when ``end`` is None)."""

    groups: tuple[tuple[str, ...], ...]
    start: float
    end: float | None = None


@dataclass(frozen=True, slots=True)
class LunarConfig:
    """What to run.

    Attributes:
        robots: the team, a subset of scout, stummel and amparo.
        samples: drill samples on the field.
        rocks: rocks on the field.
        size: side of the square field in metres.
        collect: the kinds to bring back (``green-white-red``, ...).
        goal: the goal of GetObjects over the samples' names (``at(green_white_red, g) and ...``).
        pick: without ``collect`` or ``goal``: bring back the first ``pick`` samples found.
        seed: seeds the world, the network and the agents.
        time_limit: simulated seconds before the run gives up.
        frequency: engine ticks per simulated second.
        loss: probability that a best-effort message is lost.
        delay: message delay in seconds.
        crashes: robots that crash.
        partitions: timed network partitions.
    """

    robots: tuple[str, ...] = ("scout", "stummel", "amparo")
    samples: int = 6
    rocks: int = 60
    size: float = 40.0
    collect: tuple[str, ...] = ()
    goal: str | None = None
    pick: int = 2
    seed: int = 0
    time_limit: float = 900.0
    frequency: float = 30.0
    loss: float = 0.0
    delay: float = 0.0
    crashes: tuple[Crash, ...] = ()
    partitions: tuple[Partition, ...] = ()


@dataclass(slots=True)
class LunarResult:
    """What happened (see :meth:`as_json` for the fields)."""

    success: bool
    reason: str
    sim_time_s: float
    wall_time_s: float
    coverage: float
    found: dict[str, str]
    chosen: list[str]
    delivered: list[str]
    replans: int
    plans: int
    messages: int
    robots: dict[str, dict[str, Any]]
    plan_yaml: str = ""
    crashed: list[str] = field(default_factory=list)
    replicas: dict[str, Any] = field(default_factory=dict)
    world_server: dict[str, Any] | None = None
    """With one process per robot: what the world server did (steps, calls, its CPU share); else ``None``."""

    def as_json(self) -> dict[str, Any]:
        """The summary as plain data.

        ``replicas`` compares the running robots' replicated world models at the
        end of the run (see :func:`replica_views`): ``agree`` (every running
        robot holds the same found samples and the same team map), ``found``
        (robot -> its sorted ``found(s)`` samples) and ``map_digest`` (robot ->
        a short hash of its team map grid, ``""`` before it has one).
        """
        return {
            "success": self.success,
            "reason": self.reason,
            "sim_time_s": round(self.sim_time_s, 3),
            "wall_time_s": round(self.wall_time_s, 3),
            "coverage": round(self.coverage, 4),
            "found": self.found,
            "chosen": self.chosen,
            "delivered": self.delivered,
            "replans": self.replans,
            "plans": self.plans,
            "messages": self.messages,
            "robots": self.robots,
            "crashed": self.crashed,
            "replicas": self.replicas,
            **({"processes": True, "world_server": self.world_server} if self.world_server is not None else {}),
        }


def check_config(config: LunarConfig) -> None:
    """Raise a clear error for a configuration that cannot run.

    Raises:
        AlicaError: unknown robots, bad counts, a goal that is not a conjunction of at(s, g).
    """
    unknown = [r for r in config.robots if r not in ROLES]
    if unknown or not config.robots or len(set(config.robots)) != len(config.robots):
        raise AlicaError(
            f"--agents: {', '.join(config.robots) or 'none'}: name each of {', '.join(ROLES)} at most once"
        )
    if config.samples < 1 or config.rocks < 0:
        raise AlicaError(f"--samples must be >= 1 and --rocks >= 0, got {config.samples} and {config.rocks}")
    if config.pick < 1:
        raise AlicaError(f"the operator must pick at least one sample, got {config.pick}")
    if not config.time_limit > 0:
        raise AlicaError(f"--time-limit must be a positive number of seconds, not {config.time_limit}")
    if config.collect and config.goal:
        raise AlicaError("give --collect KINDS or --goal FORMULA, not both")
    if config.collect:
        from alica.worldsim.objects import SAMPLE_KINDS

        wrong = [k for k in config.collect if k not in SAMPLE_KINDS]
        if wrong:
            raise AlicaError(f"--collect: unknown kind(s) {', '.join(wrong)}; the kinds are {', '.join(SAMPLE_KINDS)}")
    if config.goal is not None:
        goal_samples(config.goal)
    for crash in config.crashes:
        if crash.robot not in config.robots:
            raise AlicaError(f"--crash: '{crash.robot}' is not in the team ({', '.join(config.robots)})")
    for cut in config.partitions:
        strangers = [r for g in cut.groups for r in g if r not in config.robots]
        if strangers:
            raise AlicaError(f"--partition: {', '.join(strangers)} not in the team ({', '.join(config.robots)})")


def goal_samples(goal: str) -> list[str]:
    """The samples a goal brings to g, in order.

    Raises:
        AlicaError: the goal is not a conjunction of ``at(sample, g)``.
    """
    from alica.lang import literals

    try:
        found = literals(goal)
    except AlicaError as exc:
        raise AlicaError(f"--goal: '{goal}' is not a conjunction of at(sample, g): {exc}") from None
    names = []
    for positive, pred, args in found:
        if not positive or pred != "at" or len(args) != 2 or str(args[1]) != BASE:
            raise AlicaError(f"--goal: '{goal}': write at(sample, g) and at(sample, g) ..., one literal per sample")
        names.append(str(args[0]))
    if not names:
        raise AlicaError(f"--goal: '{goal}' names no sample")
    return names


def kind_name(kind: str) -> str:
    """The name a detection gives a sample of ``kind`` first seen (``green-white-red`` -> ``green_white_red``)."""
    return kind.replace("-", "_")


class Operator:
    """Reads the found samples from the team's world model, chooses, and sets the goal (see the module docstring)."""

    def __init__(self, config: LunarConfig) -> None:
        self.config = config
        self.wanted = goal_samples(config.goal) if config.goal is not None else []
        self.found: dict[str, str] = {}
        self.places: dict[str, tuple[float, float]] = {}
        self.order: list[str] = []  # the found samples, by when they were found (found_at), then name
        self.found_at: dict[str, float] = {}
        self.chosen: list[str] = []
        self.reason = ""

    def read(self, team: SimulatedTeam) -> bool:
        """Update the found samples from the running agents' world models; whether ``explored`` holds."""
        return self.read_models(engine.world_model for engine in team.running())

    def read_models(self, models: Iterable[WorldModelLike]) -> bool:
        """Update the found samples from these world models (the team's replicas); whether ``explored`` holds."""
        explored = False
        for wm in models:
            explored = explored or wm.holds("explored")
            for fact in wm.facts():
                if fact.predicate != "found" or len(fact.args) != 1:
                    continue
                name = str(fact.args[0])
                kind = wm.get("sample_kind", name)
                place = wm.get("pos", name)
                if name not in self.found:
                    self.order.append(name)
                self.found[name] = str(kind) if kind is not None else self.found.get(name, "")
                if isinstance(place, (tuple, list)) and len(place) == 2:
                    self.places[name] = (float(place[0]), float(place[1]))
                when = wm.get("found_at", name)
                if isinstance(when, (int, float)):
                    self.found_at[name] = min(float(when), self.found_at.get(name, math.inf))
        if not self.chosen:  # by when the team found them (then name), not by when their facts arrived (messages race)
            self.order.sort(key=lambda s: (self.found_at[s], s) if s in self.found_at else (math.inf, ""))
        return explored

    def choose(self, explored: bool) -> list[str] | None:
        """The samples to bring back now, or None to wait; ``[]`` when there is nothing to choose (see :attr:`reason`)."""
        if self.wanted:
            ready = [s for s in self.wanted if s in self.found]
            if len(ready) == len(self.wanted) or (explored and ready):
                return ready
        elif self.config.collect:
            picked: list[str] = []
            for kind in self.config.collect:
                match = next((s for s in self.order if self.found.get(s) == kind and s not in picked), None)
                if match is not None:
                    picked.append(match)
            if len(picked) == len(self.config.collect) or (explored and picked):
                return picked
        elif len(self.order) >= self.config.pick or (explored and self.order):
            return self.order[: self.config.pick]
        if explored:
            self.reason = "the field is explored and no sample the operator wants was found"
            return []
        return None

    def goal(self) -> str:
        """The goal of GetObjects for the chosen samples."""
        return " and ".join(f"at({s}, {BASE})" for s in self.chosen)


def run_lunar(
    config: LunarConfig,
    *,
    observers: Iterable[Observer] = (),
    on_second: Callable[[dict[str, Any]], None] | None = None,
    out: Path | None = None,
    gui: bool = False,
    prepare_world: Callable[[World], None] | None = None,
    live: LiveSession | None = None,
    ros2: Ros2Output | None = None,
) -> LunarResult:
    """Run the lunar mission once (see the module docstring).

    The result's ``replicas`` (see :meth:`LunarResult.as_json`) tells whether the running
    robots' world models agree at the end of the run: the same found samples, the same team map.

    Args:
        config: what to run.
        observers: trace observers (every event of the team).
        on_second: called once per simulated second with the progress (``time``, ``coverage``,
            ``found``, ``delivered``, ``chosen``, ``replans``).
        out: a folder for the trace (``trace.jsonl``), the map picture (``map.png``) and the
            generated plan (``plan.yaml``).
        gui: show the pybullet window.
        prepare_world: called with the simulated world (:class:`alica.worldsim.World`) once the
            field is built and before the team exists, to change it (add rocks, move a sample...);
            for tests and experiments.
        live: the control center of the run (``--center``): it serves the page and paces the run.
        ros2: where the robots' ROS 2 topics go (``--ros2``, ``--record``; :mod:`alica.app.ros2_output`),
            after every tick in simulated time; the caller closes it.

    Raises:
        AlicaError: a bad configuration.
    """
    from alica.app.trace_world import MAP_EVERY, WorldTrace, tee, world_header
    from alica.engine import JsonlTrace, SimulatedTeam, trace_header
    from alica.io import load_library
    from alica.lang import literals
    from alica.lang.skill_plugins import default_registry
    from alica.prophet import engine_config
    from alica.skills.motion import configure_ompl
    from alica.worldsim.scenarios import lunar

    check_config(config)
    configure_ompl(config.seed)  # OMPL's generator is per process: seed it before any planner exists
    library = load_library(MISSION)
    world = lunar(config.seed, rocks=config.rocks, samples=config.samples, size=config.size, **_gui(gui))
    counter = StepCounter(library.abstract(PROBLEM).elements, PROBLEM)  # type: ignore[union-attr]
    header = trace_header(
        plans=[f"alica:plans/{MISSION.relative_to(plans_dir()).as_posix()}"],
        root=PLAN,
        agents={name: ROLES[name] for name in config.robots},
        seed=config.seed,
        frequency=config.frequency,
        demo="lunar",
        field={"samples": config.samples, "rocks": config.rocks, "size": config.size},
        **world_header(world, "lunar", map_every=MAP_EVERY),
    )
    trace = JsonlTrace(out / "trace.jsonl", header=header) if out is not None else None
    hub = live.start(header, library) if live is not None else None
    sinks = [s for s in (trace, hub) if s is not None]
    watchers: list[Observer] = [counter, *observers, *sinks]
    settings = engine_config(frequency=config.frequency)
    try:
        if prepare_world is not None:
            prepare_world(world)
        team = SimulatedTeam(
            library,
            PLAN,
            {name: ROLES[name] for name in config.robots},
            seed=config.seed,
            config=settings,
            loss=config.loss,
            delay=config.delay,
            skill_registry=default_registry(),
            observers=watchers,
            world=world,
        )
        # (robots share their poses from their world skills here, not after every tick as in alica run and
        # alica agent: sharing every tick changed seed 3's run with Amparo crashed at the grasp so that
        # Stummel's putdown at g found no place pose; see the issue 38 note)
        base = world.objects[BASE].position()
        _mission_knowledge(team, world, (float(base[0]), float(base[1])))
        for crash in config.crashes:
            if crash.at is not None:
                team.crash(crash.robot, at=crash.at)
        for cut in config.partitions:
            team.partition([list(g) for g in cut.groups], start=cut.start, end=cut.end)
        team.set_facts(literals("start"), at=0.0)
        run = _Run(config, team, world, (float(base[0]), float(base[1])), tee(sinks) if sinks else None)
        if sinks:
            sample = WorldTrace(tee(sinks), world, alive=lambda name: name not in team.crashed, team_map=run.team_map)
            sample(team.now())
            team.after_tick(sample)
        if ros2 is not None:
            ros2.attach_team(team, library)
        if live is not None:
            team.after_tick(lambda now: live.pace(team))
        wall = time.perf_counter()
        run.loop(on_second, counter)
        wall = time.perf_counter() - wall
        made = _made_plans(team)
        plan_yaml = plan_yaml_text(made[-1], MISSION, out) if made else ""
        coverage = run.coverage()
        if out is not None:
            out.mkdir(parents=True, exist_ok=True)
            from alica.app.demos.lunar_map import draw_map

            draw_map(world, run.team_map(), run.operator, run.tracks, run.crash_places, out / "map.png", run.targets)
            if plan_yaml:
                (out / "plan.yaml").write_text(plan_yaml, encoding="utf-8")
                folder = out / "plans"
                folder.mkdir(exist_ok=True)
                for created in made:
                    text = plan_yaml_text(created, MISSION, folder)
                    (folder / f"{created.plan.name}.yaml").write_text(text, encoding="utf-8")
        operator = run.operator
        delivered = run.delivered()
        success = bool(operator.chosen) and len(delivered) == len(operator.chosen)
        reason = "" if success else (operator.reason or run.why_not(counter))
        return LunarResult(
            success=success,
            reason=reason,
            sim_time_s=run.reached if run.reached is not None else world.now(),
            wall_time_s=wall,
            coverage=coverage,
            found={name: operator.found[name] for name in operator.order},
            chosen=list(operator.chosen),
            delivered=delivered,
            replans=counter.replans,
            plans=len(counter.plans),
            messages=team.network.stats.sent,
            robots=run.robots_json(counter, team.crashed),
            plan_yaml=plan_yaml,
            crashed=sorted(team.crashed),
            replicas=replica_views(team),
        )
    finally:
        if trace is not None:
            trace.close()
        world.close()


def _made_plans(team: SimulatedTeam) -> list[CreatedTasks]:
    """Every plan the team generated (each once, crashed agents' too), in the order of generation and version."""
    from alica.prophet import made_plans

    seen: dict[str, tuple[int, int, CreatedTasks]] = {}
    for engine in team.engines.values():
        for generation, version, created in made_plans(engine):
            seen.setdefault(created.plan.name, (generation, version, created))
    return [created for _, _, created in sorted(seen.values(), key=lambda m: (m[0], m[1], m[2].plan.name))]


def replica_views(team: SimulatedTeam) -> dict[str, Any]:
    """What each running robot's replica of the world model holds, and whether they agree.

    Returns:
        ``{"agree": bool, "found": {robot: sorted found samples}, "map_digest": {robot: hash}}``:
        ``found`` lists the ``found(s)`` facts, ``map_digest`` is a short hash of the team map
        grid (:func:`alica.skills.mapping.team_map`; ``""`` before the robot has a map), and
        ``agree`` holds when every running robot has the same of both.
    """
    import hashlib

    from alica.skills.mapping import team_map

    found: dict[str, list[str]] = {}
    digest: dict[str, str] = {}
    for name, engine in team.engines.items():
        if name in team.crashed:
            continue
        wm = engine.world_model
        found[name] = sorted(str(f.args[0]) for f in wm.facts() if f.predicate == "found" and len(f.args) == 1)
        grid = team_map(wm)
        if grid is None:
            digest[name] = ""
        else:
            frame = repr((grid.resolution, grid.origin, grid.logodds.shape)).encode()
            digest[name] = hashlib.sha256(frame + grid.logodds.tobytes()).hexdigest()[:12]
    agree = len({tuple(v) for v in found.values()}) <= 1 and len(set(digest.values())) <= 1
    return {"agree": agree, "found": found, "map_digest": digest}


def _gui(gui: bool) -> dict[str, bool]:
    return {"gui": True} if gui else {}


def _mission_knowledge(team: SimulatedTeam, world: World, base: tuple[float, float]) -> None:
    """What every robot knows at the start: where g is, and whether its own hand is empty."""
    for name, engine in team.engines.items():
        wm = engine.world_model
        wm.add_object(BASE, "location")
        wm.set("pos", BASE, value=(round(base[0], 3), round(base[1], 3)))
        robot = world.robots[name]
        if robot.arm is not None:
            wm.assert_fact("handempty", name)


class _Run:
    """The loop of one run: ticks, the operator, faults at a grasp, scoring against the simulated world."""

    def __init__(
        self,
        config: LunarConfig,
        team: SimulatedTeam,
        world: World,
        base: tuple[float, float],
        trace: Observer | None = None,
    ) -> None:
        self.config = config
        self.trace = trace  # where ``found`` events go (the trace file), if anywhere
        self.team = team
        self.world = world
        self.base = base
        self.operator = Operator(config)
        self.targets: dict[str, str] = {}  # chosen sample -> the world's sample it is (for scoring only)
        self.reached: float | None = None
        self.distance = dict.fromkeys(config.robots, 0.0)
        self.tracks: dict[str, list[tuple[float, float]]] = {n: [] for n in config.robots}
        self.crash_places: dict[str, tuple[float, float]] = {}
        self.truth_free: np.ndarray | None = None
        self._coverage = 0.0
        self._coverage_at = -math.inf

    def loop(self, on_second: Callable[[dict[str, Any]], None] | None, counter: StepCounter) -> None:
        team, world = self.team, self.world
        at_grasp = {c.robot for c in self.config.crashes if c.at is None}
        last = {n: world.robots[n].pose[:2] for n in self.config.robots}
        next_second = 0.0
        while True:
            team.tick()
            now = world.now()
            for name in self.config.robots:
                x, y = world.robots[name].pose[:2]
                self.distance[name] += math.hypot(x - last[name][0], y - last[name][1])
                last[name] = (x, y)
                if name in at_grasp and name not in team.crashed and _lifts_sample(world, name):
                    team.crash(name)
                    at_grasp.discard(name)
                if name in team.crashed and name not in self.crash_places:
                    self.crash_places[name] = (x, y)
            if now >= next_second:
                next_second = now + 1.0
                for name in self.config.robots:
                    self.tracks[name].append(last[name])
                if self._operate(now):
                    break
                if on_second is not None:
                    on_second(self.progress(now, counter))
            if self.operator.chosen and len(self.delivered()) == len(self.operator.chosen):
                if self.reached is None:
                    self.reached = now
                if team.done() or now - self.reached >= SETTLE_S:
                    break
            elif team.done() or now >= self.config.time_limit:
                break
        if on_second is not None:
            on_second(self.progress(world.now(), counter))

    def read(self) -> bool:
        """The operator reads the team's world models; whether ``explored`` holds."""
        return self.operator.read(self.team)

    def _operate(self, now: float) -> bool:
        """The operator's second: read, and choose once; True when the run cannot go on."""
        operator = self.operator
        known = set(operator.order)
        explored = self.read()
        if self.trace is not None:
            for name in (name for name in operator.order if name not in known):
                x, y = operator.places.get(name, (math.nan, math.nan))
                self.trace(
                    {
                        "t": round(now, 6),
                        "agent": "-",
                        "event": "found",
                        "name": name,
                        "kind": operator.found.get(name, ""),
                        "x": round(x, 3) if math.isfinite(x) else None,
                        "y": round(y, 3) if math.isfinite(y) else None,
                    }
                )
        if operator.chosen:
            return False
        choice = operator.choose(explored)
        if choice is None:
            return False
        if not choice:
            return True
        operator.chosen = choice
        self.targets = self._world_samples(choice)
        self.command(operator.goal(), now)
        return False

    def command(self, goal: str, now: float) -> None:
        """Tell the team the goal of GetObjects and that the operator has chosen."""
        from alica.lang import literals

        for engine in self.team.engines.values():
            engine.set_problem(PROBLEM, goal=goal)
        self.team.set_facts(literals("chosen"), at=now)

    def _world_samples(self, chosen: Sequence[str]) -> dict[str, str]:
        """Each chosen sample's simulated body: the world's sample nearest to where it was found (scoring only)."""
        bodies = {n: o for n, o in self.world.objects.items() if o.kind == "sample"}
        out: dict[str, str] = {}
        for name in chosen:
            where = self.operator.places.get(name)
            if where is None or not bodies:
                continue
            out[name] = min(bodies, key=lambda n: math.dist(bodies[n].position()[:2], where))
        return out

    def delivered(self) -> list[str]:
        """The chosen samples resting within DELIVERED_WITHIN of g, in no gripper (ground truth, for scoring)."""
        held = {_held_name(r) for r in self.world.robots.values()}
        out = []
        for name in self.operator.chosen:
            body = self.world.objects.get(self.targets.get(name, ""))
            if body is None or body.name in held:
                continue
            x, y, z = body.position()
            if math.hypot(x - self.base[0], y - self.base[1]) <= DELIVERED_WITHIN and z < 0.3:
                out.append(name)
        return out

    def robots_json(self, counter: StepCounter, crashed: Iterable[str]) -> dict[str, dict[str, Any]]:
        """Each robot's part of the result: role, tasks and steps of generated plans, distance, crashed."""
        out = set(crashed)
        return {
            name: {
                "role": ROLES[name],
                "tasks": len(counter.tasks.get(name, set())),
                "steps": counter.steps.get(name, 0),
                "distance_m": round(self.distance[name], 2),
                "crashed": name in out,
            }
            for name in self.config.robots
        }

    def team_map(self) -> LogOddsGrid | None:
        from alica.app.trace_world import team_grid

        return team_grid(self.team)

    def coverage(self) -> float:
        """The share of the truly free cells the team map knows (ground truth, for scoring)."""
        from alica.skills.exploration import coverage
        from alica.worldsim.grid import OccupancyGrid

        grid = self.team_map()
        if grid is None:
            return 0.0
        if self.truth_free is None or self.truth_free.shape != (grid.ny, grid.nx):
            truth = OccupancyGrid.from_obstacles(
                self.world.ground_truth_obstacles(), self.world.bounds, grid.resolution
            )
            self.truth_free = truth.cells == 0
        return coverage(grid.occupancy(), self.truth_free)

    def progress(self, now: float, counter: StepCounter) -> dict[str, Any]:
        if now - self._coverage_at >= COVERAGE_EVERY:
            self._coverage_at = now
            self._coverage = self.coverage()
        return {
            "time": now,
            "limit": self.config.time_limit,
            "coverage": self._coverage,
            "found": len(self.operator.found),
            "chosen": len(self.operator.chosen),
            "delivered": len(self.delivered()),
            "replans": counter.replans,
        }

    def why_not(self, counter: StepCounter) -> str:
        operator = self.operator
        if not operator.chosen:
            return f"no choice within {self.config.time_limit:g} s: found {', '.join(operator.order) or 'nothing'}"
        missing = [s for s in operator.chosen if s not in self.delivered()]
        if self.world.now() >= self.config.time_limit:
            return f"time limit: {', '.join(missing)} not at {BASE} after {self.config.time_limit:g} s"
        ended = f"the mission ended with {', '.join(missing)} not at {BASE}"
        return (
            f"{ended}; GetObjects failed ({counter.gave_up}) and the team ran ReturnToBase"
            if counter.gave_up
            else ended
        )


def _held_name(robot: Robot) -> str | None:
    held = robot.arm.held if robot.arm is not None else None
    return held.name if held is not None else None


def _lifts_sample(world: World, name: str) -> bool:
    """Whether robot ``name`` holds a sample lifted off the ground (the grasp is done; the lift is under way)."""
    held = _held_name(world.robots[name])
    obj = world.objects.get(held) if held is not None else None
    return obj is not None and obj.kind == "sample" and float(obj.aabb()[0][2]) > LIFTED_ABOVE


def summary_lines(result: LunarResult) -> list[str]:
    """The human summary of a run."""
    state = "success" if result.success else f"failed: {result.reason}"
    lines = [
        f"lunar: {state} after {result.sim_time_s:.1f} s simulated, {result.wall_time_s:.1f} s wall",
        f"coverage {result.coverage:.0%}; found {len(result.found)} sample(s): "
        + (", ".join(f"{n} ({k})" for n, k in result.found.items()) or "none"),
        f"chosen {', '.join(result.chosen) or 'none'}; delivered {', '.join(result.delivered) or 'none'}",
        f"plans made {result.plans}, replans {result.replans}, messages sent {result.messages}",
    ]
    for name, robot in result.robots.items():
        crashed = " (crashed)" if robot["crashed"] else ""
        lines.append(
            f"  {name} ({robot['role']}){crashed}: drove {robot['distance_m']:.1f} m; "
            f"{robot['steps']} step(s) in {robot['tasks']} task(s) of generated plans"
        )
    return lines


def parse_crash(text: str) -> Crash:
    """``NAME@T`` or ``NAME@grasp``.

    Raises:
        AlicaError: neither form.
    """
    who, sep, when = text.partition("@")
    if not sep or not who:
        raise AlicaError(f"--crash: '{text}' is not NAME@T or NAME@grasp, e.g. scout@30 or amparo@grasp")
    if when == "grasp":
        return Crash(who, None)
    try:
        at = float(when)
    except ValueError:
        raise AlicaError(f"--crash: '{text}': '{when}' is neither seconds nor 'grasp'") from None
    if not (at >= 0 and math.isfinite(at)):
        raise AlicaError(f"--crash: '{text}': the time must be a number of seconds >= 0")
    return Crash(who, at)
