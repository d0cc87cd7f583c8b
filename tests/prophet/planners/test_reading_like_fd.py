"""PDDL that Fast Downward reads and the builtin planner reads alike, and the refusals that remain (issue 22)."""

from __future__ import annotations

import json
from pathlib import Path

from alica.prophet.pddl import parse_domain, parse_problem
from alica.prophet.pddl.model import Atom
from alica.prophet.planner import PlanStatus
from alica.prophet.planners import get_planner
from tests.conftest import benchmark_set

TIGHT = """(define (domain tight)
  (:requirements :strips :typing)
  (:types plane city)
  (:predicates (at ?a - plane ?c - city) (aircraft ?a))
  (:action fly
    :parameters (?a - plane ?from ?to - city)
    :precondition (and (aircraft?a) (at ?a ?from))
    :effect (and (not (at ?a ?from)) (at ?a ?to))))
"""
TIGHT_PROBLEM = """(define (problem p) (:domain tight)
  (:objects p1 - plane c1 c2 - city)
  (:init (aircraft p1) (at p1 c1))
  (:goal (at p1 c2)))
"""


def test_a_question_mark_starts_a_new_word_as_fast_downward_reads_it() -> None:
    domain = parse_domain(TIGHT, "tight.pddl")
    fly = domain.actions[0]
    assert Atom("aircraft", ("?a",)) in fly.precondition.parts  # type: ignore[attr-defined]
    result = get_planner("builtin").solve(domain, parse_problem(TIGHT_PROBLEM, "p.pddl", domain))
    assert result.status is PlanStatus.SOLVED
    assert [str(s) for s in result.plan.steps] == ["(fly p1 c1 c2)"]  # type: ignore[union-attr]


def _blowing_up(tmp_path: Path, objects: int) -> tuple[Path, Path]:
    """A precondition with an 'or' inside a 'forall' over ``objects`` objects: 2**objects disjuncts."""
    domain = tmp_path / "lamps.pddl"
    domain.write_text(
        """(define (domain lamps)
  (:requirements :adl)
  (:predicates (red ?x) (green ?x) (done))
  (:action check
    :parameters ()
    :precondition (forall (?x) (or (red ?x) (green ?x)))
    :effect (done)))
""",
        encoding="utf-8",
    )
    problem = tmp_path / "many.pddl"
    names = " ".join(f"l{i}" for i in range(objects))
    problem.write_text(
        f"(define (problem many) (:domain lamps) (:objects {names}) (:init {' '.join(f'(red l{i})' for i in range(objects))}) (:goal (done)))\n",
        encoding="utf-8",
    )
    return domain, problem


def test_a_precondition_too_large_to_expand_is_compiled_into_derived_predicates_and_planned(alica, tmp_path) -> None:  # type: ignore[no-untyped-def]
    domain, problem = _blowing_up(tmp_path, 13)  # 2**13 disjuncts if multiplied out
    run = alica("plan", domain, problem, "--json")
    assert run.code == 0, run.err
    answer = json.loads(run.out)
    assert answer["solved"] is True and answer["plan"] == ["(check)"]


def test_a_small_quantified_disjunction_is_planned(alica, tmp_path) -> None:  # type: ignore[no-untyped-def]
    domain, problem = _blowing_up(tmp_path, 4)
    run = alica("plan", domain, problem, "--json")
    assert run.code == 0
    assert json.loads(run.out)["solved"] is True


def test_with_json_a_refused_input_prints_solved_false_with_the_place(alica, tmp_path) -> None:  # type: ignore[no-untyped-def]
    bad = tmp_path / "bad.pddl"
    bad.write_text("(define (domain x)\n  (:action)\n", encoding="utf-8")
    problem = tmp_path / "p.pddl"
    problem.write_text("(define (problem p) (:domain x))\n", encoding="utf-8")
    run = alica("plan", bad, problem, "--json")
    assert run.code == 1
    answer = json.loads(run.out)
    assert answer["solved"] is False and answer["error"].startswith(f"{bad}:")
    run = alica("plan", tmp_path / "none.pddl", problem, "--json")
    assert run.code == 1
    answer = json.loads(run.out)
    assert answer["solved"] is False and "none.pddl" in answer["error"]


def test_ipc_storage_reads_and_plans(alica) -> None:  # type: ignore[no-untyped-def]
    """Storage declares 'area' under two parents and types 'in' with (either storearea crate)."""
    folder = benchmark_set("ipc") / "storage"
    run = alica("plan", folder / "domain.pddl", folder / "p03.pddl", "--json")
    assert run.code == 0, run.err
    answer = json.loads(run.out)
    assert answer["solved"] is True and answer["cost"] == len(answer["plan"])
