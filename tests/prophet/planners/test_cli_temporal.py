"""``alica plan`` on durative actions: the temporal planner's schedule, checked happening by happening."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from tests.prophet.pddl.test_durative import DOMAIN
from tests.prophet.planners.conftest import Run
from tests.prophet.test_temporal import APART, TWO_ROVERS


def _files(tmp_path: Path, domain: str, problem: str) -> tuple[Path, Path]:
    d, p = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    d.write_text(domain, encoding="utf-8")
    p.write_text(problem, encoding="utf-8")
    return d, p


def test_alica_plan_schedules_durative_actions_and_prints_the_makespan(
    alica: Callable[..., Run], tmp_path: Path
) -> None:
    files = _files(tmp_path, DOMAIN, APART)
    run = alica("plan", *files)
    assert run.code == 0, run.err
    lines = run.out.splitlines()
    assert lines[:4] == [
        "0.000: (recharge r) [2.500]",
        "0.000: (recharge s) [2.500]",
        "2.501: (move r p q) [4.000]",
        "2.501: (move s y x) [3.000]",
    ]
    assert "; cost = 6.501 (4 steps, valid: checked with alica.prophet.validate_temporal)" in lines
    assert "; planner: temporal" in lines and "; sequential_makespan: 12.003" in lines
    summary = json.loads(alica("plan", *files, "--json").out)
    assert summary["solved"] and summary["cost"] == 6.501 and summary["sequential_makespan"] == 12.003


def test_a_durative_action_the_planner_cannot_take_is_refused_in_one_line(
    alica: Callable[..., Run], tmp_path: Path
) -> None:
    domain = """(define (domain d) (:requirements :durative-actions) (:predicates (p) (q))
      (:durative-action a :parameters () :duration (= ?duration 1) :condition (over all (p))
        :effect (at start (not (p)))))"""
    files = _files(tmp_path, domain, "(define (problem e) (:domain d) (:init (p)) (:goal (q)))")
    run = alica("plan", *files)
    assert run.code == 1 and "Traceback" not in run.err
    assert "durative action a: its over all condition (p) is broken by its own start effects" in run.err


def test_alica_plan_gives_two_rovers_the_work_the_sequential_search_gives_one(
    alica: Callable[..., Run], tmp_path: Path
) -> None:
    files = _files(tmp_path, DOMAIN, TWO_ROVERS)
    run = alica("plan", *files)
    assert run.code == 0, run.err
    lines = run.out.splitlines()
    assert lines[:4] == [
        "0.000: (recharge r) [2.500]",
        "0.000: (recharge s) [2.500]",
        "2.501: (move r p q) [4.000]",
        "2.501: (move s p x) [3.000]",
    ]
    assert "; cost = 6.501 (4 steps, valid: checked with alica.prophet.validate_temporal)" in lines
    assert "; sequential_makespan: 12.003" in lines  # the same steps one after another
