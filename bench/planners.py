"""Our planner (``alica plan``) beside Fast Downward lama-first and pyperplan gbf-hff on the standard PDDL benchmarks (read in place from ../shared/benchmarks, or ``--benchmarks DIR``).

Every problem runs as a whole process, one at a time by default (the machine has 2
cores; timings must not compete), with a wall limit (60 s):

* ours: ``python -m alica.app.cli plan DOMAIN PROBLEM --json --time-limit 60``;
* Fast Downward 26.6 from PyPI ``up-fast-downward``: its driver with ``--alias lama-first``;
* pyperplan (PyPI ``pyperplan``, a peer only, installed for the bench):
  ``python -m pyperplan -s gbf -H hff`` on copies of the files (it writes ``PROBLEM.soln``
  next to the problem);
* ours again after an anytime budget (``--anytime --time-limit 10``) on the blocks problems
  with a proven optimum (``optimal_costs.tsv``) and on Rovers p01-p20;
* the grounding alone (:func:`alica.prophet.ground.ground`, after parsing) on Rovers p18-p20 in a
  fresh process each, the median of 3.

Every plan, ours and the peers', is validated with :func:`alica.prophet.validate.validate_plan`;
an invalid plan counts as unsolved. Times are whole-process wall seconds. The tables
(markdown on standard output, TSV in ``build/bench/``): coverage per domain; Rovers
p01-p20 total time, ours vs Fast Downward (goal: at most 2x); per-problem cost on Rovers
p01-p20 vs the IMPERA paper's Table 1, our first plan and ours after the anytime budget (goal:
ours at most that on each); blocks after the anytime budget vs the optimum (goal: total at
most 1.15x); the grounding time of Rovers p18-p20 (goal: at most 0.1 s each).

The benchmark sets are read in place from the folder holding ``pddl/`` and ``ipc/``: ``--benchmarks DIR``, else the
environment variable ``ALICA_BENCHMARKS``, else ``../shared/benchmarks`` beside the checkout
(:mod:`bench.benchmark_sets`).

With ``--suite ipc`` (issue 22) the 175 problems of the 26 domains in ``ipc/`` of that folder instead (airport
and psr-small: each problem ``pNN-*.pddl`` with its own ``pNN-domain.pddl``), 30 s each: ours (first plan),
Fast Downward lama-first, then ours with ``--anytime --time-limit 10`` on every problem. Each run is appended
to ``build/bench/ipc_runs.tsv`` as it completes; at the end three markdown tables: per domain (solved, invalid,
errors, total time and first-plan cost on the problems both solve, anytime cost vs FD's), issue 22's goals
(met or missed) and the problems ours fails with the reason. ``--report-only`` prints the tables from that
TSV (of a run stopped early, say).

Run: ``.venv/bin/python bench/planners.py [--domains blocks,rovers] [--limit N] [--jobs 1] [--quick] [--benchmarks DIR]``

With ``--suite large`` (issue 41) generated problems larger than the suite's, ours and lama-first with their peak
memory (:mod:`bench.planners_large`): ``.venv/bin/python bench/planners.py --suite large [--domains logistics]
[--limit N] [--time-limit 60]``.

or: ``.venv/bin/python bench/planners.py --suite ipc [--domains a,b] [--limit N] [--time-limit 30]
[--anytime-budget 10] [--skip-anytime] [--skip-fd] [--report-only] [--benchmarks DIR]``
"""

from __future__ import annotations

import argparse
import compileall
import contextlib
import importlib.util
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from alica.prophet.pddl import Domain, read_domain, read_problem
from alica.prophet.planner import PlanStep
from alica.prophet.planners.fd import find_driver
from alica.prophet.planners.planfile import parse_plan
from alica.prophet.validate import validate_plan
from bench.benchmark_sets import add_benchmarks_option, benchmark_set, default_benchmarks

BENCHMARKS = default_benchmarks() / "pddl"
"""The classic sets (blocks, rovers); :func:`use_benchmarks` moves it and :data:`IPC`."""
IPC = default_benchmarks() / "ipc"
OUT = ROOT / "build" / "bench"
IMPERA_TABLE1 = (10, 8, 13, 10, 22, 38, 18, 28, 34, 36, 38, 22, 46, 32, 44, 43, 52, 48, 74, 87)
"""Fast Downward (FDP) costs of Rovers1-20 in the IMPERA paper's Table 1."""
IMPERA_EARLY = tuple(f"p{i:02d}" for i in range(1, 21))
"""The Rovers problems of that table (also the ones ours runs on with the anytime budget)."""
GROUND_PROBLEMS = ("p18", "p19", "p20")
"""The Rovers problems whose grounding is timed (goal: at most 0.1 s each)."""
GROUND_REPEATS = 3
GRACE_S = 5.0
QUICK = {
    "blocks": ("probBLOCKS-4-0", "probBLOCKS-5-2", "probBLOCKS-6-1", "probBLOCKS-8-0"),
    "rovers": ("p01", "p03", "p05", "p10"),
}
OURS, FD, PYPERPLAN, ANYTIME = "ours", "fd lama-first", "pyperplan gbf-hff", "ours anytime 10 s"


@dataclass(frozen=True, slots=True)
class Job:
    """One planner on one problem."""

    planner: str
    domain: str
    problem: str
    domain_file: Path
    problem_file: Path


@dataclass(slots=True)
class Outcome:
    """What a job gave: a plan (validated) or why not."""

    job: Job
    wall_s: float
    status: str
    steps: tuple[PlanStep, ...] | None = None
    cost: float | None = None
    valid: str = "-"
    note: str = ""
    peak_mb: float | None = None
    expansions: int | None = None

    @property
    def solved(self) -> bool:
        """Whether the job gave a valid plan."""
        return self.valid == "VALID"


@dataclass(frozen=True, slots=True)
class Proc:
    """A finished (or killed) process."""

    code: int | None
    wall_s: float
    out: str
    err: str
    timed_out: bool
    peak_mb: float | None = None


@dataclass
class Tasks:
    """Parsed domains and problems, each read once, for validation."""

    domains: dict[Path, Domain] = field(default_factory=dict)

    def check(self, job: Job, steps: Sequence[PlanStep]) -> tuple[bool, float, str]:
        """Validate ``steps`` on the job's task: (valid, cost, reason)."""
        domain = self.domains.get(job.domain_file)
        if domain is None:
            domain = self.domains[job.domain_file] = read_domain(job.domain_file)
        result = validate_plan((domain, read_problem(job.problem_file, domain)), tuple(steps))
        return result.valid, result.cost, result.reason


def _child_env() -> dict[str, str]:
    """The planners' environment: with bytecode caching, as an installed package has it.

    Under ``PYTHONDONTWRITEBYTECODE`` an edited checkout recompiles its changed modules in every
    process (0.1 s and more per run), while a peer installed by pip ships compiled bytecode.
    """
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def compile_bytecode() -> None:
    """Compile the project's modules once, before any timed run (see :func:`_child_env`)."""
    for folder in ("alica", "prophet", "skills", "worldsim", "plans"):
        compileall.compile_dir(str(ROOT / folder), quiet=1)


def run_process(command: Sequence[str], cwd: Path, timeout: float, peak: bool = False) -> Proc:
    """Run ``command`` in its own process group; kill the whole group after ``timeout`` wall seconds.

    With ``peak``, through :mod:`bench.peak_rss`, which reports the largest resident set of the
    command's processes (``Proc.peak_mb``).
    """
    report = None
    if peak:
        handle, name = tempfile.mkstemp(prefix="bench-peak-", suffix=".txt")
        os.close(handle)
        report = Path(name)
        command = [sys.executable, str(ROOT / "bench" / "peak_rss.py"), str(report), "--", *command]
    start = time.perf_counter()
    with subprocess.Popen(
        list(command),
        cwd=cwd,
        env=_child_env(),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    ) as process:
        try:
            out, err = process.communicate(timeout=timeout)
            timed_out = False
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
            out, err = process.communicate()
            timed_out = True
        wall = time.perf_counter() - start
    peak_mb = None
    if report is not None:  # the launcher's own wall time leaves out its start-up
        with contextlib.suppress(OSError, ValueError):
            peak_kb, child_wall = report.read_text(encoding="utf-8").split()
            peak_mb, wall = int(peak_kb) / 1024, float(child_wall)
        report.unlink(missing_ok=True)
    return Proc(process.returncode, wall, out, err, timed_out, peak_mb)


def run_ours(job: Job, limit: float, tasks: Tasks, anytime: bool = False, peak: bool = False) -> Outcome:
    """``alica plan --json``: the plan it printed, validated again here."""
    command = [
        sys.executable,
        "-m",
        "alica.app.cli",
        "plan",
        os.path.relpath(job.domain_file, ROOT),
        os.path.relpath(job.problem_file, ROOT),
        "--json",
        "--time-limit",
        f"{limit:g}",
    ]
    if anytime:
        command.append("--anytime")
    proc = run_process(command, ROOT, limit + GRACE_S, peak)
    if proc.timed_out:
        return Outcome(job, proc.wall_s, "killed", peak_mb=proc.peak_mb)
    if proc.code != 0:
        status = {3: "unsolvable", 4: "timeout"}.get(proc.code or 0, f"exit {proc.code}")
        note = _json_error(proc.out) or _last_line(proc.err)
        return Outcome(job, proc.wall_s, status, note=note, peak_mb=proc.peak_mb)
    summary = json.loads(proc.out)
    steps = parse_plan("\n".join(summary["plan"])).steps
    outcome = Outcome(job, proc.wall_s, "ok", peak_mb=proc.peak_mb, expansions=summary.get("expansions"))
    return _validated(outcome, steps, tasks, claimed=summary["cost"])


def run_fd(job: Job, limit: float, tasks: Tasks, peak: bool = False) -> Outcome:
    """Fast Downward's driver with lama-first, in a temporary folder; the plan file, validated."""
    driver = find_driver()
    if driver is None:
        return Outcome(job, 0.0, "not installed")
    with tempfile.TemporaryDirectory(prefix="bench-fd-") as tmp:
        command = [
            sys.executable,
            str(driver),
            "--overall-time-limit",
            f"{int(limit)}s",
            "--alias",
            "lama-first",
            "--plan-file",
            "sas_plan",
            str(job.domain_file),
            str(job.problem_file),
        ]
        proc = run_process(command, Path(tmp), limit + GRACE_S, peak)
        plan_file = Path(tmp) / "sas_plan"
        if not plan_file.exists():
            status = (
                "killed"
                if proc.timed_out
                else {10: "unsolvable", 11: "unsolvable", 23: "timeout"}.get(proc.code or 0, f"exit {proc.code}")
            )
            return Outcome(job, proc.wall_s, status, note=_last_line(proc.err), peak_mb=proc.peak_mb)
        plan = parse_plan(plan_file.read_text(encoding="utf-8"), "sas_plan")
    expanded = re.findall(r"Expanded (\d+) state", proc.out)
    outcome = Outcome(job, proc.wall_s, "ok", peak_mb=proc.peak_mb, expansions=int(expanded[-1]) if expanded else None)
    return _validated(outcome, plan.steps, tasks, claimed=plan.cost)


def run_pyperplan(job: Job, limit: float, tasks: Tasks) -> Outcome:
    """pyperplan gbf with hFF on copies of the files; its ``.soln`` file, validated."""
    if importlib.util.find_spec("pyperplan") is None:
        return Outcome(job, 0.0, "not installed")
    with tempfile.TemporaryDirectory(prefix="bench-pyperplan-") as tmp:
        folder = Path(tmp)
        domain = shutil.copy(job.domain_file, folder / "domain.pddl")
        problem = shutil.copy(job.problem_file, folder / job.problem_file.name)
        command = [sys.executable, "-m", "pyperplan", "-s", "gbf", "-H", "hff", str(domain), str(problem)]
        proc = run_process(command, folder, limit)
        solution = Path(f"{problem}.soln")
        if not solution.exists():
            return Outcome(job, proc.wall_s, "killed" if proc.timed_out else "no plan", note=_last_line(proc.err))
        plan = parse_plan(solution.read_text(encoding="utf-8"), solution.name)
    return _validated(Outcome(job, proc.wall_s, "ok"), plan.steps, tasks, claimed=None)


def _validated(outcome: Outcome, steps: tuple[PlanStep, ...], tasks: Tasks, claimed: float | None) -> Outcome:
    try:
        valid, cost, reason = tasks.check(outcome.job, steps)
    except Exception as error:  # our reader refuses the task (a peer's plan on a domain ours cannot read)
        outcome.steps, outcome.cost, outcome.valid = steps, claimed, "UNCHECKED"
        outcome.note = "not validated: " + str(error).strip().splitlines()[0].replace(f"{ROOT}{os.sep}", "")
        return outcome
    outcome.steps, outcome.cost = steps, cost
    outcome.valid = "VALID" if valid else "INVALID"
    if not valid:
        outcome.note = reason
    elif claimed is not None and abs(claimed - cost) > 1e-9:
        outcome.note = f"claimed cost {claimed}, validated {cost}"
    return outcome


def _json_error(out: str) -> str:
    """The first line of the error ``alica plan --json`` printed for a refused input ("" if none)."""
    with contextlib.suppress(ValueError, AttributeError):
        error = json.loads(out).get("error")
        if error:
            return str(error).strip().splitlines()[0]
    return ""


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1][:160] if lines else ""


def _order(name: str) -> tuple[int, ...]:
    return tuple(int(n) for n in re.findall(r"\d+", name))


def use_benchmarks(folder: Path) -> None:
    """Read the benchmark sets from ``folder`` (``--benchmarks``): its ``pddl/`` and ``ipc/``."""
    global BENCHMARKS, IPC
    BENCHMARKS, IPC = folder / "pddl", folder / "ipc"


def problems(domain: str, limit: int | None, quick: bool) -> list[Job]:
    """The benchmark problems of ``domain`` (natural order), as planner-less jobs."""
    folder = BENCHMARKS / domain
    names = sorted((p.stem for p in folder.glob("*.pddl") if p.name != "domain.pddl"), key=_order)
    if quick:
        names = [n for n in names if n in QUICK.get(domain, ())]
    if limit is not None:
        names = names[:limit]
    return [Job("", domain, n, folder / "domain.pddl", folder / f"{n}.pddl") for n in names]


def optimal_costs(domain: str) -> dict[str, float]:
    """The proven optimal costs of ``optimal_costs.tsv`` (problems without one are left out)."""
    path = BENCHMARKS / domain / "optimal_costs.tsv"
    costs: dict[str, float] = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#") or not line.strip():
            continue
        name, _, value = line.partition("\t")
        with contextlib.suppress(ValueError):
            costs[name.strip()] = float(value)
    return costs


def _fmt(value: float | None, digits: int = 2) -> str:
    if value is None:
        return "-"
    return str(int(value)) if float(value).is_integer() and digits == 0 else f"{value:.{digits}f}"


def markdown(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def write_tsv(name: str, header: Sequence[str], rows: Iterable[Sequence[object]]) -> None:
    """One table as ``build/bench/NAME.tsv``."""
    OUT.mkdir(parents=True, exist_ok=True)
    text = "\t".join(header) + "\n" + "".join("\t".join(str(c) for c in row) + "\n" for row in rows)
    (OUT / f"{name}.tsv").write_text(text, encoding="utf-8")


def table(name: str, title: str, header: Sequence[str], rows: list[list[object]], note: str = "") -> None:
    """Print one table as markdown and write it as TSV."""
    print(f"\n### {title}\n")
    print(markdown(header, rows))
    if note:
        print(f"\n{note}")
    write_tsv(name, header, rows)


def report(outcomes: list[Outcome], limit: float, budget: float) -> None:
    """Print the four tables (those the runs allow) and write them with every run as TSV."""
    by = {(o.job.planner, o.job.domain, o.job.problem): o for o in outcomes}
    domains = sorted({o.job.domain for o in outcomes})
    planners = [p for p in (OURS, FD, PYPERPLAN) if any(o.job.planner == p for o in outcomes)]
    write_tsv(
        "planners_runs",
        ["planner", "domain", "problem", "status", "valid", "cost", "wall_s", "note"],
        [
            [o.job.planner, o.job.domain, o.job.problem, o.status, o.valid, _fmt(o.cost, 0), f"{o.wall_s:.3f}", o.note]
            for o in outcomes
        ],
    )

    rows = []
    for domain in domains:
        total = len({o.job.problem for o in outcomes if o.job.domain == domain and o.job.planner == OURS})
        rows.append(
            [
                domain,
                *(
                    f"{sum(1 for o in outcomes if o.job.planner == p and o.job.domain == domain and o.solved)}/{total}"
                    for p in planners
                ),
            ]
        )
    if len(domains) > 1:
        total = sum(1 for o in outcomes if o.job.planner == OURS)
        rows.append(
            ["all", *(f"{sum(1 for o in outcomes if o.job.planner == p and o.solved)}/{total}" for p in planners)]
        )
    table("planners_coverage", f"Coverage (valid plans within {limit:g} s)", ["domain", *planners], rows)

    present = [p for p in IMPERA_EARLY if (OURS, "rovers", p) in by]
    if present:
        rows = []
        for planner in planners:
            runs = [by.get((planner, "rovers", p)) for p in present]
            solved = [r for r in runs if r is not None and r.solved]
            rows.append(
                [planner, f"{len(solved)}/{len(present)}", f"{sum(r.wall_s for r in runs if r is not None):.2f}"]
            )
        ours = sum(by[(OURS, "rovers", p)].wall_s for p in present)
        fd = (
            sum(by[(FD, "rovers", p)].wall_s for p in present)
            if all((FD, "rovers", p) in by for p in present)
            else None
        )
        ratio = f"ours / fd = {ours / fd:.2f}x (goal: at most 2x)" if fd else ""
        table(
            "planners_rovers_time",
            f"Rovers {present[0]}-{present[-1]}: total whole-process wall time (s)",
            ["planner", "solved", "total wall s"],
            rows,
            ratio,
        )

        rovers_cost_table(by, present, planners, budget)

    anytime = [o for o in outcomes if o.job.planner == ANYTIME and o.job.domain == "blocks"]
    if anytime:
        optimum = optimal_costs("blocks")
        rows = []
        total_ours = total_opt = 0.0
        for o in sorted(anytime, key=lambda o: _order(o.job.problem)):
            best = optimum[o.job.problem]
            first = by.get((OURS, "blocks", o.job.problem))
            if o.solved and o.cost is not None:
                total_ours += o.cost
                total_opt += best
            rows.append(
                [
                    o.job.problem,
                    _fmt(best, 0),
                    _fmt(first.cost if first and first.solved else None, 0),
                    _fmt(o.cost if o.solved else None, 0),
                    f"{o.cost / best:.2f}" if o.solved and o.cost else "-",
                ]
            )
        solved = sum(1 for o in anytime if o.solved)
        note = (
            (
                f"solved {solved}/{len(anytime)}; total cost {total_ours:g} vs optimum {total_opt:g} = "
                f"{total_ours / total_opt:.3f}x on the solved ones (goal: at most 1.15x)"
            )
            if total_opt
            else f"solved {solved}/{len(anytime)}"
        )
        table(
            "planners_blocks_anytime",
            f"Blocks with a proven optimum: ours after {budget:g} s anytime vs the optimum",
            ["problem", "optimum", "ours first plan", f"ours anytime {budget:g} s", "ratio"],
            rows,
            note,
        )


def _solved_cost(by: dict[tuple[str, str, str], Outcome], planner: str, problem: str) -> float | None:
    run = by.get((planner, "rovers", problem))
    return run.cost if run is not None and run.solved else None


def rovers_cost_table(
    by: dict[tuple[str, str, str], Outcome], present: Sequence[str], planners: Sequence[str], budget: float
) -> None:
    """Rovers cost per problem vs IMPERA's Table 1: our first plan, ours after the anytime budget, the peers."""
    anytime = f"ours anytime {budget:g} s"
    with_anytime = any((ANYTIME, "rovers", p) in by for p in present)
    peers = [p for p in planners if p != OURS]
    header = ["problem", "IMPERA", "ours first plan", *([anytime] if with_anytime else []), *peers, "first <= IMPERA"]
    header += [f"anytime {budget:g} s <= IMPERA"] if with_anytime else []
    rows = []
    met_first = met_anytime = 0
    for p in present:
        impera = IMPERA_TABLE1[int(p[1:]) - 1]
        first = _solved_cost(by, OURS, p)
        ok_first = first is not None and first <= impera
        met_first += ok_first
        row: list[object] = [p, impera, _fmt(first, 0)]
        if with_anytime:
            best = _solved_cost(by, ANYTIME, p)
            ok_anytime = best is not None and best <= impera
            met_anytime += ok_anytime
            row.append(_fmt(best, 0))
        row += [_fmt(_solved_cost(by, peer, p), 0) for peer in peers]
        row.append("yes" if ok_first else "NO")
        if with_anytime:
            row.append("yes" if ok_anytime else "NO")
        rows.append(row)
    note = f"ours at most IMPERA's cost on {met_first} of {len(present)} with the first plan"
    if with_anytime:
        note += f", on {met_anytime} of {len(present)} after the {budget:g} s anytime budget"
    table("planners_rovers_cost", "Rovers: plan cost vs the IMPERA paper's Table 1 (FDP)", header, rows, note)


GROUND_SCRIPT = """
import json, statistics, sys, time
from alica.prophet.ground import ground
from alica.prophet.pddl import read_domain, read_problem
domain = read_domain(sys.argv[1])
problem = read_problem(sys.argv[2], domain)
times = []
for _ in range(int(sys.argv[3])):
    start = time.perf_counter()
    task = ground(domain, problem)
    times.append(time.perf_counter() - start)
    del task
print(json.dumps({"median_s": statistics.median(times), "times_s": times}))
"""


def grounding_table(names: Sequence[str] = GROUND_PROBLEMS, repeats: int = GROUND_REPEATS) -> None:
    """Time the grounding alone (after parsing) of Rovers problems, each in a fresh process."""
    folder = BENCHMARKS / "rovers"
    rows = []
    for name in names:
        command = [sys.executable, "-c", GROUND_SCRIPT, str(folder / "domain.pddl"), str(folder / f"{name}.pddl")]
        proc = run_process([*command, str(repeats)], ROOT, 120.0)
        if proc.code != 0:
            rows.append([name, "-", "-", _last_line(proc.err)])
            continue
        result = json.loads(proc.out)
        each = " ".join(f"{t:.3f}" for t in result["times_s"])
        rows.append([name, f"{result['median_s']:.3f}", each, "yes" if result["median_s"] <= 0.1 else "NO"])
    table(
        "planners_grounding",
        f"Grounding time of Rovers {names[0]}-{names[-1]} (s, after parsing, median of {repeats})",
        ["problem", "median s", "runs s", "<= 0.1 s"],
        rows,
    )


def jobs_for(domains: Sequence[str], limit: int | None, quick: bool, planners: Sequence[str]) -> list[Job]:
    """Every job of the run, in a fixed order: per problem ours, FD, pyperplan; then the anytime runs."""
    jobs: list[Job] = []
    anytime: list[Job] = []
    for domain in domains:
        known = optimal_costs(domain) if domain == "blocks" else {}
        for base in problems(domain, limit, quick):
            for planner in planners:
                jobs.append(Job(planner, base.domain, base.problem, base.domain_file, base.problem_file))
            if OURS in planners and (base.problem in known or (domain == "rovers" and base.problem in IMPERA_EARLY)):
                anytime.append(Job(ANYTIME, base.domain, base.problem, base.domain_file, base.problem_file))
    return jobs + anytime


RUN_HEADER = ("planner", "domain", "problem", "status", "valid", "cost", "wall_s", "note")
GOAL_TIME, GOAL_ANYTIME, GOAL_FIRST = 1.0, 0.8, 1.1
"""Issue 22's goals on the IPC suite: ours / FD on total time, anytime cost and first-plan cost."""


def ipc_problems(domain: str, limit: int | None) -> list[Job]:
    """The problems of ``IPC/DOMAIN`` (natural order), each with its domain file, as planner-less jobs.

    A folder holds ``domain.pddl``, or (airport, psr-small) one ``pNN-domain.pddl`` per problem ``pNN-*.pddl``.
    """
    folder = IPC / domain
    shared = folder / "domain.pddl"
    jobs = []
    for path in sorted((p for p in folder.glob("*.pddl") if "domain" not in p.name), key=lambda p: _order(p.stem)):
        domain_file = shared if shared.exists() else folder / f"{path.stem.split('-')[0]}-domain.pddl"
        if not domain_file.exists():
            raise FileNotFoundError(f"no domain file for {path}")
        jobs.append(Job("", domain, path.stem, domain_file, path))
    return jobs[:limit] if limit is not None else jobs


def ipc_domains() -> list[str]:
    """Every domain folder of ``IPC`` (``ipc/`` of the benchmark sets)."""
    return sorted(p.name for p in IPC.iterdir() if p.is_dir())


def ipc_jobs(domains: Sequence[str], limit: int | None, planners: Sequence[str]) -> list[Job]:
    """Every job of an IPC run: per problem ours and FD (those in ``planners``); then the anytime runs."""
    bases = [base for domain in domains for base in ipc_problems(domain, limit)]
    first = [
        Job(p, b.domain, b.problem, b.domain_file, b.problem_file) for b in bases for p in planners if p != ANYTIME
    ]
    later = [Job(ANYTIME, b.domain, b.problem, b.domain_file, b.problem_file) for b in bases if ANYTIME in planners]
    return first + later


def run_row(o: Outcome) -> list[object]:
    """One run as a row of ``RUN_HEADER``."""
    cost = "-" if o.cost is None else f"{o.cost:g}"
    return [o.job.planner, o.job.domain, o.job.problem, o.status, o.valid, cost, f"{o.wall_s:.3f}", o.note]


def read_runs(path: Path) -> list[Outcome]:
    """The runs of a ``RUN_HEADER`` TSV (as :func:`run_row` wrote them), for a report without running."""
    outcomes = []
    for line in path.read_text(encoding="utf-8").splitlines()[1:]:
        planner, domain, problem, status, valid, cost, wall, note = (line.split("\t") + [""] * 8)[:8]
        job = Job(planner, domain, problem, Path(), Path())
        value = None if cost == "-" else float(cost)
        outcomes.append(Outcome(job, float(wall), status, cost=value, valid=valid, note=note))
    return outcomes


def _ratio(ours: float, peer: float) -> str:
    return f"{ours / peer:.2f}x" if peer else "-"


def ipc_report(outcomes: Sequence[Outcome], limit: float, budget: float) -> str:
    """The IPC suite's tables as markdown: per domain, issue 22's goals, the problems ours fails."""
    by = {(o.job.planner, o.job.domain, o.job.problem): o for o in outcomes}
    domains = sorted({o.job.domain for o in outcomes})
    has_fd = any(o.job.planner == FD for o in outcomes)
    has_anytime = any(o.job.planner == ANYTIME for o in outcomes)
    keys = {d: sorted({o.job.problem for o in outcomes if o.job.domain == d}, key=_order) for d in domains}

    def sums(domain_list: Sequence[str]) -> list[float]:
        n = solved_o = solved_f = invalid_o = invalid_f = errors = 0
        t_o = t_f = c_o = c_f = a_o = a_f = 0.0
        for d in domain_list:
            for p in keys[d]:
                ours, fd, anytime = by.get((OURS, d, p)), by.get((FD, d, p)), by.get((ANYTIME, d, p))
                n += 1
                solved_o += bool(ours and ours.solved)
                solved_f += bool(fd and (fd.solved or fd.valid == "UNCHECKED"))
                invalid_o += sum(1 for r in (ours, anytime) if r and r.valid == "INVALID")
                invalid_f += bool(fd and fd.valid == "INVALID")
                errors += bool(ours and ours.status.startswith("exit"))
                if ours and fd and ours.solved and fd.solved:
                    t_o, t_f = t_o + ours.wall_s, t_f + fd.wall_s
                    c_o, c_f = c_o + (ours.cost or 0.0), c_f + (fd.cost or 0.0)
                if anytime and fd and anytime.solved and fd.solved:
                    a_o, a_f = a_o + (anytime.cost or 0.0), a_f + (fd.cost or 0.0)
        return [n, solved_o, solved_f, invalid_o, invalid_f, errors, t_o, t_f, c_o, c_f, a_o, a_f]

    def row(name: str, s: list[float]) -> list[object]:
        n, so, sf, io, i_f, err, t_o, t_f, c_o, c_f, a_o, a_f = s
        cells: list[object] = [name, int(n), int(so), int(sf) if has_fd else "-", f"{int(io)} / {int(i_f)}", int(err)]
        cells += [f"{t_o:.2f}", f"{t_f:.2f}", _ratio(t_o, t_f), f"{c_o:g}", f"{c_f:g}", _ratio(c_o, c_f)]
        cells += [f"{a_o:g}", f"{a_f:g}", _ratio(a_o, a_f)] if has_anytime else ["-", "-", "-"]
        return cells

    anytime_name = f"anytime {budget:g} s"
    header = ["domain", "problems", "solved ours", f"solved fd ({limit:g} s)", "invalid ours / fd", "errors ours"]
    header += ["time both ours s", "time both fd s", "time ratio", "first cost ours", "first cost fd", "first ratio"]
    header += [f"{anytime_name} cost ours", f"{anytime_name} cost fd", f"{anytime_name} ratio"]
    total = sums(domains)
    rows = [row(d, sums([d])) for d in domains] + [row("total", total)]
    out = [
        f"### IPC suite: ours vs Fast Downward lama-first ({limit:g} s each, {anytime_name})\n",
        markdown(header, rows),
    ]
    unchecked = [f"{o.job.domain}/{o.job.problem}" for o in outcomes if o.job.planner == FD and o.valid == "UNCHECKED"]
    out.append(
        "\n'time both' and 'first cost': the problems both ours (first plan) and FD solved; "
        f"'{anytime_name}': the problems where ours after the anytime budget and FD have a plan; "
        "errors: ours refused or crashed. Invalid plans count as unsolved."
        + (
            f" FD's solved count includes {len(unchecked)} plan(s) our validator cannot read the task of "
            f"(not validated): {', '.join(unchecked)}."
            if unchecked
            else ""
        )
    )

    n, so, sf, io, _, _, t_o, t_f, c_o, c_f, a_o, a_f = total

    def goal(met: bool) -> str:
        return "met" if met else "missed"

    goals = [
        ["coverage", f"ours {int(so)}/{int(n)} vs fd {int(sf)}/{int(n)} (same run)", ">= fd's count", goal(so >= sf)],
        [
            "total time on both-solved",
            _ratio(t_o, t_f),
            f"<= {GOAL_TIME:g}x",
            goal(bool(t_f) and t_o <= GOAL_TIME * t_f),
        ],
        [
            f"{anytime_name} cost, summed",
            _ratio(a_o, a_f) if has_anytime else "not run",
            f"<= {GOAL_ANYTIME:g}x",
            goal(bool(a_f) and a_o <= GOAL_ANYTIME * a_f),
        ],
        [
            "first-plan cost, summed",
            _ratio(c_o, c_f),
            f"<= {GOAL_FIRST:g}x",
            goal(bool(c_f) and c_o <= GOAL_FIRST * c_f),
        ],
        ["invalid plans (ours)", str(int(io)), "0", goal(io == 0)],
    ]
    out += ["\n### Issue 22's goals\n", markdown(["goal", "measured", "target", "status"], goals)]

    def reason(run: Outcome) -> str:
        if run.valid == "INVALID":
            return f"invalid plan: {run.note}"
        if run.status == "killed" and not run.note:
            return f"no answer within its time limit + {GRACE_S:g} s grace: killed"
        return run.note

    failing = []
    for d in domains:
        for p in keys[d]:
            runs = [(name, r) for name, r in (("first", by.get((OURS, d, p))), ("anytime", by.get((ANYTIME, d, p))))]
            fails = [(name, r) for name, r in runs if r is not None and not r.solved]
            if len(fails) == 2 and fails[0][1].status == fails[1][1].status:
                first, anytime = fails[0][1], fails[1][1]
                walls = f"{first.wall_s:.2f} / {anytime.wall_s:.2f}"
                fails = [("first, anytime", first)]
            else:
                walls = ""
            for name, run in fails:
                wall = walls or f"{run.wall_s:.2f}"
                failing.append([d, p, name, run.status, wall, reason(run).replace("|", "\\|")])
    problems_failing = len({(row[0], row[1]) for row in failing})
    out.append(f"\n### Problems ours fails ({problems_failing}; run: first plan, anytime or both)\n")
    header = ["domain", "problem", "run", "status", "wall s (first / anytime)", "reason (the first run's)"]
    out.append(markdown(header, failing) if failing else "none")
    return "\n".join(out)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the bench; returns the exit code."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--suite",
        choices=("classic", "ipc", "large"),
        default="classic",
        help="classic: pddl/ of the benchmark sets (blocks, rovers); ipc: the 26 domains of their ipc/; large: "
        "problems generated larger than those (bench/large_problems.py) on ipc/'s domains (default classic)",
    )
    add_benchmarks_option(parser)
    parser.add_argument(
        "--domains", help="comma-separated benchmark domains (default blocks,rovers; for ipc every domain)"
    )
    parser.add_argument("--limit", type=int, help="the first N problems of each domain")
    parser.add_argument("--jobs", type=int, default=1, help="processes at a time (default 1: timings must not compete)")
    parser.add_argument("--quick", action="store_true", help="a few small problems per domain, for a smoke run")
    parser.add_argument(
        "--time-limit", type=float, metavar="S", help="wall seconds per run (default 60; 30 with --suite ipc)"
    )
    parser.add_argument(
        "--anytime-budget",
        type=float,
        default=10.0,
        metavar="S",
        help="ours --anytime on blocks with an optimum and Rovers p01-p20, or every ipc problem (default 10)",
    )
    parser.add_argument("--planners", default=f"{OURS},fd,pyperplan", help="which of ours, fd, pyperplan (default all)")
    parser.add_argument("--skip-anytime", action="store_true", help="ipc: no anytime runs")
    parser.add_argument("--skip-fd", action="store_true", help="ipc: no Fast Downward runs")
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="ipc: no runs, the tables from build/bench/ipc_runs.tsv (e.g. of a run stopped early)",
    )
    args = parser.parse_args(argv)
    if args.suite == "large":
        from bench import planners_large

        use_benchmarks(args.benchmarks)
        compile_bytecode()
        args.time_limit = 60.0 if args.time_limit is None else args.time_limit
        return planners_large.main(args, benchmark_set(args.benchmarks, "ipc"))
    if not args.report_only:
        benchmark_set(args.benchmarks, "ipc" if args.suite == "ipc" else "pddl")
        use_benchmarks(args.benchmarks)
        compile_bytecode()
    if args.time_limit is None:
        args.time_limit = 30.0 if args.suite == "ipc" else 60.0

    if args.suite == "ipc":
        runs_path = OUT / "ipc_runs.tsv"
        if args.report_only:
            print(ipc_report(read_runs(runs_path), args.time_limit, args.anytime_budget))
            return 0
        domains = [d.strip() for d in args.domains.split(",") if d.strip()] if args.domains else ipc_domains()
        planners = [OURS, *([] if args.skip_fd else [FD]), *([] if args.skip_anytime else [ANYTIME])]
        jobs = ipc_jobs(domains, args.limit, planners)
        OUT.mkdir(parents=True, exist_ok=True)
        runs_path.write_text("\t".join(RUN_HEADER) + "\n", encoding="utf-8")
    else:
        names = {"ours": OURS, "fd": FD, "pyperplan": PYPERPLAN}
        planners = [names[p.strip()] for p in args.planners.split(",") if p.strip()]
        domains = [d.strip() for d in (args.domains or "blocks,rovers").split(",") if d.strip()]
        jobs = jobs_for(domains, args.limit, args.quick, planners)
    tasks = Tasks()
    runners: dict[str, Callable[[Job], Outcome]] = {
        OURS: lambda j: run_ours(j, args.time_limit, tasks),
        FD: lambda j: run_fd(j, args.time_limit, tasks),
        PYPERPLAN: lambda j: run_pyperplan(j, args.time_limit, tasks),
        ANYTIME: lambda j: run_ours(j, args.anytime_budget, tasks, anytime=True),
    }
    print(f"{len(jobs)} runs, {args.jobs} at a time, {args.time_limit:g} s limit each", file=sys.stderr)
    lock = threading.Lock()

    def one(job: Job) -> Outcome:
        outcome = runners[job.planner](job)
        with lock:
            print(
                f"  {job.planner:<18} {job.domain}/{job.problem:<16} {outcome.status:<10} {outcome.valid:<7} "
                f"cost {_fmt(outcome.cost, 0):>4}  {outcome.wall_s:7.2f} s {outcome.note}",
                file=sys.stderr,
                flush=True,
            )
            if args.suite == "ipc":
                with (OUT / "ipc_runs.tsv").open("a", encoding="utf-8") as runs:
                    runs.write("\t".join(str(c).replace("\t", " ") for c in run_row(outcome)) + "\n")
        return outcome

    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        outcomes = list(pool.map(one, jobs))
    if args.suite == "ipc":
        print(ipc_report(outcomes, args.time_limit, args.anytime_budget))
    else:
        report(outcomes, args.time_limit, args.anytime_budget)
        if "rovers" in domains and not args.quick:
            grounding_table()
    invalid = [o for o in outcomes if o.valid == "INVALID"]
    if invalid:
        runs_name = "ipc_runs" if args.suite == "ipc" else "planners_runs"
        print(f"\n{len(invalid)} INVALID plan(s): see build/bench/{runs_name}.tsv", file=sys.stderr)
    return 1 if any(o.job.planner in (OURS, ANYTIME) and o.valid == "INVALID" for o in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
