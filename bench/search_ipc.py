"""The builtin search's first plan on the IPC suite (``ipc/`` of the benchmark sets), beside Fast Downward lama-first.

One problem at a time, each as a whole process with a wall limit (30 s): ours runs
``alica plan --json`` (the default first search), or ``search_task`` with another
first search (``--first``) in a child process of this script (imports, parsing,
grounding and search timed together); Fast Downward runs its driver with
``--alias lama-first`` (``bench/planners.py``'s ``run_fd``). Every plan is validated.
Results go to ``build/bench/search_ipc-<tag>.tsv`` (one row per problem, appended as they
come, so a later run with ``--resume`` skips the problems done) and a per-domain table to
standard output, compared with another tag (``--against fd``) where both ran.

The benchmark sets are read in place from ``--benchmarks DIR`` (the folder holding ``pddl/`` and ``ipc/``), else
the environment variable ``ALICA_BENCHMARKS``, else ``../shared/benchmarks`` beside the checkout.

Run: ``.venv/bin/python bench/search_ipc.py --planner ours --tag lama [--first lama] [--domains a,b] [--limit 30]
[--benchmarks DIR]``
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from bench.benchmark_sets import add_benchmarks_option, benchmark_set, default_benchmarks
from bench.planners import GRACE_S, Job, Outcome, Tasks, _validated, run_fd, run_process

OUT = ROOT / "build" / "bench"
FIELDS = ("domain", "problem", "status", "wall_s", "cost", "first_s", "expansions", "evaluations")


def _order(name: str) -> tuple[int, ...]:
    return tuple(int(x) for x in re.findall(r"\d+", name))


def jobs(domains: Sequence[str] | None, benchmarks: Path | None = None) -> list[Job]:
    """Every IPC problem (and blocks/rovers when named), in order, from the benchmark sets ``benchmarks`` (default: ``default_benchmarks()``)."""
    benchmarks = benchmarks or default_benchmarks()
    ipc, pddl = benchmark_set(benchmarks, "ipc"), benchmarks / "pddl"
    out: list[Job] = []
    names = sorted(p.name for p in ipc.iterdir() if p.is_dir())
    for extra in ("blocks", "rovers"):
        if domains and extra in domains:
            names.append(extra)
    for name in names:
        if domains and name not in domains:
            continue
        folder = (pddl if name in ("blocks", "rovers") else ipc) / name
        for prob in sorted(folder.glob("*.pddl"), key=lambda p: (_order(p.stem), p.stem)):
            if "domain" in prob.stem:
                continue
            dom = folder / "domain.pddl"
            if not dom.exists():
                dom = folder / f"{prob.stem.split('-')[0]}-domain.pddl"
            out.append(Job("ours", name, prob.stem, dom, prob))
    return out


def child(domain_file: str, problem_file: str, first: str) -> None:
    """Plan one problem (first plan only) and print a JSON summary."""
    start = time.perf_counter()
    from alica.prophet.ground import ground
    from alica.prophet.pddl import read_domain, read_problem
    from alica.prophet.planner import Done, Improved
    from alica.prophet.search.anytime import FirstSearch, search_task
    from alica.prophet.search.gbfs import Stats

    domain = read_domain(domain_file)
    task = ground(domain, read_problem(problem_file, domain))
    search = FirstSearch() if first == "default" else FirstSearch(first)
    evals = Stats(1000)
    plan = None
    first_s = None
    expansions = 0
    for event in search_task(task, anytime=False, first=search, stats=evals):
        if isinstance(event, Improved):
            plan = event.plan
            first_s = time.perf_counter() - start
        if isinstance(event, Done):
            expansions = event.expansions
    steps = [f"({' '.join((s.action, *s.args))})" for s in plan.steps] if plan else None
    print(
        json.dumps(
            {
                "plan": steps,
                "cost": plan.cost if plan else None,
                "first_s": first_s,
                "expansions": expansions,
                "evaluations": evals.evaluations,
            }
        )
    )


def run_ours(job: Job, limit: float, tasks: Tasks, first: str) -> tuple[Outcome, dict]:
    """The default first search through ``alica plan --json`` itself; another one through :func:`child`."""
    if first == "default":
        command = [sys.executable, "-m", "alica.app.cli", "plan", str(job.domain_file), str(job.problem_file)]
        command += ["--json", "--time-limit", f"{limit - GRACE_S:g}"]
    else:
        command = [sys.executable, __file__, "--child", str(job.domain_file), str(job.problem_file), "--first", first]
    proc = run_process(command, ROOT, limit)
    if proc.timed_out:
        return Outcome(job, proc.wall_s, "timeout"), {}
    if proc.code != 0 and not proc.out.strip():
        return Outcome(job, proc.wall_s, f"exit {proc.code}", note=proc.err.strip().splitlines()[-1:]), {}
    summary = json.loads(proc.out)
    summary.setdefault("first_s", summary.get("time_first_s"))
    if summary.get("plan") is None:
        return Outcome(job, proc.wall_s, "unsolved"), summary
    from alica.prophet.planners.planfile import parse_plan

    steps = parse_plan("\n".join(summary["plan"])).steps
    return _validated(Outcome(job, proc.wall_s, "ok"), steps, tasks, claimed=summary["cost"]), summary


def load(tag: str) -> dict[tuple[str, str], dict[str, str]]:
    path = OUT / f"search_ipc-{tag}.tsv"
    if not path.exists():
        return {}
    with path.open() as fh:
        return {(r["domain"], r["problem"]): r for r in csv.DictReader(fh, delimiter="\t")}


def summary_table(rows: dict, against: dict) -> str:
    lines = [
        "| domain | solved | vs | time (both solved) | vs | cost (both solved) | vs | ratio time | ratio cost |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    doms: dict[str, list] = {}
    for key, r in rows.items():
        doms.setdefault(key[0], []).append((key, r))
    tot = [0, 0, 0.0, 0.0, 0.0, 0.0, 0]
    for dom, items in doms.items():
        solved = sum(r["status"] == "VALID" for _k, r in items)
        other = sum(against.get(k, {}).get("status") == "VALID" for k, _r in items)
        both = [
            (r, against[k]) for k, r in items if r["status"] == "VALID" and against.get(k, {}).get("status") == "VALID"
        ]
        t1 = sum(float(a["wall_s"]) for a, _b in both)
        t2 = sum(float(b["wall_s"]) for _a, b in both)
        c1 = sum(float(a["cost"]) for a, _b in both)
        c2 = sum(float(b["cost"]) for _a, b in both)
        rt = f"{t1 / t2:.2f}" if t2 else "-"
        rc = f"{c1 / c2:.2f}" if c2 else "-"
        lines.append(
            f"| {dom} | {solved}/{len(items)} | {other} | {t1:.1f} | {t2:.1f} | {c1:g} | {c2:g} | {rt} | {rc} |"
        )
        for i, v in enumerate((solved, other, t1, t2, c1, c2, len(items))):
            tot[i] += v
    rt = f"{tot[2] / tot[3]:.2f}" if tot[3] else "-"
    rc = f"{tot[4] / tot[5]:.2f}" if tot[5] else "-"
    lines.append(
        f"| all | {tot[0]}/{tot[6]} | {tot[1]} | {tot[2]:.1f} | {tot[3]:.1f} | {tot[4]:g} | {tot[5]:g} | {rt} | {rc} |"
    )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", nargs=2, metavar=("DOMAIN", "PROBLEM"))
    parser.add_argument("--planner", choices=("ours", "fd"), default="ours")
    parser.add_argument("--first", default="default", help="the first search's heuristic (FirstSearch)")
    parser.add_argument("--tag", default=None, help="the results file's tag (default: the planner, or --first)")
    parser.add_argument("--domains", default="", help="comma-separated domain folders (default: every IPC domain)")
    parser.add_argument("--problems", default="", help="comma-separated problem names (default: all)")
    parser.add_argument("--limit", type=float, default=30.0)
    parser.add_argument("--resume", action="store_true", help="skip problems the tag's file already has")
    parser.add_argument("--against", default="fd", help="compare with this tag's results")
    parser.add_argument("--table", action="store_true", help="print the table of the stored results only")
    add_benchmarks_option(parser)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child[0], args.child[1], args.first)
        return 0
    tag = args.tag or ("fd" if args.planner == "fd" else args.first)
    domains = [d for d in args.domains.split(",") if d] or None
    problems = {p for p in args.problems.split(",") if p}
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"search_ipc-{tag}.tsv"
    done = load(tag)
    if not args.table:
        if not args.resume:
            done = {}
            path.write_text("\t".join(FIELDS) + "\n")
        elif not path.exists():
            path.write_text("\t".join(FIELDS) + "\n")
        tasks = Tasks()
        for job in jobs(domains, args.benchmarks):
            if problems and job.problem not in problems:
                continue
            if (job.domain, job.problem) in done:
                continue
            if args.planner == "fd":
                try:
                    outcome, extra = run_fd(job, args.limit, tasks), {}
                except Exception as error:  # our reader refuses the input (derived predicates): not validated
                    outcome, extra = Outcome(job, 0.0, "unread", note=str(error)), {}
                if outcome.wall_s > args.limit:
                    outcome.valid = "-"
            else:
                try:
                    outcome, extra = run_ours(job, args.limit + GRACE_S, tasks, args.first)
                except Exception as error:
                    outcome, extra = Outcome(job, 0.0, "unread", note=str(error)), {}
                if outcome.wall_s > args.limit:
                    outcome.valid = "-"
            status = outcome.valid if outcome.valid != "-" else outcome.status
            row = {
                "domain": job.domain,
                "problem": job.problem,
                "status": status,
                "wall_s": f"{outcome.wall_s:.2f}",
                "cost": "" if outcome.cost is None else f"{outcome.cost:g}",
                "first_s": "" if extra.get("first_s") is None else f"{extra['first_s']:.2f}",
                "expansions": str(extra.get("expansions", "")),
                "evaluations": str(extra.get("evaluations", "")),
            }
            done[(job.domain, job.problem)] = row
            with path.open("a") as fh:
                fh.write("\t".join(row[f] for f in FIELDS) + "\n")
            print("\t".join(row[f] for f in FIELDS), flush=True)
    rows = {k: v for k, v in load(tag).items() if not domains or k[0] in domains}
    print(summary_table(rows, load(args.against)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
