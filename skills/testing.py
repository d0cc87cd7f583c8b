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
    left in the agent's scratch space (``context.scratch``).

    Raises:
        SkillError: bad parameters, no such robot, or no implementation.
        UnknownSkillError: no skill of that name.
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    from py_trees.common import Status

    from alica.engine.behaviours import SkillContext
    from alica.worldmodel import WorldModel

    if registry is not None and skills:
        raise SkillError("run_skill takes a registry or plug-in modules (skills=...), not both")
    modules = [skills] if isinstance(skills, str) else list(skills)
    registry = registry if registry is not None else default_registry(modules)
    spec = registry.get(name)
    values = checked_params(spec, params or {})
    if robot not in world.robots:
        raise SkillError(f"the world has no robot named '{robot}' (robots: {', '.join(sorted(world.robots))})")
    factory = registry.load(name)
    wm = world_model if world_model is not None else WorldModel(robot, clock=world.clock)
    belief: Any = wm  # alone, the world model is the skill's whole belief base
    context = SkillContext(robot, world.now, wm, belief, random.Random(f"{seed}:{robot}"), world, None, f"skill/{name}")
    if scratch is not None:
        context.scratch = scratch  # shared with the skills run before and after: a pipeline, step by step
    behaviour = factory(name, values, context)
    behaviour.setup(context=context)
    start = world.now()
    period = 1.0 / rate
    trace: list[dict[str, object]] = []
    ticks = 0
    last: tuple[str, str] | None = None
    status = "timeout"
    while True:
        if on_tick is not None:
            on_tick(world, behaviour)
        behaviour.tick_once()
        ticks += 1
        now = world.now()
        seen = (behaviour.status.value, behaviour.feedback_message)
        if seen != last:
            trace.append({"t": round(now - start, 4), "status": seen[0].lower(), "feedback": seen[1]})
            last = seen
        if behaviour.status == Status.SUCCESS:
            status = "success"
            break
        if behaviour.status == Status.FAILURE:
            status = "failure"
            break
        if now - start >= timeout:
            behaviour.stop(Status.INVALID)
            break
        world.step(period)
    reason = behaviour.feedback_message or ("" if status != "timeout" else f"still running after {timeout:.0f} s")
    facts = sorted(wm.facts(), key=lambda fact: repr(fact.flat))
    written = {Fact(key, args): value for key, args, value in wm.values()}
    return SkillRun(name, robot, status, reason, round(world.now() - start, 4), ticks, trace, facts, written)


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
