"""Which skills of a team run run for real, which are stand-ins, and the world they act on."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from alica.errors import AlicaError
from alica.lang.skills import SkillRegistry, SkillSpec
from alica.model import Behaviour, PlanLibrary, PlanningProblem

if TYPE_CHECKING:
    from alica.engine import SimulatedTeam
    from alica.worldsim.world import World


def plan_skills(library: PlanLibrary, plan: str) -> list[str]:
    """The skills the behaviours under ``plan`` run, sorted.

    Under a planning problem the plans are made at run time from any plan of
    the library, so then every behaviour of the library counts.

    Raises:
        AlicaError: no plan of that name.
    """
    if plan not in library.plans:
        raise AlicaError(f"no plan named '{plan}' to run; plans: {', '.join(sorted(library.plans))}")
    seen: set[str] = set()
    todo = [plan]
    skills: set[str] = set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        element = library.abstract(name)
        if isinstance(element, Behaviour):
            skills.add(element.skill)
        elif isinstance(element, PlanningProblem):
            skills.update(b.skill for b in library.behaviours.values())
        else:
            todo.extend(library.children(element))
    return sorted(skills)


def needs_world(spec: SkillSpec) -> bool:
    """Whether a skill acts on a robot: it declares capabilities the robot must have."""
    return bool(spec.capabilities)


@dataclass(frozen=True, slots=True)
class SkillWiring:
    """How a run binds its skills.

    Attributes:
        registry: the declarations the team builds skills from; a stand-in's
            skill has its implementation removed here, so the team's fallback builds it.
        real: skills that run their implementation.
        stand_ins: skills that run as scripted stand-ins.
    """

    registry: SkillRegistry
    real: list[str]
    stand_ins: list[str]


#: How ``alica run`` gives its skills a robot (the end of skill_wiring's message).
RUN_ROBOTS = "pass --world blocks or --world lunar, or --robot PLUGIN (a robot driver)"


def skill_wiring(
    registry: SkillRegistry,
    skills: Sequence[str],
    *,
    world: bool,
    stand_ins: bool,
    plan: str = "the plan",
    robots: str = RUN_ROBOTS,
) -> SkillWiring:
    """Decide for each skill of a run whether it runs for real or as a stand-in.

    Raises:
        AlicaError: without ``stand_ins``, some skills have no implementation, or
            act on a robot while the run has no world (the message lists them).
    """
    missing: list[str] = []
    worldless: list[str] = []
    real: list[str] = []
    for name in skills:
        spec = registry.get(name)
        if spec.implementation is None:
            missing.append(name)
        elif needs_world(spec) and not world:
            worldless.append(name)
        else:
            real.append(name)
    if not stand_ins:
        problems = []
        if missing:
            problems.append(
                f"{plan} uses skills that have no implementation: {', '.join(missing)}; pass --stand-ins to run scripted "
                "stand-ins for them, or provide an implementation (--skills MODULE or an installed plug-in)"
            )
        if worldless:
            problems.append(
                f"{plan} uses skills that act on a robot and the run has no world: {', '.join(worldless)}; "
                f"{robots} (or --stand-ins to script them)"
            )
        if problems:
            raise AlicaError("; and ".join(problems))
    scripted = sorted(missing + worldless)
    view = registry.copy()
    for name in worldless:
        view.register(dataclasses.replace(registry.get(name), implementation=None), replace=True)
    return SkillWiring(view, real, scripted)


def _blocks_world(args: argparse.Namespace, agents: Sequence[str]) -> World:
    from alica.worldsim.scenarios import blocksworld

    stacks = [[b.strip() for b in stack.split(",") if b.strip()] for stack in args.stacks.split(";") if stack.strip()]
    if not stacks:
        raise AlicaError(f"--stacks: '{args.stacks}' names no blocks; write e.g. 'a,b;c'")
    world = blocksworld(stacks, agents=len(agents), seed=args.seed)
    try:
        # the scenario names its robots r1..rN: give each its agent's name, in the same place
        placed = [(f"r{k + 1}", agent) for k, agent in enumerate(agents) if agent != f"r{k + 1}"]
        poses = {old: world.robots[old].pose for old, _ in placed}
        for old, _ in placed:
            world.remove(old)
        for old, agent in placed:
            world.add_robot("manipulator", agent, poses[old])
    except Exception:
        world.close()
        raise
    return world


def _lunar_world(args: argparse.Namespace, agents: Sequence[str]) -> World:
    from alica.app.skill_options import lunar_field

    world = lunar_field(args)
    strangers = [a for a in agents if a not in world.robots]
    if strangers:
        robots = ", ".join(sorted(world.robots))
        world.close()
        raise AlicaError(
            f"--world lunar: no robot for agent(s) {', '.join(strangers)}; its robots are {robots}: "
            "name the agents after them, e.g. --agents scout:Scout"
        )
    return world


@contextlib.contextmanager
def run_world(
    args: argparse.Namespace, agents: Sequence[str]
) -> Iterator[tuple[World | None, Callable[[SimulatedTeam], None] | None]]:
    """The world of ``--world`` (closed afterwards) and its perception hook; ``(None, None)`` without it."""
    if args.world is None:
        yield None, None
        return
    from alica.app.cli_skill import _c_prints_to_stderr
    from alica.skills.motion import configure_ompl

    configure_ompl(args.seed)  # OMPL's generator is per process: seed it before any planner exists
    with _c_prints_to_stderr():
        world = _blocks_world(args, agents) if args.world == "blocks" else _lunar_world(args, agents)
    try:
        perception: Callable[[SimulatedTeam], None] | None = None
        if args.world == "blocks":
            from alica.worldsim.scenarios import blocks_perception

            perception = blocks_perception()
        yield world, perception
    finally:
        with _c_prints_to_stderr():
            world.close()


def share_poses(team: SimulatedTeam) -> Callable[[float], None]:
    """A hook for ``team.after_tick``: each running agent shares its robot's pose estimate, as robots do.

    A robot broadcasts where it believes it is whatever it runs; its world skills share too, but an
    agent that runs none (one waiting for its task) would otherwise be known to its teammates only as
    cells of their map. :func:`alica.skills.team_poses.share_pose` throttles the writes.
    """
    from alica.skills.team_poses import share_pose

    def share(_now: float) -> None:
        for engine in team.running():
            world: Any = team.agent_worlds.get(engine.name, team.world)
            robot = world.robots.get(engine.name) if world is not None else None
            if robot is not None:
                share_pose(engine.world_model, world, robot)

    return share


__all__ = ["SkillWiring", "needs_world", "plan_skills", "run_world", "share_poses", "skill_wiring"]
