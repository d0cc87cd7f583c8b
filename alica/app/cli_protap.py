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

Dispatching the steps' actions to the skills of a simulated world
(``--world lunar``) is not built yet; the command says so.
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
from pathlib import Path
from typing import Any

from alica.errors import AlicaError


def _grid(text: str) -> tuple[int, int]:
    width, sep, height = text.lower().partition("x")
    if not sep or not width.isdigit() or not height.isdigit() or int(width) < 1 or int(height) < 1:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT with positive whole numbers, e.g. 5x5, got {text!r}")
    return int(width), int(height)


def _count(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"expected a positive whole number, got {text!r}")
    return int(text)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"expected 0 or more seconds, got {text!r}")
    return value


def _problem_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robots", type=_count, default=2, metavar="N", help="robots (default 2)")
    p.add_argument("--grid", type=_grid, default=(5, 5), metavar="WxH", help="grid size (default 5x5)")
    p.add_argument("--goals", type=_count, default=3, metavar="K", help="goals at distinct random cells (default 3)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="seeds the problem and the runs (default 0)")


def add_parser(sub: Any) -> None:
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
        help="none: the domain's own simulator (default); lunar: not built yet",
    )
    r.add_argument("--steps", type=_count, default=10, metavar="H", help="steps per episode, the horizon (default 10)")
    r.add_argument("--episodes", type=_count, default=20, metavar="E", help="episodes (default 20)")
    r.add_argument(
        "--time-per-step", type=_seconds, default=0.5, metavar="S", help="planning seconds per step (default 0.5)"
    )
    r.add_argument("--json", action="store_true", help="print the summary as JSON")
    r.set_defaults(run=cmd_run)


def _spec(args: argparse.Namespace, horizon: int = 10) -> Any:
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

    if args.world != "none":
        raise AlicaError(
            "--world lunar: dispatching ProTaP's actions to the skills of a simulated world is not built yet; "
            "use --world none (the domain's own simulator)"
        )
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
