"""MAGiC on Rovers p01-p20 with 1-4 agents, beside the single-process builtin planner and IMPERA's Table 1.

For each problem: the builtin planner alone (first plan, not anytime: its cost and wall
seconds to the first plan), then one MAGiC round per team size over the simulated
network in lock step (:func:`alica.app.magic.run_lockstep`): every tick each agent takes
one planner step of ``--progress-every`` expansions. Lock step measures time to the
first plan in **ticks** (the parallel time of the team, in search steps), not in
seconds: all agents run in this one process, one after the other. The wall-clock
figures of MAGiC come from agent processes (a process driver over zenoh), not from
this table. IMPERA's columns are its Table 1 (FDP: Fast Downward split over the
team; cost, agents and messages as printed there).

With ``--processes`` the rounds run over agent processes instead
(:func:`alica.app.magic_processes.run_processes`: the leader here, one spawned worker process per
teammate, zenoh on loopback); the time to the first plan is then in wall seconds from the round's
start (the processes already up).

The Rovers problems are read in place from ``pddl/rovers`` of the benchmark sets: ``--benchmarks DIR``, else the
environment variable ``ALICA_BENCHMARKS``, else ``../shared/benchmarks`` beside the checkout.

Run: ``.venv/bin/python bench/magic.py [--problems p01,p05] [--agents 1,2,3,4] [--seed 0] [--processes]
[--benchmarks DIR]``; prints a markdown table.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from alica.app.magic import run_lockstep
from alica.prophet.pddl import parse_domain, parse_problem
from alica.prophet.search import BuiltinPlanner
from bench.benchmark_sets import add_benchmarks_option, benchmark_set, default_benchmarks

FDP_COST = (10, 8, 13, 10, 22, 38, 18, 28, 34, 36, 38, 22, 46, 32, 44, 43, 52, 48, 74, 87)
"""IMPERA Table 1: the cost FDP found on Rovers1-20."""
FDP_MESSAGES = (0, 0, 3, 3, 3, 3, 6, 6, 6, 6, 6, 6, 6, 6, 6, 6, 15, 15, 15, 21)
"""IMPERA Table 1: FDP's messages on Rovers1-20."""
FDP_AGENTS = (1, 1, 2, 2, 2, 2, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 6, 6, 6, 8)
"""IMPERA Table 1: the team size of Rovers1-20."""


def _number(value: float | None) -> str:
    if value is None:
        return "-"
    return str(int(value)) if float(value).is_integer() else f"{value:.1f}"


def row(
    name: str,
    agents: Sequence[int],
    seed: int,
    progress_every: int,
    processes: bool = False,
    benchmarks: Path | None = None,
) -> str:
    """One table row: IMPERA's FDP, the builtin planner alone, then MAGiC per team size.

    ``benchmarks`` is the folder of the benchmark sets (default: ``default_benchmarks()``).
    """
    number = int(name[1:])
    rovers = benchmark_set(benchmarks or default_benchmarks(), "pddl") / "rovers"
    domain_text, problem_text = (rovers / "domain.pddl").read_text(), (rovers / f"{name}.pddl").read_text()
    domain = parse_domain(domain_text)
    problem = parse_problem(problem_text, name, domain)
    start = time.perf_counter()
    alone = BuiltinPlanner().solve(domain, problem, anytime=False, time_limit=600)
    alone_s = time.perf_counter() - start
    cells = [name]
    if number <= len(FDP_COST):
        i = number - 1
        cells += [str(FDP_AGENTS[i]), str(FDP_COST[i]), str(FDP_MESSAGES[i])]
    else:
        cells += ["-", "-", "-"]
    cells += [_number(alone.cost), f"{alone_s:.3f}"]
    for n in agents:
        if processes:
            from alica.app.magic_processes import run_processes  # lazy: zenoh only here

            run = run_processes(domain_text, problem_text, n, seed=seed, timeout=600)
            first = "-" if run.first_plan_s is None else f"{run.first_plan_s:.3f}"
        else:
            run = run_lockstep(domain_text, problem_text, n, seed=seed, progress_every=progress_every)
            first = "-" if run.first_plan_tick is None else str(run.first_plan_tick)
        cells.append(f"{_number(run.cost)} / {first} / {run.messages}")
    return "| " + " | ".join(cells) + " |"


def main(argv: Sequence[str] | None = None) -> int:
    """Print the table; returns the exit code."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--problems", default=",".join(f"p{i:02d}" for i in range(1, 21)), help="e.g. p01,p05")
    parser.add_argument("--agents", default="1,2,3,4", help="team sizes, e.g. 1,2,4")
    parser.add_argument("--seed", type=int, default=0, help="the network's and the shares' seed")
    parser.add_argument("--progress-every", type=int, default=10, help="expansions per planner step (one per tick)")
    parser.add_argument("--processes", action="store_true", help="agent processes over zenoh instead of lock step")
    add_benchmarks_option(parser)
    args = parser.parse_args(argv)
    benchmark_set(args.benchmarks, "pddl")  # before the first line of the table
    agents = [int(a) for a in args.agents.split(",")]
    if args.processes:
        print(
            f"MAGiC over agent processes (zenoh on loopback, seed {args.seed}): "
            "time to the first plan in wall seconds from the round's start."
        )
        unit = "first s"
    else:
        print(
            f"MAGiC in-process lock step over SimNetwork (seed {args.seed}, one step of {args.progress_every} "
            "expansions per agent and tick): NOT the process figures; time to the first plan in ticks."
        )
        unit = "ticks"
    print()
    head = ["problem", "FDP agents", "FDP cost", "FDP msgs", "builtin cost", "builtin first s"]
    head += [f"{n} agent{'s' if n > 1 else ''}: cost / {unit} / msgs" for n in agents]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for name in args.problems.split(","):
        print(row(name.strip(), agents, args.seed, args.progress_every, args.processes, args.benchmarks), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
