"""``alica protap``: generate ProTaP problems and run the planner on them.

* ``alica protap generate [--robots N] [--grid WxH] [--goals K] [--seed S] --out DIR``
  writes ``domain.rddl`` and ``instance.rddl`` (Algorithm 2 of the ProTaP paper).
* ``alica protap run [...] --world none`` generates the same problem, plans every
  step from the observed state with the built-in anytime planner and samples
  the step's outcome from the domain's own probabilities (the fast simulator
  of the domain), for ``--episodes`` episodes of ``--steps`` steps. It prints
  a summary, or with ``--json`` the keys ``reward_mean``, ``reward_std``,
  ``episodes``, ``constraint_breaks``, ``time_per_step_s`` (median),
  ``greedy_reward_mean`` and ``trials_per_step`` (median).
* ``alica protap run [...] --world lunar`` dispatches every step's actions at
  once to the skills of stummel robots on a lunar field laid out as the grid
  (:mod:`alica.app.protap_world`) and plans the next step from where the
  robots really are and which goals really got done. The summary adds
  ``success``, ``goals_done``, ``goals``, ``action_failures``, ``sim_time_s``,
  ``wall_time_s`` and, with ``--json``, a ``trace`` of every step.
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.app.options import add_deprecated
from alica.app.skill_options import add_skills_option
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.prophet.protap import ProblemSpec, ProtapModel, StepRecord


def _grid(text: str) -> tuple[int, int]:
    width, sep, height = text.lower().partition("x")
    if not sep or not width.isdigit() or not height.isdigit() or int(width) < 1 or int(height) < 1:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT with positive whole numbers, e.g. 5x5, got {text!r}")
    return int(width), int(height)


def _count(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return int(text)


def _number(what: str, *, zero: bool) -> Callable[[str], float]:
    """An argparse type: a number of ``what`` (``"seconds"``, ``"metres"``) above 0, or from 0 with ``zero``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number of {what}, got {text!r}") from None
        if not (value >= 0 if zero else value > 0) or value == float("inf"):
            bound = "0 or more" if zero else "more than 0"
            raise argparse.ArgumentTypeError(f"expected {bound} {what}, got {text!r}")
        return value

    return parse


_seconds = _number("seconds", zero=True)
_metres = _number("metres", zero=False)


def _whole(text: str) -> int:
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}")
    return int(text)


def _goto_fault(text: str) -> tuple[str, int]:
    robot, sep, step = text.partition("@")
    if not sep or not robot or not step.isdigit() or int(step) < 1:
        raise argparse.ArgumentTypeError(f"expected ROBOT@STEP with STEP 1 or more, e.g. r1@2, got {text!r}")
    return robot, int(step)


#: The options that only ``--world lunar`` reads, with their defaults there.
_WORLD_DEFAULTS: dict[str, object] = {
    "uda_skill": "DetectCircles",
    "cell_size": 3.0,
    "grid_rocks": 4,
    "step_timeout": 120.0,
    "fail_goto": [],
}


def _problem_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robots", type=_count, default=2, metavar="N", help="robots r1..rN (default 2)")
    p.add_argument("--grid", type=_grid, default=(5, 5), metavar="WxH", help="grid size in cells (default 5x5)")
    p.add_argument("--goals", type=_count, default=3, metavar="K", help="goals at distinct random cells (default 3)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="seeds the problem and the runs (default 0)")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``protap`` subcommand (``generate``, ``run``) to the ``alica`` parser."""
    p = sub.add_parser(
        "protap",
        help="ProTaP: generate probabilistic concurrent planning problems (RDDL) and run the planner",
        description="ProTaP (probabilistic concurrent task planning): generate RDDL problems and run the anytime "
        "planner on them.",
    )
    cmds = p.add_subparsers(dest="protap_command", metavar="COMMAND")
    cmds.required = True
    g = cmds.add_parser(
        "generate",
        help="write domain.rddl and instance.rddl",
        description="Write the ProTaP domain and a generated instance (Algorithm 2) to a folder.",
    )
    _problem_options(g)
    g.add_argument("--out", required=True, metavar="DIR", help="the folder to write to (created if missing)")
    g.set_defaults(run=cmd_generate)
    r = cmds.add_parser(
        "run",
        help="plan and simulate episodes of a generated problem",
        description="Generate a problem, plan every step from the observed state with the built-in planner and "
        "sample the outcomes from the domain's probabilities (--world none).",
    )
    _problem_options(r)
    r.add_argument(
        "--world",
        choices=("none", "lunar"),
        default="none",
        help="none: the domain's own simulator (default); lunar: dispatch every step's actions at once to the "
        "skills of stummel robots in a pybullet lunar field laid out as the grid",
    )
    r.add_argument("--steps", type=_count, default=10, metavar="H", help="steps per episode, the horizon (default 10)")
    r.add_argument(
        "--episodes", type=_count, default=None, metavar="E", help="episodes (default 20; 1 with --world lunar)"
    )
    r.add_argument(
        "--time-per-step", type=_seconds, default=0.5, metavar="S", help="planning seconds per step (default 0.5)"
    )
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    w = r.add_argument_group("with --world lunar")
    add_skills_option(w)
    w.add_argument(
        "--uda-skill",
        default=None,
        metavar="NAME",
        help="the skill a user-defined action runs (default DetectCircles: the robot scans its cell with its 2D "
        "lidar for the goal's sample container); it gets 'object' (the goal's sample) if it declares it",
    )
    w.add_argument(
        "--cell-size", type=_metres, default=None, metavar="M", help="side of a grid cell in metres (default 3)"
    )
    w.add_argument(
        "--grid-rocks",
        type=_whole,
        default=None,
        metavar="N",
        help="rocks on the field between the grid's cells (default 4); not the lunar field's --rocks of alica run",
    )
    add_deprecated(w, "--rocks", "--grid-rocks", dest="grid_rocks", type=_whole, metavar="N")
    w.add_argument(
        "--step-timeout",
        type=_seconds,
        default=None,
        metavar="S",
        help="simulated seconds a step's skills may take; a skill still running then is stopped and its action "
        "fails (default 120)",
    )
    w.add_argument(
        "--fail-goto",
        type=_goto_fault,
        action="append",
        default=None,
        metavar="ROBOT@STEP",
        help="fault injection: crash ROBOT when its goto of step STEP (1 = the first) starts, and power it up "
        "again when the step ends; nothing happens if it has no goto in that step (repeatable)",
    )
    r.set_defaults(run=cmd_run)


def _spec(args: argparse.Namespace, horizon: int = 10) -> ProblemSpec:
    from alica.prophet.protap import random_spec

    width, height = args.grid
    if args.goals > width * height:
        raise AlicaError(
            f"{args.goals} goals do not fit on a {width}x{height} grid (goals lie on distinct cells): "
            "use fewer goals or a larger --grid"
        )
    try:
        return random_spec(
            robots=args.robots, width=width, height=height, goals=args.goals, seed=args.seed, horizon=horizon
        )
    except ValueError as exc:
        raise AlicaError(f"cannot generate the problem: {exc}") from None


def cmd_generate(args: argparse.Namespace) -> int:
    """Write ``domain.rddl`` and ``instance.rddl``; returns the exit code."""
    from alica.prophet.protap import write_problem

    domain, instance = write_problem(_spec(args), Path(args.out))
    print(f"wrote {domain} and {instance}")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    """Plan and simulate the episodes; returns the exit code."""
    from alica.prophet.protap import (
        Budget,
        PlannerPolicy,
        ProtapModel,
        ProtapPlanner,
        Recorder,
        evaluate,
        greedy,
    )

    if args.world == "lunar":
        return _run_lunar(args)
    given = [name for name in _WORLD_DEFAULTS if getattr(args, name) is not None] + (["skills"] if args.skills else [])
    if given:
        options = ", ".join("--" + name.replace("_", "-") for name in given)
        raise AlicaError(f"{options}: only with --world lunar (--world none samples the outcomes, it runs no skills)")
    args.episodes = 20 if args.episodes is None else args.episodes
    model = ProtapModel(_spec(args, args.steps))
    planner = ProtapPlanner(model)
    recorder = Recorder(
        PlannerPolicy(planner, Budget(seconds=args.time_per_step), rng=random.Random(args.seed)), planner
    )
    result = evaluate(model, recorder, episodes=args.episodes, seed=args.seed)
    baseline = evaluate(model, greedy, episodes=args.episodes, seed=args.seed)
    summary = {
        "reward_mean": round(result.mean, 3),
        "reward_std": round(result.std, 3),
        "episodes": args.episodes,
        "constraint_breaks": recorder.breaks,
        "time_per_step_s": round(statistics.median(recorder.seconds), 4) if recorder.seconds else 0.0,
        "trials_per_step": int(statistics.median(recorder.trials)) if recorder.trials else 0,
        "greedy_reward_mean": round(baseline.mean, 3),
        "world": args.world,
    }
    if args.json:
        print(json.dumps(summary, sort_keys=True))
    else:
        width, height = args.grid
        print(
            f"ProTaP, {args.robots} robot(s) on {width}x{height} with {args.goals} goal(s), seed {args.seed}, "
            f"{args.episodes} episode(s) of {args.steps} steps, {args.time_per_step:g} s per step "
            "(outcomes sampled from the domain's probabilities)"
        )
        print(f"  reward            {result.mean:.1f} +- {result.std:.1f} (greedy {baseline.mean:.1f})")
        print(f"  constraint breaks {recorder.breaks}")
        print(f"  time per step     {summary['time_per_step_s']} s (median), {summary['trials_per_step']} trials")
    return 0


def _run_lunar(args: argparse.Namespace) -> int:
    """``--world lunar``: dispatch every step to the skills of a lunar field; prints the summary."""
    from alica.app.protap_world import GotoFault, GridLayout, run_lunar_episode
    from alica.app.skill_options import skill_registry
    from alica.prophet.protap import Budget, PlannerPolicy, ProtapModel, ProtapPlanner, Recorder

    for name, default in _WORLD_DEFAULTS.items():
        if getattr(args, name) is None:
            setattr(args, name, default)
    episodes = 1 if args.episodes is None else args.episodes
    started = time.perf_counter()
    model = ProtapModel(_spec(args, args.steps))
    width, height = args.grid
    layout = GridLayout(width, height, args.robots, cell=args.cell_size)
    registry = skill_registry(args)
    faults = [GotoFault(robot, step) for robot, step in args.fail_goto]
    planner = ProtapPlanner(model)
    recorder = Recorder(
        PlannerPolicy(planner, Budget(seconds=args.time_per_step), rng=random.Random(args.seed)), planner
    )
    header = (
        f"ProTaP in the lunar world: {args.robots} robot(s) on {width}x{height} ({args.cell_size:g} m cells) with "
        f"{args.goals} goal(s), seed {args.seed}, {episodes} episode(s) of {args.steps} steps, "
        f"{args.time_per_step:g} s planning per step"
    )
    trace: list[dict[str, Any]] = []
    totals: list[float] = []
    goals_done = failures = 0
    sim_time = 0.0
    success = True
    for episode in range(episodes):

        def record(step: StepRecord, episode: int = episode) -> None:
            trace.append(_step_trace(model, episode, step))
            if not args.json:
                if len(trace) == 1:  # after the checks and the world's building, which may refuse the input
                    print(header)
                _print_step(model, episode, episodes, step)

        run = run_lunar_episode(
            model,
            recorder,
            registry,
            layout=layout,
            uda=args.uda_skill,
            seed=args.seed + episode,
            rocks=args.grid_rocks,
            horizon=args.steps,
            step_timeout=args.step_timeout,
            faults=faults,
            rng=random.Random(args.seed + episode),
            on_step=record,
        )
        totals.append(run.episode.total)
        goals_done += run.episode.goals_done
        failures += run.episode.failures
        sim_time += run.sim_time_s
        success = success and run.episode.all_done
    wall = time.perf_counter() - started
    summary: dict[str, Any] = {
        "reward_mean": round(statistics.fmean(totals), 3),
        "reward_std": round(statistics.stdev(totals), 3) if len(totals) > 1 else 0.0,
        "episodes": episodes,
        "constraint_breaks": recorder.breaks,
        "time_per_step_s": round(statistics.median(recorder.seconds), 4) if recorder.seconds else 0.0,
        "trials_per_step": int(statistics.median(recorder.trials)) if recorder.trials else 0,
        "world": args.world,
        "success": success,
        "goals_done": goals_done,
        "goals": len(model.spec.goals) * episodes,
        "action_failures": failures,
        "sim_time_s": round(sim_time, 2),
        "wall_time_s": round(wall, 2),
    }
    if args.json:
        print(json.dumps({**summary, "trace": trace}, sort_keys=True))
        return 0
    print(f"  reward            {summary['reward_mean']:.1f} +- {summary['reward_std']:.1f}")
    verdict = "every goal done" if success else "not every goal done"
    print(f"  goals done        {goals_done} of {summary['goals']} ({verdict})")
    print(f"  action failures   {failures}")
    print(f"  constraint breaks {recorder.breaks}")
    print(f"  time per step     {summary['time_per_step_s']} s planning (median), {summary['trials_per_step']} trials")
    print(f"  time              {summary['sim_time_s']} s simulated, {summary['wall_time_s']} s wall")
    return 0


def _step_trace(model: ProtapModel, episode: int, step: StepRecord) -> dict[str, Any]:
    """One step of the ``--json`` trace: each robot's action, outcome and skills (simulated seconds)."""
    robots = []
    for robot, (action, outcome) in enumerate(zip(step.actions, step.outcomes, strict=True)):
        robots.append(
            {
                "robot": model.spec.robots[robot].name,
                "action": action,
                "cell_before": list(model.cell_of(step.state, robot)),
                "cell_after": list(outcome.cell),
                "do_ok": outcome.do_ok,
                "goto_ok": outcome.goto_ok,
                "reason": outcome.reason,
                "skills": [
                    {
                        "skill": a.name,
                        "status": a.status,
                        "start": round(a.start, 2),
                        "end": round(a.end, 2),
                        "reason": a.reason,
                    }
                    for a in outcome.activities
                ],
            }
        )
    return {"episode": episode + 1, "step": step.step + 1, "reward": round(step.reward, 3), "robots": robots}


def _print_step(model: ProtapModel, episode: int, episodes: int, step: StepRecord) -> None:
    """One line per step, and one per robot that acted: what it did and how it went."""
    label = f"step {step.step + 1}" if episodes == 1 else f"episode {episode + 1} step {step.step + 1}"
    print(f"  {label}: reward {step.reward:g}")
    for robot, (action, outcome) in enumerate(zip(step.actions, step.outcomes, strict=True)):
        if action == "noop":
            continue
        skills = ", ".join(f"{a.name} {a.status} {a.end - a.start:.1f} s" for a in outcome.activities) or "no skill"
        verdict = "ok" if outcome.failures == 0 else f"FAILED: {outcome.reason}"
        name = model.spec.robots[robot].name
        print(f"    {name} {action}: {verdict} ({skills}); now in cell {outcome.cell}")
