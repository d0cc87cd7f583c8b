"""Run one skill alone in a small world, in simulated time: for users' tests and ``alica skill run``.

Example::

    from alica.worldsim.scenarios import lunar
    from alica.skills.testing import run_skill

    with lunar(seed=1, rocks=20) as world:
        run = run_skill("MoveToPosition", world, "scout", {"goal": [5.0, 5.0]})
        assert run.status == "success", run.reason

With pytest, the fixtures of :mod:`alica.skills.pytest_plugin` (``lunar_world``,
``blocks_world``, ``skill_run``) are available in every test.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.errors import SkillError
from alica.lang.fact import Fact
from alica.lang.skill_plugins import default_registry
from alica.lang.skills import SkillRegistry
from alica.skills.team_poses import POSE, SHARERS, share_pose
from alica.worldmodel.protocol import WorldModelLike

if TYPE_CHECKING:
    from py_trees.behaviour import Behaviour

    from alica.worldsim.world import World


@dataclass(slots=True)
class SkillRun:
    """What happened when a skill ran alone.

    Attributes:
        skill: the skill's name.
        robot: the robot that ran it.
        status: ``success``, ``failure`` or ``timeout``.
        reason: the skill's last feedback (why it failed, or what it did).
        sim_time_s: simulated seconds until it ended.
        ticks: skill ticks.
        trace: ``{"t", "status", "feedback"}`` whenever the feedback or status changed.
        facts: the world-model facts after the run (the outcome facts the skill wrote), sorted.
        values: the world-model function values after the run, such as ``values[Fact("pos", ("r1",))]``.
    """

    skill: str
    robot: str
    status: str
    reason: str
    sim_time_s: float
    ticks: int
    trace: list[dict[str, object]] = field(default_factory=list)
    facts: list[Fact] = field(default_factory=list)
    values: dict[Fact, object] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Whether the skill succeeded."""
        return self.status == "success"

    def holds(self, predicate: str, *args: object) -> bool:
        """Whether ``predicate(*args)`` is among the facts after the run."""
        return Fact(predicate, args) in self.facts


def checked_params(spec: Any, params: Mapping[str, object]) -> dict[str, object]:
    """The parameters with defaults filled in.

    Raises:
        SkillError: an unknown or missing parameter, or a value of the wrong type.
    """
    out: dict[str, object] = {}
    known = {p.name for p in spec.params}
    unknown = sorted(set(params) - known)
    if unknown:
        raise SkillError(
            f"skill '{spec.name}' has no parameter {', '.join(map(repr, unknown))} (parameters: {', '.join(sorted(known)) or 'none'})"
        )
    for p in spec.params:
        if p.name in params:
            value = params[p.name]
            if isinstance(value, list):
                value = tuple(value)
            problem = p.check(value)
            if problem is not None:
                raise SkillError(f"skill '{spec.name}': parameter '{p.name}' {problem}, got {value!r}")
            out[p.name] = value
        elif p.required:
            raise SkillError(f"skill '{spec.name}' needs the parameter '{p.name}' ({p.type}: {p.doc})")
        else:
            out[p.name] = p.default
    return out


class SkillSession:
    """One skill built from a registry for one robot of a world, ticked by its caller.

    The part of :func:`run_skill` that runs a skill: build the behaviour from
    the registry's implementation with the robot's world model, tick it, keep
    the trace of its status and feedback, stop it, and say what happened. A
    caller drives the time: :func:`run_skill` steps the world between the
    ticks of one session, :func:`alica.skills.together.run_together` between
    the ticks of several sessions on different robots.

    Args:
        name: the skill.
        world: the world it acts in.
        robot: the robot that runs it.
        params: the skill's parameters (defaults are filled in).
        registry: where the skill is declared and implemented.
        world_model: the robot's world model (a new one on the world's clock when omitted).
        seed: seeds the skill's ``random.Random`` (with the robot's name).
        scratch: the robot's scratch space, shared with the skills run before and after it.

    Attributes:
        name: the skill.
        robot: the robot.
        world_model: the robot's world model.
        behaviour: the py_trees behaviour (set up, not yet ticked).
        started: the simulated time the session was made.
        ticks: the ticks so far.
        status: ``running``, then ``success``, ``failure`` or ``timeout`` (stopped before it ended).
        trace: ``{"t", "status", "feedback"}`` whenever the feedback or status changed.

    Raises:
        SkillError: bad parameters, no such robot, or no implementation.
        UnknownSkillError: no skill of that name.
    """

    def __init__(
        self,
        name: str,
        world: World,
        robot: str,
        params: Mapping[str, object] | None,
        registry: SkillRegistry,
        *,
        world_model: WorldModelLike | None = None,
        seed: int = 0,
        scratch: dict[str, object] | None = None,
    ) -> None:
        from alica.engine.behaviours import SkillContext
        from alica.worldmodel import WorldModel

        spec = registry.get(name)
        values = checked_params(spec, params or {})
        if robot not in world.robots:
            raise SkillError(f"the world has no robot named '{robot}' (robots: {', '.join(sorted(world.robots))})")
        factory = registry.load(name)
        self.name = name
        self.robot = robot
        self.world = world
        self.world_model: WorldModelLike = (
            world_model if world_model is not None else WorldModel(robot, clock=world.clock)
        )
        belief: Any = self.world_model  # alone, the world model is the skill's whole belief base
        context = SkillContext(
            robot, world.now, self.world_model, belief, random.Random(f"{seed}:{robot}"), world, None, f"skill/{name}"
        )
        if scratch is not None:
            context.scratch = scratch  # shared with the skills run before and after: a pipeline, step by step
        self.behaviour: Behaviour = factory(name, values, context)
        self.behaviour.setup(context=context)
        self.started = world.now()
        self.ticks = 0
        self.status = "running"
        self.trace: list[dict[str, object]] = []
        self._last: tuple[str, str] | None = None

    @property
    def running(self) -> bool:
        """Whether the skill has not ended yet."""
        return self.status == "running"

    def tick(self) -> bool:
        """Tick the behaviour once; returns whether it has ended (succeeded or failed)."""
        from py_trees.common import Status

        behaviour = self.behaviour
        self._hear_team()
        behaviour.tick_once()
        self.ticks += 1
        seen = (behaviour.status.value, behaviour.feedback_message)
        if seen != self._last:
            self.trace.append(
                {"t": round(self.world.now() - self.started, 4), "status": seen[0].lower(), "feedback": seen[1]}
            )
            self._last = seen
        if behaviour.status == Status.SUCCESS:
            self.status = "success"
        elif behaviour.status == Status.FAILURE:
            self.status = "failure"
        return not self.running

    def _hear_team(self) -> None:
        """Every robot of the world shares its pose into the session's world model (a loss-free team network).

        The harness plays the application's part, which shares each robot's
        pose on every tick (:func:`alica.skills.team_poses.share_pose`,
        throttled), and the network's: a robot standing by is avoided as in a
        team whose robots all share. A test that wants a robot unseen builds
        and ticks the skill itself, with a world model of its own.
        """
        for robot in self.world.robots.values():
            share_pose(self.world_model, self.world, robot)

    def stop(self) -> None:
        """Stop a running skill (py_trees runs its ``terminate``); it counts as ``timeout``."""
        from py_trees.common import Status

        if self.running:
            self.behaviour.stop(Status.INVALID)
            self.status = "timeout"

    def result(self, timeout: float | None = None) -> SkillRun:
        """What happened: the status, the skill's last feedback, the time taken and the world model's facts.

        Args:
            timeout: the time bound the session was stopped at, to say so when the skill said nothing.
        """
        reason = self.behaviour.feedback_message
        if not reason and self.status == "timeout":
            reason = "still running" + (f" after {timeout:.0f} s" if timeout is not None else "")
        wm = self.world_model
        # the robots' shared poses are the team's traffic (alica.skills.team_poses), not the skill's outcome
        facts = sorted((f for f in wm.facts() if f.predicate != SHARERS), key=lambda fact: repr(fact.flat))
        written = {Fact(key, args): value for key, args, value in wm.values() if key != POSE}
        return SkillRun(
            self.name,
            self.robot,
            self.status,
            reason,
            round(self.world.now() - self.started, 4),
            self.ticks,
            list(self.trace),
            facts,
            written,
        )


def run_skill(
    name: str,
    world: World,
    robot: str,
    params: Mapping[str, object] | None = None,
    *,
    timeout: float = 120.0,
    rate: float = 10.0,
    seed: int = 0,
    registry: SkillRegistry | None = None,
    skills: Iterable[str] | str = (),
    world_model: WorldModelLike | None = None,
    on_tick: Callable[[World, Behaviour], None] | None = None,
    scratch: dict[str, object] | None = None,
) -> SkillRun:
    """Run skill ``name`` on ``robot`` of ``world`` until it ends or ``timeout`` simulated seconds pass.

    The skill is built from the registry's implementation, ticked ``rate``
    times per simulated second, and the world steps between ticks.
    ``on_tick(world, behaviour)``, if given, runs before every tick (to inject
    faults at the right moment, say). The skill is looked up in ``registry``,
    or else in the installed plug-ins and the plug-in modules named in
    ``skills`` (as ``--skills`` does on the command line, e.g.
    ``skills=["my_skills"]``). Pass one ``scratch`` dict to several calls to
    run a pipeline of skills step by step: each finds what the one before
    left in the agent's scratch space (``context.scratch``). Several skills on
    different robots at once: :func:`alica.skills.together.run_together`.

    Raises:
        SkillError: bad parameters, no such robot, or no implementation.
        UnknownSkillError: no skill of that name.
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    registry = resolve_registry(registry, skills, "run_skill")
    session = SkillSession(name, world, robot, params, registry, world_model=world_model, seed=seed, scratch=scratch)
    period = 1.0 / rate
    while True:
        if on_tick is not None:
            on_tick(world, session.behaviour)
        if session.tick():
            break
        if world.now() - session.started >= timeout:
            session.stop()
            break
        world.step(period)
    return session.result(timeout)


def resolve_registry(registry: SkillRegistry | None, skills: Iterable[str] | str, caller: str) -> SkillRegistry:
    """``registry``, or the installed plug-ins with the plug-in modules ``skills`` (one of the two, not both).

    Raises:
        SkillError: both are given.
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    if registry is not None and skills:
        raise SkillError(f"{caller} takes a registry or plug-in modules (skills=...), not both")
    modules = [skills] if isinstance(skills, str) else list(skills)
    return registry if registry is not None else default_registry(modules)


# -- scoring maps against the ground truth (tests and benches) --------------------------


def map_truth(world: Any, grid: Any, *, skip: tuple[str, ...] = (), height: float = 0.1) -> np.ndarray:
    """Ground truth at the lidar's height on the cells of ``grid`` (a ``LogOddsGrid``): True = occupied.

    For scoring maps in tests and benches only (a skill never reads the simulator's bodies): rock
    meshes sliced at ``height``, tables, blocks and samples by their footprints, and the robots not
    in ``skip``.
    """
    res = grid.resolution
    cx = grid.origin[0] + (np.arange(grid.nx) + 0.5) * res
    cy = grid.origin[1] + (np.arange(grid.ny) + 0.5) * res
    out = np.zeros((grid.ny, grid.nx), dtype=bool)
    for obj in world.objects.values():
        mesh = obj.world_mesh()
        if mesh is not None:
            lo, hi = mesh.bounds
            i0, i1 = np.searchsorted(cx, lo[0]), np.searchsorted(cx, hi[0])
            j0, j1 = np.searchsorted(cy, lo[1]), np.searchsorted(cy, hi[1])
            if i1 <= i0 or j1 <= j0:
                continue
            xs, ys = np.meshgrid(cx[i0:i1], cy[j0:j1])
            points = np.stack([xs, ys, np.full_like(xs, height)], -1).reshape(-1, 3)
            normals, corners = mesh.face_normals, mesh.triangles[:, 0]
            inside = ((points[:, None, :] - corners[None]) * normals[None]).sum(-1).max(axis=1) <= 0.0
            out[j0:j1, i0:i1] |= inside.reshape(xs.shape)
        elif obj.kind in ("table", "block", "sample"):
            footprint = obj.footprint()
            if footprint is not None:
                out |= footprint.distance(cx[None, :], cy[:, None]) <= 0.0
    for name, robot in world.robots.items():
        if name not in skip:
            x, y, _ = robot.pose
            out |= np.hypot(cx[None, :] - x, cy[:, None] - y) <= robot.spec.radius
    return out


def map_agreement(occupancy: np.ndarray, truth: np.ndarray, *, strict: bool = False) -> float:
    """The fraction of known cells that agree with the truth, within one cell (an occupied cell next to a truly occupied one, a free cell at most one cell deep in an obstacle).

    ``strict``: no tolerance, the cell's class must be the truth's.
    """
    from scipy.ndimage import binary_dilation, binary_erosion

    known = occupancy >= 0
    if not known.any():
        return float("nan")
    if strict:
        return float(((occupancy == 1) == truth)[known].mean())
    occupied_ok = binary_dilation(truth, iterations=1)
    free_ok = ~binary_erosion(truth, iterations=1)
    good = np.where(occupancy == 1, occupied_ok, free_ok)
    return float(good[known].mean())
