"""``alica skill run``: one skill alone in a small simulated world."""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from alica.app.options import add_time_limit, time_limit
from alica.app.robot_plugin import RobotPlugin, WallPaced, add_robot_options, close_world, is_simulated, robot_plugin
from alica.app.skill_options import add_lunar_options, add_skills_option, lunar_field, skill_registry
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.lang.skills import SkillRegistry, SkillSpec
    from alica.skills.testing import SkillRun
    from alica.worldsim.world import World


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``skill`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "skill",
        help="run one skill alone in a simulated world",
        description="Run one skill alone in a simulated world, in simulated time.",
    )
    skill_sub = p.add_subparsers(dest="skill_command", metavar="ACTION")
    skill_sub.required = True
    r = skill_sub.add_parser(
        "run",
        help="run a skill until it ends",
        description="Run a skill on one robot of a lunar or blocks world until it succeeds, fails or reaches "
        "--time-limit. Exit 0 on success, 1 otherwise.",
    )
    r.add_argument("name", metavar="NAME", help="the skill, e.g. MoveToPosition (alica list-skills lists them)")
    r.add_argument(
        "--world",
        choices=("lunar", "blocks"),
        help="the scenario (default lunar; leave it out with --robot)",
    )
    r.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a parameter; VALUE is read as YAML, e.g. goal=[5, 5] (repeatable)",
    )
    r.add_argument(
        "--after",
        action="append",
        default=[],
        metavar="SKILL",
        help="run this skill first, with its default parameters, on the same robot, world model and scratch space "
        "(repeatable, in order): a pipeline step by step, e.g. --after DetectCircles --after CropCandidate "
        "for BlobDetect; the run stops at the first step that does not succeed",
    )
    r.add_argument(
        "--robot-name",
        metavar="NAME",
        help="the robot: with --world, one of the scenario's (default: the first one that has what the skills need); "
        "with --robot, the name the factory gets (default robot)",
    )
    r.add_argument(
        "--role",
        help="with --robot: the role the factory gets (the unicycle takes its kind from it; default: none)",
    )
    add_robot_options(r)
    r.add_argument("--seed", type=int, default=0, help="the world's seed (default 0)")
    add_lunar_options(r)
    r.add_argument("--stacks", default="a,b;c", help="blocks world stacks, bottom first, e.g. 'a,b;c' (default)")
    add_time_limit(r, 120.0, "give up after S simulated seconds (default 120)", old=("--timeout",))
    r.add_argument("--json", action="store_true", help="print the result as JSON")
    add_skills_option(r)
    r.set_defaults(run=cmd_skill_run)


def _params(items: list[str]) -> dict[str, object]:
    import yaml  # lazy: every alica command builds this parser

    params: dict[str, object] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise AlicaError(f"--param: '{item}' is not KEY=VALUE, e.g. --param goal=[5, 5]")
        try:
            value = yaml.safe_load(text) if text.strip() else ""
        except yaml.YAMLError as exc:
            raise AlicaError(
                f"--param {key}: '{text}' is not a YAML value ({exc.problem if isinstance(exc, yaml.MarkedYAMLError) else exc})"
            ) from None
        params[key] = tuple(value) if isinstance(value, list) else value
    return params


def _world(args: argparse.Namespace) -> World:
    if args.world in (None, "lunar"):
        return lunar_field(args)
    from alica.worldsim.scenarios import blocksworld

    stacks = [[b.strip() for b in stack.split(",") if b.strip()] for stack in args.stacks.split(";") if stack.strip()]
    if not stacks:
        raise AlicaError(f"--stacks: '{args.stacks}' names no blocks; write e.g. 'a,b;c'")
    return blocksworld(stacks, agents=2, seed=args.seed)


@contextlib.contextmanager
def _c_prints_to_stderr() -> Iterator[None]:
    """pybullet prints from C to file descriptor 1; keep standard output for our own output."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:
        yield
        return
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def _run(args: argparse.Namespace, registry: SkillRegistry, spec: SkillSpec, params: dict[str, object]) -> SkillRun:
    from alica.skills.testing import run_skill
    from alica.worldmodel import WorldModel

    steps = [registry.get(name) for name in args.after]
    needs = frozenset().union(spec.capabilities, *(step.capabilities for step in steps))
    names = ", ".join([*args.after, args.name])
    try:
        plugin = robot_plugin(args, [args.robot_name or "robot"])
    except AlicaError as exc:
        if args.robot is None or ":" in args.robot:
            raise
        raise AlicaError(
            f"{exc}; to pick a robot of the --world scenario by name, use --robot-name {args.robot}"
        ) from None
    if plugin is not None and args.world is not None:
        raise AlicaError("--robot and --world both give the robot: choose one")
    world: Any = _world(args) if plugin is None else _plugged(plugin, args.robot_name or "robot", args.role or "")
    try:
        robot = args.robot_name or ("robot" if plugin is not None else None)
        if robot is None:
            fits = [n for n, r in sorted(world.robots.items()) if needs <= r.spec.capabilities]
            if not fits:
                raise AlicaError(
                    f"no robot of the {args.world} world can run {names} (needs {', '.join(sorted(needs))})"
                )
            robot = fits[0]
        world_model = WorldModel(robot, clock=world.clock)
        scratch: dict[str, object] = {}  # shared by the steps and the skill, as their world model
        for step in steps:
            run = run_skill(
                step.name,
                world,
                robot,
                {},
                timeout=args.time_limit,
                seed=args.seed,
                registry=registry,
                world_model=world_model,
                scratch=scratch,
            )
            if not run.ok:
                run.reason = f"step {step.name} before {args.name} did not succeed: {run.reason}"
                return run
        return run_skill(
            args.name,
            world,
            robot,
            params,
            timeout=args.time_limit,
            seed=args.seed,
            registry=registry,
            world_model=world_model,
            scratch=scratch,
        )
    finally:
        close_world(world)


def _plugged(plugin: RobotPlugin, name: str, role: str) -> Any:
    """The plug-in's world for ``alica skill run --robot``; a hardware one is ticked on the wall clock."""
    world = plugin.make(name, role)
    return world if is_simulated(world) else WallPaced(world)


def cmd_skill_run(args: argparse.Namespace) -> int:
    """Run ``alica skill run``; returns the exit code."""
    from alica.skills.motion import configure_ompl

    time_limit(args)
    registry = skill_registry(args)
    configure_ompl(args.seed)  # OMPL's generator is per process: seed it before any planner exists
    spec = registry.get(args.name)
    params = _params(args.param)
    with _c_prints_to_stderr():
        run = _run(args, registry, spec, params)
    if args.json:
        print(
            json.dumps(
                {
                    "skill": run.skill,
                    "robot": run.robot,
                    "status": run.status,
                    "reason": run.reason,
                    "sim_time_s": run.sim_time_s,
                    "ticks": run.ticks,
                    "trace": run.trace,
                    "facts": [list(map(str, f.flat)) for f in run.facts],
                },
                indent=2,
            )
        )
    else:
        print(f"{run.skill} on {run.robot}: {run.status} after {run.sim_time_s:.2f} s simulated ({run.ticks} ticks)")
        if run.reason:
            print(f"  {run.reason}")
        for fact in run.facts:
            print(f"  fact: {fact}")
    return 0 if run.ok else 1
