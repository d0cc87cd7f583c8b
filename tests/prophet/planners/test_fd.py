"""The Fast Downward back-end (optional: skipped when ``up-fast-downward`` is not installed).

The skip checks for the planner's driver and binary inside the installed
package rather than importing ``up_fast_downward``: that module needs
``unified-planning``, which the back-end does not use.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import pytest

from alica.prophet.pddl import read_domain, read_problem
from alica.prophet.planner import Done, Improved, PlanStatus
from alica.prophet.planners import get_planner
from alica.prophet.planners.fd import FastDownward, find_driver
from tests.prophet.planners.checks import JSON_KEYS, check_json, check_text, valid_cost

if find_driver() is None:
    pytest.skip("Fast Downward is not installed: pip install 'alica-teams[fd]'", allow_module_level=True)

pytestmark = pytest.mark.optional


@pytest.fixture(autouse=True)
def own_tempdir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Temporary folders of the back-end go here, so a test can see them cleaned up."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    yield folder
    assert list(folder.iterdir()) == []


def test_cli_blocks_text(alica, blocks) -> None:
    domain, problem = blocks("4-0")
    run = alica("plan", domain, problem, "--planner", "fd")
    assert run.code == 0, run.err
    assert check_text(run.out, domain, problem) >= 6
    assert "; planner: fd" in run.out


def test_cli_rovers_json(alica, rovers) -> None:
    domain, problem = rovers("p01")
    run = alica("plan", domain, problem, "--planner", "fd", "--json")
    assert run.code == 0, run.err
    assert check_json(run.out, domain, problem)["cost"] == 10


def test_cli_unsolvable_exit_3(alica, unsolvable) -> None:
    run = alica("plan", *unsolvable, "--planner", "fd")
    assert run.code == 3, run.err
    assert "Fast Downward proved the task unsolvable" in run.out


def test_cli_timeout_exit_4(alica, rovers) -> None:
    run = alica("plan", *rovers("p30"), "--planner", "fd", "--time-limit", "0.01", "--json")
    assert run.code == 4, run.out
    summary = json.loads(run.out)
    assert set(summary) == JSON_KEYS and summary["solved"] is False


def test_cli_anytime(alica, blocks) -> None:
    domain, problem = blocks("9-0")
    run = alica("plan", domain, problem, "--planner", "fd", "--anytime", "--time-limit", "3", "--json")
    assert run.code == 0, run.err
    assert check_json(run.out, domain, problem)["cost"] <= 60  # lama-first's cost here


def test_anytime_events_improve_while_fd_runs(rovers) -> None:
    domain, problem = rovers("p20")
    events = list(FastDownward(time_limit=4).search(domain, problem, anytime=True))
    improved = [e for e in events if isinstance(e, Improved)]
    assert len(improved) >= 2
    costs = [e.plan.cost for e in improved]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert isinstance(events[-1], Done) and events[-1].status is PlanStatus.SOLVED
    assert events.index(improved[0]) < len(events) - 2  # the first plan came while FD was still running
    assert valid_cost(domain, problem, improved[-1].plan.steps) == costs[-1]


def test_stopping_early_ends_the_planner(rovers) -> None:
    domain, problem = rovers("p20")
    search = FastDownward().search(domain, problem, anytime=True)  # no limit: lama would run on
    first = next(e for e in search if isinstance(e, Improved))
    search.close()  # kills Fast Downward and removes its folder (checked by the fixture)
    assert first.plan.cost > 0


def test_parsed_objects_are_written_for_fd(blocks) -> None:
    domain_file, problem_file = blocks("6-1")
    domain = read_domain(domain_file)
    problem = read_problem(problem_file, domain)
    result = get_planner("fd").solve(domain, problem, time_limit=30)
    assert result.status is PlanStatus.SOLVED and result.plan is not None
    assert valid_cost(domain_file, problem_file, result.plan.steps) == result.cost


def test_optimal_alias(blocks) -> None:
    result = get_planner("fd", alias="seq-opt-lmcut").solve(*blocks("5-2"), time_limit=30)
    assert result.status is PlanStatus.OPTIMAL and result.cost == 16
    assert result.expansions > 0 and result.time_first_s is not None


def test_fd_failure_gives_its_output_tail(tmp_path: Path, blocks) -> None:
    broken = tmp_path / "broken.pddl"
    broken.write_text(
        "(define (problem p) (:domain blocks) (:objects a) (:init (clear a)) (:goal (on a b)))\n", encoding="utf-8"
    )
    result = FastDownward().solve(blocks("4-0")[0], broken, time_limit=30)
    assert result.status is PlanStatus.ERROR and result.plan is None
    assert "Fast Downward failed (exit code" in result.message
    assert len(result.message.splitlines()) > 1


def test_missing_input_file(tmp_path: Path, blocks) -> None:
    from alica.errors import PlannerError

    with pytest.raises(PlannerError, match="problem file .* does not exist"):
        FastDownward().solve(blocks("4-0")[0], tmp_path / "none.pddl", time_limit=5)
