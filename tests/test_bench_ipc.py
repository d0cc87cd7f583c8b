"""bench/planners.py --suite ipc: its job listing and its tables on made-up outcomes (nothing is run)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from tests.conftest import benchmark_set

ROOT = Path(__file__).resolve().parent.parent


def _bench() -> ModuleType:
    name = "bench_planners"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, ROOT / "bench" / "planners.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def test_ipc_jobs_pair_every_problem_with_its_domain_file() -> None:
    benchmark_set("ipc")  # the bench reads the same folder (bench/benchmark_sets.py)
    bench = _bench()
    jobs = bench.ipc_jobs(bench.ipc_domains(), None, [bench.OURS, bench.FD, bench.ANYTIME])
    assert len(bench.ipc_domains()) == 26
    for planner in (bench.OURS, bench.FD, bench.ANYTIME):
        assert sum(1 for j in jobs if j.planner == planner) == 175
    assert [j.planner for j in jobs[:2]] == [bench.OURS, bench.FD]
    assert all(j.planner == bench.ANYTIME for j in jobs[-175:])
    for job in jobs:
        assert job.domain_file.exists() and job.problem_file.exists()
        assert "domain" not in job.problem_file.name
        if job.domain in ("airport", "psr-small"):
            assert job.domain_file.name == f"{job.problem.split('-')[0]}-domain.pddl"
        else:
            assert job.domain_file.name == "domain.pddl"
    airport = [j for j in jobs if j.domain == "airport" and j.planner == bench.OURS]
    assert [(j.problem, j.domain_file.name) for j in airport[:2]] == [
        ("p01-airport1-p1", "p01-domain.pddl"),
        ("p02-airport1-p1", "p02-domain.pddl"),
    ]
    assert len(bench.ipc_jobs(["depot", "airport"], 2, [bench.OURS])) == 4


def test_ipc_report_on_made_up_outcomes() -> None:
    bench = _bench()

    def run(planner: str, problem: str, cost: float | None, wall: float, status: str = "ok", note: str = "") -> object:
        job = bench.Job(planner, "d", problem, Path(), Path())
        valid = "VALID" if cost is not None else "-"
        return bench.Outcome(job, wall, status, cost=cost, valid=valid, note=note)

    outcomes = [
        run(bench.OURS, "p1", 10, 1.0),
        run(bench.FD, "p1", 10, 2.0),
        run(bench.ANYTIME, "p1", 7, 10.0),
        run(bench.OURS, "p2", None, 0.3, "exit 1", "error: unsupported construct"),
        run(bench.FD, "p2", 5, 1.0),
        run(bench.ANYTIME, "p2", None, 0.3, "exit 1", "error: unsupported construct"),
    ]
    text = bench.ipc_report(outcomes, 30, 10)
    sums = "| 2 | 1 | 2 | 0 / 0 | 1 | 1.00 | 2.00 | 0.50x | 10 | 10 | 1.00x | 7 | 10 | 0.70x |"
    assert f"| d {sums}" in text and f"| total {sums}" in text
    assert "| coverage | ours 1/2 vs fd 2/2 (same run) | >= fd's count | missed |" in text
    assert "| total time on both-solved | 0.50x | <= 1x | met |" in text
    assert "| anytime 10 s cost, summed | 0.70x | <= 0.8x | met |" in text
    assert "| invalid plans (ours) | 0 | 0 | met |" in text
    assert "### Problems ours fails (1; run: first plan, anytime or both)" in text
    assert "| d | p2 | first, anytime | exit 1 | 0.30 / 0.30 | error: unsupported construct |" in text


def test_ipc_report_counts_a_peer_plan_our_reader_refuses_as_solved_and_says_so() -> None:
    bench = _bench()
    ours = bench.Outcome(bench.Job(bench.OURS, "d", "p1", Path(), Path()), 0.2, "exit 1", note="error: '(:derived'")
    fd = bench.Outcome(bench.Job(bench.FD, "d", "p1", Path(), Path()), 0.5, "ok", cost=3.0, valid="UNCHECKED")
    text = bench.ipc_report([ours, fd], 30, 10)
    assert "| coverage | ours 0/1 vs fd 1/1 (same run) | >= fd's count | missed |" in text
    assert "includes 1 plan(s) our validator cannot read the task of (not validated): d/p1." in text
