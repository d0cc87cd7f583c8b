"""A few benchmark problems through the real parser and grounding (the benchmark folder must be there)."""

from __future__ import annotations

import pytest

from alica.prophet import ground as grounding
from alica.prophet import pddl
from alica.prophet.planner import Done, Improved, PlanStatus
from alica.prophet.search import BuiltinPlanner, search_task
from tests.conftest import benchmark_set
from tests.prophet.search.helpers import check_plan

CASES = [
    ("blocks", "probBLOCKS-4-0", 6),
    ("blocks", "probBLOCKS-6-0", 12),
    ("rovers", "p01", 10),
    ("rovers", "p03", 11),
]


def load(domain: str, problem: str):
    folder = benchmark_set("pddl") / domain
    d = pddl.read_domain(folder / "domain.pddl")
    return d, pddl.read_problem(folder / f"{problem}.pddl", d)


@pytest.mark.parametrize(("domain", "problem", "optimum"), CASES)
def test_benchmark_problem(domain: str, problem: str, optimum: int) -> None:
    d, p = load(domain, problem)
    task = grounding.ground(d, p)
    events = []
    for event in search_task(task):
        events.append(event)
        if sum(isinstance(e, Improved) for e in events) and len(events) > 2000:
            break
    found = [e.plan for e in events if isinstance(e, Improved)]
    assert found
    for plan in found:
        check_plan(task, plan)
    assert found[-1].cost >= optimum
    if isinstance(events[-1], Done) and events[-1].status is PlanStatus.OPTIMAL:
        assert found[-1].cost == optimum


def test_builtin_planner_solve() -> None:
    d, p = load("rovers", "p01")
    result = BuiltinPlanner().solve(d, p, time_limit=10)
    assert result.solved and result.planner == "builtin"
    check_plan(grounding.ground(d, p), result.plan)
