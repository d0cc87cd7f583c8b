"""MAGiC over agent processes linked by zenoh on loopback (the leader in the test's process)."""

from __future__ import annotations

from alica.app.magic_processes import run_processes
from alica.prophet.pddl import parse_domain, parse_problem
from alica.prophet.planner import PlanStatus
from alica.prophet.validate import validate_plan
from tests.conftest import benchmark_set


def test_three_agent_processes_give_a_valid_plan_within_the_message_bound() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    domain, problem = (rovers / "domain.pddl").read_text(), (rovers / "p05.pddl").read_text()
    run = run_processes(domain, problem, 3, timeout=60)
    assert run.status is PlanStatus.SOLVED and run.plan is not None
    parsed = parse_domain(domain)
    assert validate_plan((parsed, parse_problem(problem, "p05", parsed)), run.plan).valid
    assert 4 <= run.messages <= 6  # two shares and two finals at least
    assert run.agents == 3 and run.first_plan_s is not None


def test_a_worker_process_killed_during_the_round_is_not_waited_for():
    rovers = benchmark_set("pddl") / "rovers"
    domain, problem = (rovers / "domain.pddl").read_text(), (rovers / "p10.pddl").read_text()
    run = run_processes(domain, problem, 3, timeout=60.0, kill_after={"agent2": 0.0})
    assert run.status is PlanStatus.SOLVED and run.plan is not None
    assert "agent2" in run.lost
    assert run.messages <= 3 * (3 - 1)
