"""ProTaP in the lunar world: a grid laid over a pybullet field, and the executor that runs each step's actions as skills.

The application layer brings the two siblings together: the dispatch loop of
:mod:`alica.prophet.protap.dispatch` (planning, no world) and the skills
acting in a :mod:`alica.worldsim` world, run at once by
:func:`alica.skills.together.run_together`.

**The grid in metres** (:class:`GridLayout`). Cell ``(x, y)`` is a square of
``cell`` metres; the grid is centred on the origin with a border of ``border``
metres around it. Each robot has its own *slot* in every cell, on a circle of
``0.3 x cell`` around the centre at the angle ``2 pi i / robots + pi / 4``
(robot ``i``): robots sharing a cell never stand on each other. A goal's
sample container stands at its cell's centre. A position is in the cell whose
square holds it (the nearest cell centre), clamped to the grid.

**The executor** (:class:`LunarExecutor`): each robot of a step gets one
sequence of skills, and all robots run at once (Algorithm 1's asynchronous
calls of one plan step):

* its ``do`` first, where the robot stands at the start of the step (the
  domain's rule): a *manipulation* action is ``Pickup`` of the goal's sample,
  then ``Putdown`` of it at the cell's centre again (take it up, set it down:
  Pickup may bring the base a little nearer the sample first, within the
  cell); a *user-defined* action (``uda``) is a registered skill chosen by
  name (default ``DetectCircles`` with a short ``max_range``: the robot scans
  with its 2D lidar and succeeds when a sample-sized circle is within reach,
  i.e. it confirms the sample is there). A ``do`` where no goal of its action
  lies fails at once: there is no sample to act on;
* then its ``goto``: ``MoveToPosition`` to the robot's slot in the target cell.

A step ends when every robot's skills have ended, or after ``step_timeout``
simulated seconds: a skill still running is then stopped and its action
fails. The observed cell of a robot is the cell of its position in the world
after the step; a goto succeeds when MoveToPosition succeeded and the robot
stands in the target cell. Faults for tests and demos: :class:`GotoFault`
crashes a robot (a worldsim fault) the moment its goto of a given step
starts, and powers it up again when the step ends, so the goto really fails
and the next step is planned from where the robot really is.
"""

from __future__ import annotations

import math
import random
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from alica.errors import AlicaError, SkillError
from alica.prophet.protap.dispatch import (
    Activity,
    ChooseStep,
    Episode,
    RobotCalls,
    RobotOutcome,
    StepRecord,
    run_dispatched,
)
from alica.prophet.protap.model import ProtapModel
from alica.prophet.protap.spec import MANIPULATION, Cell, ProblemSpec

if TYPE_CHECKING:
    from alica.lang.skills import SkillRegistry
    from alica.skills.together import RobotRuns, SkillCall
    from alica.worldmodel.protocol import WorldModelLike
    from alica.worldsim.world import World

#: The robot kind of every ProTaP robot in the lunar world: a base, an arm with a gripper, a 2D lidar and a camera.
ROBOT_KIND = "stummel"
#: The default skill of a user-defined action.
DEFAULT_UDA_SKILL = "DetectCircles"
#: The longest side (m) of a lunar field for ProTaP: a robot crosses its diagonal in about 70 s.
MAX_FIELD = 40.0
#: The smallest cell (m): the slots of several robots and the sample must fit in it.
MIN_CELL = 2.5
#: A robot's slot lies this fraction of the cell size from the cell's centre.
SLOT_FRACTION = 0.3
#: Free room (m) between two robots' footprints at neighbouring slots.
SLOT_GAP = 0.2
#: How near (m) MoveToPosition must bring a robot to its slot.
GOTO_TOLERANCE = 0.25


@dataclass(frozen=True, slots=True)
class GridLayout:
    """Where the cells of a ProTaP grid and the robots' slots in them lie on the field, in metres.

    Args:
        width: the number of columns.
        height: the number of rows.
        robots: the number of robots (each has its own slot in every cell).
        cell: the side of a cell in metres.
        border: free room around the grid in metres.

    Raises:
        AlicaError: a cell too small, a field larger than :data:`MAX_FIELD`,
            or more robots than fit around a cell (the message says which option to change).
    """

    width: int
    height: int
    robots: int
    cell: float = 3.0
    border: float = 1.5

    def __post_init__(self) -> None:
        from alica.worldsim.robots import ROBOT_KINDS

        if not (math.isfinite(self.cell) and self.cell >= MIN_CELL):
            raise AlicaError(f"a cell of {self.cell:g} m is too small: cells are at least {MIN_CELL:g} m (--cell-size)")
        side = max(self.width, self.height) * self.cell + 2 * self.border
        if side > MAX_FIELD:
            raise AlicaError(
                f"a {self.width}x{self.height} grid of {self.cell:g} m cells needs a field of {side:g} m, and the "
                f"lunar field holds at most {MAX_FIELD:g} m: use a smaller --grid or --cell-size"
            )
        radius = ROBOT_KINDS[ROBOT_KIND].radius
        if self.robots > 1 and 2 * self.slot_radius * math.sin(math.pi / self.robots) < 2 * radius + SLOT_GAP:
            fit = max(
                n
                for n in range(1, 64)
                if n == 1 or 2 * self.slot_radius * math.sin(math.pi / n) >= 2 * radius + SLOT_GAP
            )
            raise AlicaError(
                f"{self.robots} robots do not fit around a cell of {self.cell:g} m (every robot has its own place "
                f"in every cell): use at most {fit} robots or a larger --cell-size"
            )

    @property
    def slot_radius(self) -> float:
        """The distance (m) from a cell's centre to the robots' slots."""
        return SLOT_FRACTION * self.cell

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The field ``(xmin, ymin, xmax, ymax)``: the grid and its border, centred on the origin."""
        half_x = 0.5 * self.width * self.cell + self.border
        half_y = 0.5 * self.height * self.cell + self.border
        return (-half_x, -half_y, half_x, half_y)

    def centre(self, cell: Cell) -> tuple[float, float]:
        """The centre of ``cell`` in metres."""
        return (
            (cell[0] + 0.5 - 0.5 * self.width) * self.cell,
            (cell[1] + 0.5 - 0.5 * self.height) * self.cell,
        )

    def slot_angle(self, robot: int) -> float:
        """The direction (rad) from a cell's centre to robot ``robot``'s slot."""
        return 2.0 * math.pi * robot / max(1, self.robots) + 0.25 * math.pi

    def slot(self, cell: Cell, robot: int) -> tuple[float, float]:
        """Where robot ``robot`` stands in ``cell``."""
        cx, cy = self.centre(cell)
        angle = self.slot_angle(robot)
        return (cx + self.slot_radius * math.cos(angle), cy + self.slot_radius * math.sin(angle))

    def start_pose(self, cell: Cell, robot: int) -> tuple[float, float, float]:
        """Robot ``robot``'s start pose in ``cell``: at its slot, facing the centre."""
        x, y = self.slot(cell, robot)
        return (x, y, math.remainder(self.slot_angle(robot) + math.pi, 2.0 * math.pi))

    def cell_at(self, x: float, y: float) -> Cell:
        """The cell a position lies in (the nearest cell centre), clamped to the grid."""
        column = math.floor(x / self.cell + 0.5 * self.width)
        row = math.floor(y / self.cell + 0.5 * self.height)
        return (min(max(column, 0), self.width - 1), min(max(row, 0), self.height - 1))

    def keep_clear(self) -> list[tuple[float, float, float]]:
        """Discs no rock may touch: around every cell's centre, its sample and every robot's slot with room to spare."""
        from alica.worldsim.robots import ROBOT_KINDS

        radius = self.slot_radius + ROBOT_KINDS[ROBOT_KIND].radius + 0.3
        return [(*self.centre((x, y)), radius) for x in range(self.width) for y in range(self.height)]


@dataclass(frozen=True, slots=True)
class GotoFault:
    """Crash ``robot`` when its goto of step ``step`` (1 for the first) starts; power it up when the step ends."""

    robot: str
    step: int


def sample_of(spec: ProblemSpec) -> dict[Cell, str]:
    """The sample container at each goal cell: the goal's name (one goal per cell).

    Raises:
        AlicaError: two goals share a cell (one container stands at a cell's centre).
    """
    out: dict[Cell, str] = {}
    for goal in spec.goals:
        if goal.cell in out:
            raise AlicaError(
                f"goals {out[goal.cell]} and {goal.name} share the cell {goal.cell}: the lunar world puts one sample "
                "container per goal at its cell's centre"
            )
        out[goal.cell] = goal.name
    return out


def build_world(spec: ProblemSpec, layout: GridLayout, *, seed: int = 0, rocks: int = 4) -> World:
    """The lunar field of a spec: a stummel per robot at its slot of its start cell, a sample per goal, rocks.

    Raises:
        AlicaError: the robots, samples or rocks do not fit (the message says why).
    """
    from alica.worldsim.errors import WorldError
    from alica.worldsim.objects import SAMPLE_KINDS
    from alica.worldsim.scenarios import lunar_sites

    samples = sample_of(spec)
    robots = [(robot.name, ROBOT_KIND, layout.start_pose(robot.cell, i)) for i, robot in enumerate(spec.robots)]
    containers = [
        (name, SAMPLE_KINDS[g % len(SAMPLE_KINDS)], layout.centre(cell))
        for g, (cell, name) in enumerate(sorted(samples.items(), key=lambda item: item[1]))
    ]
    try:
        return lunar_sites(
            seed,
            bounds=layout.bounds,
            robots=robots,
            samples=containers,
            rocks=rocks,
            keep_clear=layout.keep_clear(),
        )
    except WorldError as exc:
        raise AlicaError(f"cannot build the lunar field for the ProTaP grid: {exc}") from None


@dataclass(frozen=True, slots=True)
class UdaSkill:
    """The skill a user-defined action runs, with the parameters the executor gives it.

    Attributes:
        name: the registered skill.
        params: its fixed parameters (besides ``object``).
        takes_object: the skill declares ``object``: it gets the goal's sample.
    """

    name: str
    params: Mapping[str, object] = field(default_factory=dict)
    takes_object: bool = False


def uda_skill(registry: SkillRegistry, name: str, layout: GridLayout) -> UdaSkill:
    """Check the ``--uda-skill`` and say how to call it.

    The default, ``DetectCircles``, gets ``max_range`` = the slot radius +
    0.6 m: the robot scans its own cell only.

    Raises:
        AlicaError: no such skill, no implementation, a capability a stummel
            lacks, or a required parameter the dispatcher cannot give.
    """
    from alica.worldsim.robots import ROBOT_KINDS

    if name not in registry:
        near = [n for n in registry.names() if n.lower().startswith(name[:3].lower())] or registry.names()[:8]
        raise AlicaError(f"--uda-skill {name}: no skill of that name is registered (e.g. {', '.join(near)})")
    spec = registry.get(name)
    if spec.implementation is None:
        raise AlicaError(f"--uda-skill {name}: the skill is declared but has no implementation to run")
    missing = sorted(spec.capabilities - ROBOT_KINDS[ROBOT_KIND].capabilities)
    if missing:
        raise AlicaError(f"--uda-skill {name}: the skill needs {', '.join(missing)}, which a {ROBOT_KIND} lacks")
    takes_object = spec.param("object") is not None
    needs = [p.name for p in spec.params if p.required and p.name != "object"]
    if needs:
        raise AlicaError(
            f"--uda-skill {name}: the dispatcher cannot give the required parameter(s) {', '.join(needs)}; "
            "choose a skill whose parameters have defaults (it may take 'object', the goal's sample)"
        )
    params: dict[str, object] = {}
    if name == DEFAULT_UDA_SKILL:
        params["max_range"] = round(layout.slot_radius + 0.6, 2)
    return UdaSkill(name, params, takes_object)


class LunarExecutor:
    """Runs each step's gotos and dos as skills of the robots in a lunar world, all robots at once.

    Args:
        world: the world (robots named as in the spec).
        spec: the problem.
        layout: the grid in metres.
        registry: where the skills come from.
        uda: the skill of user-defined actions (:func:`uda_skill`).
        step_timeout: the simulated seconds a step may take.
        rate: skill ticks per simulated second.
        seed: seeds the skills' random sources.
        faults: gotos to make fail (:class:`GotoFault`).

    Attributes:
        steps: the steps run so far.
        world_models: each robot's world model, kept for the whole run.
    """

    def __init__(
        self,
        world: World,
        spec: ProblemSpec,
        layout: GridLayout,
        registry: SkillRegistry,
        uda: UdaSkill,
        *,
        step_timeout: float = 120.0,
        rate: float = 10.0,
        seed: int = 0,
        faults: Sequence[GotoFault] = (),
    ) -> None:
        from alica.worldmodel import WorldModel

        self.world = world
        self.spec = spec
        self.layout = layout
        self.registry = registry
        self.uda = uda
        self.step_timeout = step_timeout
        self.rate = rate
        self.seed = seed
        self.faults = tuple(faults)
        self.samples = sample_of(spec)
        self.steps = 0
        self.world_models: dict[str, WorldModelLike] = {
            robot.name: WorldModel(robot.name, clock=world.clock) for robot in spec.robots
        }

    def _do_skills(self, call: RobotCalls) -> list[SkillCall]:
        from alica.skills.together import SkillCall

        assert call.do is not None
        sample = self.samples.get(call.start)
        if call.do.kind == MANIPULATION:
            assert sample is not None
            target = [round(v, 3) for v in self.layout.centre(call.start)]
            return [
                SkillCall("Pickup", {"object": sample}, label="do"),
                SkillCall("Putdown", {"object": sample, "target": target}, chained=True, label="do"),
            ]
        params = dict(self.uda.params)
        if self.uda.takes_object and sample is not None:
            params["object"] = sample
        return [SkillCall(self.uda.name, params, label="do")]

    def execute(self, calls: Sequence[RobotCalls]) -> list[RobotOutcome]:
        """Run one step's calls as skills, all robots at once, and observe where the robots are."""
        from alica.skills.together import SkillCall, run_together

        self.steps += 1
        sequences: dict[str, list[SkillCall]] = {}
        refused: dict[int, str] = {}
        for call in calls:
            skills: list[SkillCall] = []
            if call.do is not None:
                if call.do.goals:
                    skills.extend(self._do_skills(call))
                else:
                    refused[call.robot] = (
                        f"do({call.name}, {call.do.action}) at {call.start}: no goal of {call.do.action} there, "
                        "so no sample to act on"
                    )
            if call.goto is not None:
                goal = [round(v, 3) for v in self.layout.slot(call.goto, call.robot)]
                params = {"goal": goal, "tolerance": GOTO_TOLERANCE, "timeout": self.step_timeout}
                skills.append(SkillCall("MoveToPosition", params, label="goto"))
            if skills:
                sequences[call.name] = skills
        crashed: list[str] = []
        faulted = {fault.robot for fault in self.faults if fault.step == self.steps}

        def inject(world: World, robot: str, index: int) -> None:
            if robot in faulted and robot not in crashed and sequences[robot][index].label == "goto":
                world.faults.crash(robot)
                crashed.append(robot)

        try:
            runs = run_together(
                self.world,
                sequences,
                timeout=self.step_timeout,
                rate=self.rate,
                seed=self.seed,
                registry=self.registry,
                world_models={name: self.world_models[name] for name in sequences},
                on_tick=inject if faulted else None,
            )
        except SkillError as exc:
            raise AlicaError(f"step {self.steps}: a skill could not run: {exc}") from None
        finally:
            for robot in crashed:
                self.world.faults.recover(robot)
        return [
            self._outcome(call, runs.get(call.name), refused.get(call.robot), call.name in crashed) for call in calls
        ]

    def _outcome(self, call: RobotCalls, runs: RobotRuns | None, refused: str | None, crashed: bool) -> RobotOutcome:
        x, y, _ = self.world.robots[call.name].pose
        cell = self.layout.cell_at(float(x), float(y))
        reasons: list[str] = []
        activities: list[Activity] = []
        do_ok: bool | None = None
        goto_ok: bool | None = None
        if call.do is not None:
            do_ok = refused is None
            if refused is not None:
                reasons.append(refused)
        if runs is not None:
            for skill_call, run, start in zip(runs.calls, runs.runs, runs.starts, strict=True):
                begin = 0.0 if start is None else start
                activities.append(Activity(run.skill, run.status, run.reason, begin, begin + run.sim_time_s))
                if run.ok:
                    continue
                if skill_call.label == "do" and do_ok:
                    do_ok = False
                    reasons.append(f"do: {run.skill} {run.status}: {run.reason}")
                elif skill_call.label == "goto":
                    goto_ok = False
                    why = f"{run.reason} (robot crashed by the injected fault)" if crashed else run.reason
                    reasons.append(f"goto: {run.skill} {run.status}: {why}")
        if call.goto is not None:
            if goto_ok is None:
                goto_ok = cell == call.goto
                if not goto_ok:
                    reasons.append(f"goto: the robot stopped in cell {cell}, not {call.goto}")
        return RobotOutcome(call.robot, cell, do_ok, goto_ok, "; ".join(reasons), tuple(activities))


@dataclass(frozen=True, slots=True)
class LunarEpisode:
    """A dispatched episode in the lunar world.

    Attributes:
        episode: the steps, the reward and the goals done.
        sim_time_s: the simulated seconds the episode took.
        wall_time_s: the wall-clock seconds, building the world included.
    """

    episode: Episode
    sim_time_s: float
    wall_time_s: float


def run_lunar_episode(
    model: ProtapModel,
    choose_step: ChooseStep,
    registry: SkillRegistry,
    *,
    layout: GridLayout,
    uda: str = DEFAULT_UDA_SKILL,
    seed: int = 0,
    rocks: int = 4,
    horizon: int | None = None,
    step_timeout: float = 120.0,
    faults: Sequence[GotoFault] = (),
    rng: random.Random | None = None,
    on_step: Callable[[StepRecord], None] | None = None,
) -> LunarEpisode:
    """Build the lunar field of ``model``'s spec and dispatch one episode to it.

    Args:
        model: the problem's domain.
        choose_step: the policy (a planner's, say), called with the observed state of every step.
        registry: the skills (the shipped catalogue, plug-ins, ``--skills`` modules).
        layout: the grid in metres.
        uda: the skill of user-defined actions.
        seed: seeds the world, the rocks and the skills.
        rocks: rocks on the field.
        horizon: the steps (default: the spec's horizon).
        step_timeout: the simulated seconds a step may take.
        faults: gotos to make fail.
        rng: handed to ``choose_step``.
        on_step: called with each :class:`~alica.prophet.protap.dispatch.StepRecord` when its step ended.

    OMPL's random generator is seeded with ``seed`` if nothing in the process
    planned before (see :func:`alica.skills.motion.configure_ompl`): a run
    from a fresh process is the same for a seed.

    Raises:
        AlicaError: a bad ``--uda-skill``, a field that cannot be built, a fault
            naming no robot, or a skill that cannot run.
    """
    names = {robot.name for robot in model.spec.robots}
    for fault in faults:
        if fault.robot not in names:
            raise AlicaError(
                f"--fail-goto {fault.robot}@{fault.step}: no robot named {fault.robot} ({', '.join(sorted(names))})"
            )
    from alica.skills.motion import configure_ompl

    skill = uda_skill(registry, uda, layout)
    configure_ompl(seed)  # OMPL's generator is per process: seed it before any planner exists (the first call wins)
    started = time.perf_counter()
    with build_world(model.spec, layout, seed=seed, rocks=rocks) as world:
        executor = LunarExecutor(
            world, model.spec, layout, registry, skill, step_timeout=step_timeout, seed=seed, faults=faults
        )
        begin = world.now()
        episode = run_dispatched(model, choose_step, executor, horizon, rng=rng, on_step=on_step)
        sim_time = world.now() - begin
    return LunarEpisode(episode, sim_time, time.perf_counter() - started)
