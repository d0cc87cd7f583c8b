"""``alica plan`` end to end with the builtin planner: exit codes, output, validation, errors."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

import alica.prophet.planners as planners
from alica.prophet.planner import Done, Feature, Improved, Plan, Planner, PlanStatus, PlanStep, SearchEvent
from tests.prophet.planners.checks import JSON_KEYS, check_json, check_text


def test_blocks_text(alica, blocks) -> None:
    domain, problem = blocks("4-0")
    run = alica("plan", domain, problem)
    assert run.code == 0, run.err
    assert check_text(run.out, domain, problem) >= 6  # 6 is optimal
    assert "; planner: builtin" in run.out


def test_blocks_json(alica, blocks) -> None:
    domain, problem = blocks("4-0")
    run = alica("plan", domain, problem, "--json")
    assert run.code == 0, run.err
    assert check_json(run.out, domain, problem)["cost"] >= 6


def test_rovers_json(alica, rovers) -> None:
    domain, problem = rovers("p01")
    run = alica("plan", domain, problem, "--json", "--planner", "builtin")
    assert run.code == 0, run.err
    assert check_json(run.out, domain, problem)["cost"] >= 10  # 10 is optimal


def test_anytime_reaches_the_optimum_on_a_small_task(alica, blocks) -> None:
    domain, problem = blocks("5-2")
    run = alica("plan", domain, problem, "--anytime", "--time-limit", "10", "--json")
    assert run.code == 0, run.err
    assert check_json(run.out, domain, problem)["cost"] == 16


def test_unsolvable_exit_3(alica, unsolvable) -> None:
    run = alica("plan", *unsolvable)
    assert run.code == 3, run.err
    assert "proven unsolvable" in run.out
    run = alica("plan", *unsolvable, "--json")
    assert run.code == 3
    assert json.loads(run.out) == {k: v for k, v in json.loads(run.out).items() if k in JSON_KEYS}
    assert json.loads(run.out)["solved"] is False and json.loads(run.out)["plan"] is None


def test_timeout_exit_4(alica, rovers) -> None:
    run = alica("plan", *rovers("p30"), "--time-limit", "0.01", "--json")  # ~1000 expansions to a first plan
    assert run.code == 4, run.out
    summary = json.loads(run.out)
    assert set(summary) == JSON_KEYS and summary["solved"] is False and summary["cost"] is None


def test_parse_error_exit_1(alica, tmp_path: Path, blocks) -> None:
    bad = tmp_path / "bad-domain.pddl"
    bad.write_text(
        "(define (domain x)\n  (:predicates (p)\n  (:action a :parameters () :effect (p))\n", encoding="utf-8"
    )
    run = alica("plan", bad, blocks("4-0")[1])
    assert run.code == 1
    first = run.err.splitlines()[0]
    assert first.startswith(f"{bad}:3:3: error: "), run.err
    assert "Traceback" not in run.err and run.out == ""


def test_parse_error_in_problem(alica, tmp_path: Path, blocks) -> None:
    bad = tmp_path / "bad-problem.pddl"
    bad.write_text(
        "(define (problem p) (:domain blocks)\n  (:objects a)\n  (:init (clear a) (ontable a) (handempty))\n  (:goal (on a zz)))\n",
        encoding="utf-8",
    )
    run = alica("plan", blocks("4-0")[0], bad)
    assert run.code == 1
    assert run.err.startswith(f"{bad}:4:"), run.err
    assert ": error: " in run.err and "Traceback" not in run.err


def test_missing_file(alica, tmp_path: Path, blocks) -> None:
    missing = tmp_path / "nowhere.pddl"
    run = alica("plan", blocks("4-0")[0], missing)
    assert run.code == 1
    assert str(missing) in run.err and "Traceback" not in run.err


def test_unknown_planner(alica, blocks) -> None:
    run = alica("plan", *blocks("4-0"), "--planner", "nope")
    assert run.code == 2
    assert "invalid choice: 'nope'" in run.err and "'builtin', 'fd'" in run.err


def test_bad_time_limit(alica, blocks) -> None:
    run = alica("plan", *blocks("4-0"), "--time-limit", "-1")
    assert run.code == 2 and "positive" in run.err


class _Scripted(Planner):
    """A back-end that answers with a fixed plan or a fixed failure."""

    name = "scripted"
    features = frozenset(Feature)

    def __init__(self, plan: Plan | None, status: PlanStatus, message: str = "") -> None:
        self.plan, self.status, self.message = plan, status, message

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        if self.plan is not None:
            yield Improved(self.plan, 1)
        yield Done(self.status, 1, self.message)


def test_an_invalid_plan_from_a_back_end_is_an_error(alica, blocks, monkeypatch: pytest.MonkeyPatch) -> None:
    wrong = Plan((PlanStep("stack", ("a", "b")),), 1.0)
    monkeypatch.setattr(planners, "get_planner", lambda name: _Scripted(wrong, PlanStatus.SOLVED))
    run = alica("plan", *blocks("4-0"))
    assert run.code == 1 and run.out == ""
    assert "planner 'scripted' returned an invalid plan: step 1" in run.err


def test_a_failing_back_end_is_an_error(alica, blocks, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(planners, "get_planner", lambda name: _Scripted(None, PlanStatus.ERROR, "it broke"))
    run = alica("plan", *blocks("4-0"), "--json")
    assert run.code == 1
    assert json.loads(run.out) == {"solved": False, "error": "planner 'scripted' failed: it broke"}
    assert "planner 'scripted' failed: it broke" in run.err


def test_parallel_runs_magic_over_agent_processes(alica, rovers) -> None:
    domain, problem = rovers("p03")
    run = alica("plan", domain, problem, "--parallel", "3", "--json", "--time-limit", "60")
    assert run.code == 0, run.err
    summary = json.loads(run.out)
    assert set(summary) == JSON_KEYS | {"agents", "messages"}
    check_json(json.dumps({k: v for k, v in summary.items() if k in JSON_KEYS}), domain, problem)
    assert summary["agents"] == 3
    assert 0 < summary["messages"] <= 6


def test_parallel_proves_unsolvable_and_refuses_other_planners(alica, unsolvable, rovers) -> None:
    run = alica("plan", *unsolvable, "--parallel", "2", "--json", "--time-limit", "60")
    assert run.code == 3, run.err
    summary = json.loads(run.out)
    assert (summary["solved"], summary["agents"]) == (False, 2) and summary["messages"] <= 3
    run = alica("plan", *rovers("p01"), "--parallel", "2", "--anytime")
    assert run.code == 1 and "--parallel runs MAGiC" in run.err


def _psr(problem: str = "p01-s17-n2-l2-f30") -> tuple[Path, Path]:
    from tests.conftest import benchmark_set

    folder = benchmark_set("ipc") / "psr-middle"
    return folder / "domain.pddl", folder / f"{problem}.pddl"


def test_the_builtin_planners_plan_is_checked_on_its_ground_task(alica, monkeypatch: pytest.MonkeyPatch) -> None:
    import alica.prophet.validate as validate
    from alica.prophet.ground import GroundTask

    checked: list[object] = []
    original = validate.validate_plan

    def spy(task: object, plan: object) -> object:
        checked.append(task)
        return original(task, plan)  # type: ignore[arg-type]

    monkeypatch.setattr(validate, "validate_plan", spy)
    run = alica("plan", *_psr(), "--json")
    assert run.code == 0, run.err
    assert len(checked) == 1 and isinstance(
        checked[0], GroundTask
    )  # derived facts recomputed by the grounding's fixpoint
    assert check_json(run.out, *_psr())["solved"]  # and the lifted check agrees


class _Grounding(_Scripted):
    """A back-end that grounds the task itself, then answers with a fixed plan."""

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        from alica.prophet.ground import ground

        self.last_ground_task = ground(domain, problem)  # type: ignore[arg-type]
        yield from super()._search(domain, problem, anytime=anytime)


def test_a_plan_that_leaves_a_derived_goal_false_is_refused_on_the_ground_task(
    alica, monkeypatch: pytest.MonkeyPatch
) -> None:
    run = alica("plan", *_psr(), "--json")
    steps = [PlanStep(s.strip("()").split()[0], tuple(s.strip("()").split()[1:])) for s in json.loads(run.out)["plan"]]
    short = Plan(tuple(steps[:-1]), len(steps) - 1)
    monkeypatch.setattr(planners, "get_planner", lambda name: _Grounding(short, PlanStatus.SOLVED))
    run = alica("plan", *_psr())
    assert run.code == 1 and run.out == ""
    assert "planner 'scripted' returned an invalid plan: goal" in run.err and "does not hold after the plan" in run.err
