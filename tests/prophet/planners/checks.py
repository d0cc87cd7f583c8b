"""Checks the CLI tests share: JSON keys, and plans validated against the PDDL files."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from alica.prophet.pddl import read_domain, read_problem
from alica.prophet.planner import PlanStep
from alica.prophet.planners.planfile import parse_plan
from alica.prophet.validate import validate_plan

JSON_KEYS = {"solved", "cost", "plan", "time_first_s", "time_s", "expansions"}

#: A task no plan solves: the goal wants the switch on and off at once.
UNSOLVABLE_DOMAIN = """\
(define (domain switch)
  (:requirements :strips)
  (:predicates (on) (off))
  (:action turn-on
    :parameters ()
    :precondition (off)
    :effect (and (on) (not (off)))))
"""
UNSOLVABLE_PROBLEM = """\
(define (problem both-at-once)
  (:domain switch)
  (:init (off))
  (:goal (and (on) (off))))
"""


def valid_cost(domain: Path, problem: Path, steps: list[PlanStep] | tuple[PlanStep, ...]) -> float:
    """The cost of a plan that must be valid for the task in the files."""
    d = read_domain(domain)
    check = validate_plan((d, read_problem(problem, d)), tuple(steps))
    assert check.valid, check.reason
    return check.cost


def check_json(out: str, domain: Path, problem: Path) -> dict[str, Any]:
    """The ``--json`` output of a solved run, checked: exact keys, a valid plan of the given cost."""
    summary = json.loads(out)
    assert set(summary) == JSON_KEYS
    assert summary["solved"] is True
    assert all(isinstance(s, str) and s.startswith("(") and s.endswith(")") for s in summary["plan"])
    steps = parse_plan("\n".join(summary["plan"])).steps
    assert valid_cost(domain, problem, steps) == summary["cost"]
    assert 0 <= summary["time_first_s"] <= summary["time_s"]
    assert isinstance(summary["expansions"], int)
    return summary


def check_text(out: str, domain: Path, problem: Path) -> float:
    """The text output of a solved run, checked: a plan file whose steps are valid; its cost."""
    assert "valid: checked with alica.prophet.validate" in out
    assert "time to first plan:" in out and "final cost:" in out and "expansions:" in out
    plan = parse_plan(out)
    assert len(plan) > 0
    assert valid_cost(domain, problem, plan.steps) == plan.cost
    return plan.cost
