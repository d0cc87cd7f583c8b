"""``bench/planners.py --suite large``: ours beside Fast Downward lama-first on generated problems larger than the IPC suite's.

The problems come from :mod:`bench.large_problems` (gripper, logistics, miconic, satellite; seeds 0
and 1; written to ``build/bench/large/``). Each runs as a whole process, one at a time, ours (``alica
plan --json``, first plan) and then lama-first, each through :mod:`bench.peak_rss` (the largest
resident set of the planner's processes, the same measure for both), every plan validated. The
table: ground actions (our grounding), wall seconds, expansions and expansions per wall second,
peak memory, plan cost; the totals and issue 41's goals (time at most 1.0x, peak memory at most
1.5x, first-plan cost at most 1.05x lama-first's, over the problems both solve).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from bench.large_problems import DOMAIN_FOLDERS, LargeProblem, write_set
from bench.planners import FD, OURS, OUT, Job, Outcome, Tasks, _fmt, markdown, run_fd, run_ours, write_tsv

GOALS = {"time": 1.0, "memory": 1.5, "cost": 1.05}
"""Issue 41's goals on the large set: ours / lama-first."""


def ground_actions(problem: LargeProblem) -> int:
    """How many ground actions our grounding makes of ``problem``."""
    from alica.prophet.ground import ground
    from alica.prophet.pddl import read_domain, read_problem

    domain = read_domain(problem.domain_file)
    return len(ground(domain, read_problem(problem.problem_file, domain)).operators)


def _rate(o: Outcome) -> str:
    return f"{o.expansions / o.wall_s:,.0f}" if o.solved and o.expansions and o.wall_s > 0 else "-"


def _ratio(ours: float, peer: float) -> str:
    return f"{ours / peer:.2f}x" if peer > 0 else "-"


def report(problems: Sequence[LargeProblem], by: dict[tuple[str, str], Outcome], actions: dict[str, int]) -> str:
    """The per-problem table and the totals against the goals, as markdown."""
    rows: list[list[object]] = []
    both: list[tuple[Outcome, Outcome]] = []
    for p in problems:
        ours, fd = by[(OURS, p.name)], by[(FD, p.name)]
        if ours.solved and fd.solved:
            both.append((ours, fd))

        def cell(o: Outcome) -> str:
            return f"{o.wall_s:.2f}" if o.solved else f"{o.status} ({o.wall_s:.0f} s)"

        rows.append(
            [
                p.name,
                f"{actions[p.name]:,}",
                cell(ours),
                cell(fd),
                f"{ours.expansions:,}" if ours.solved and ours.expansions else "-",
                f"{fd.expansions:,}" if fd.solved and fd.expansions else "-",
                _rate(ours),
                _rate(fd),
                _fmt(ours.peak_mb, 0),
                _fmt(fd.peak_mb, 0),
                _fmt(ours.cost, 0) if ours.solved else "-",
                _fmt(fd.cost, 0) if fd.solved else "-",
            ]
        )
    header = [
        "problem",
        "ground actions",
        "ours s",
        "lama-first s",
        "ours expansions",
        "lama-first expansions",
        "ours exp/s",
        "lama-first exp/s",
        "ours peak MB",
        "lama-first peak MB",
        "ours cost",
        "lama-first cost",
    ]
    write_tsv("large_runs", header, rows)
    out = ["### Large generated problems: ours (first plan) vs Fast Downward lama-first\n", markdown(header, rows)]
    solved_ours = sum(by[(OURS, p.name)].solved for p in problems)
    solved_fd = sum(by[(FD, p.name)].solved for p in problems)
    time_ours = sum(o.wall_s for o, _ in both)
    time_fd = sum(f.wall_s for _, f in both)
    peak_ours = max((o.peak_mb or 0.0 for o, _ in both), default=0.0)
    peak_fd = max((f.peak_mb or 0.0 for _, f in both), default=0.0)
    worst_peak = max(((o.peak_mb or 0.0) / (f.peak_mb or 1.0) for o, f in both), default=0.0)
    cost_ours = sum(o.cost or 0.0 for o, _ in both)
    cost_fd = sum(f.cost or 0.0 for _, f in both)
    ratios = {
        "time": time_ours / time_fd if time_fd else float("inf"),
        "memory": worst_peak,
        "cost": cost_ours / cost_fd if cost_fd else float("inf"),
    }

    def goal(name: str) -> str:
        return "met" if ratios[name] <= GOALS[name] else "missed"

    out.append(f"\n### Totals over the {len(both)} problems both solve (ours {solved_ours}, lama-first {solved_fd})\n")
    out.append(
        markdown(
            ["figure", "ours", "lama-first", "ratio", "goal", ""],
            [
                [
                    "total wall s",
                    f"{time_ours:.1f}",
                    f"{time_fd:.1f}",
                    _ratio(time_ours, time_fd),
                    "<= 1.0x",
                    goal("time"),
                ],
                [
                    "peak MB (largest; ratio: the worst problem's)",
                    f"{peak_ours:.0f}",
                    f"{peak_fd:.0f}",
                    f"{worst_peak:.2f}x",
                    "<= 1.5x",
                    goal("memory"),
                ],
                [
                    "total first-plan cost",
                    f"{cost_ours:.0f}",
                    f"{cost_fd:.0f}",
                    _ratio(cost_ours, cost_fd),
                    "<= 1.05x",
                    goal("cost"),
                ],
            ],
        )
    )
    return "\n".join(out)


def main(args: argparse.Namespace, ipc: Path) -> int:
    """Run the large suite (``args`` of ``bench/planners.py``; ``ipc`` the IPC folder, read in place)."""
    domains = [d.strip() for d in args.domains.split(",")] if args.domains else None
    unknown = sorted(set(domains or ()) - set(DOMAIN_FOLDERS))
    if unknown:
        print(f"error: no generator for {', '.join(unknown)}; choose from {', '.join(DOMAIN_FOLDERS)}", file=sys.stderr)
        return 2
    problems = write_set(OUT / "large", ipc, domains=domains)
    if args.limit:
        problems = problems[: args.limit]
    tasks = Tasks()
    by: dict[tuple[str, str], Outcome] = {}
    actions = {p.name: ground_actions(p) for p in problems}
    print(f"{len(problems)} problems, ours then lama-first, {args.time_limit:g} s limit each", file=sys.stderr)
    for p in problems:
        for planner in (OURS, FD):
            job = Job(planner, p.domain, p.name, p.domain_file, p.problem_file)
            run = run_ours if planner == OURS else run_fd
            outcome = run(job, args.time_limit, tasks, peak=True)
            by[(planner, p.name)] = outcome
            print(
                f"  {planner:<14} {p.name:<18} {outcome.status:<9} {outcome.valid:<7} cost {_fmt(outcome.cost, 0):>5} "
                f"{outcome.wall_s:7.2f} s  peak {_fmt(outcome.peak_mb, 0):>5} MB  {outcome.note}",
                file=sys.stderr,
                flush=True,
            )
    print(report(problems, by, actions))
    invalid = [o for o in by.values() if o.valid == "INVALID"]
    return 1 if any(o.job.planner == OURS for o in invalid) else 0
