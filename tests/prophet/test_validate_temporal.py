"""Temporal plans: parsed with their places, and validated happening by happening (PDDL 2.1 semantics)."""

from __future__ import annotations

import re

import pytest

from alica.prophet.pddl import parse_domain, parse_problem
from alica.prophet.temporal_plan import TemporalPlanError, parse_temporal_plan
from alica.prophet.validate import ValidationResult
from alica.prophet.validate_temporal import validate_temporal_plan
from tests.prophet.pddl.test_durative import DOMAIN

PROBLEM = """(define (problem two) (:domain rovers-t)
  (:objects r s - rover p q - place)
  (:init (at r p) (at s p) (path p q) (= (travel p q) 4))
  (:goal (visited q))
  (:metric minimize (total-time)))
"""


def check(text: str) -> ValidationResult:
    domain = parse_domain(DOMAIN)
    return validate_temporal_plan(domain, parse_problem(PROBLEM, domain=domain), parse_temporal_plan(text))


def test_a_plan_with_its_happenings_apart_is_valid_and_costs_its_makespan() -> None:
    result = check("0.000: (recharge r) [2.500]\n0.000: (recharge s) [2.500]\n2.501: (move r p q) [4.000]")
    assert result.valid, result.reason
    assert result.cost == pytest.approx(6.501)


@pytest.mark.parametrize(
    ("plan", "reason"),
    [
        ("0: (move r p q) [4]", r"step 1 \(move r p q\): at start condition \(charged r\) does not hold at 0\.000"),
        (
            "0: (recharge r) [2.5]\n3: (move r p q) [3]",
            r"step 2 \(move r p q\): duration 3 differs from the domain's 4",
        ),
        (
            "0: (recharge r) [2.5]\n2.5: (move r p q) [4]",
            r"step 1 \(recharge r\) and step 2 \(move r p q\) interfere at 2\.500 \(change \(charged r\), which the other reads\)",
        ),
        (
            "0: (recharge r) [2.5]\n3: (move r p q) [4]\n3.5: (close p q) [1]",
            r"step 2 \(move r p q\): over all condition \(path p q\) does not hold at 4\.500",
        ),
        (
            "0: (recharge r) [2.5]\n3: (move r p q) [4]\n5: (drain r) [1]",
            r"step 2 \(move r p q\): at end condition \(charged r\) does not hold at 7\.000",
        ),
        ("0: (recharge r) [2.5]", r"goal \(visited q\) does not hold after the plan"),
        ("0: (fly r p q) [1]", r"step 1 \(fly r p q\): unknown durative action 'fly'"),
        ("0: (recharge p) [2.5]", r"step 1 \(recharge p\): 'p' is no rover \(parameter \?r\)"),
    ],
    ids=["at start", "duration", "simultaneous", "over all", "at end", "goal", "unknown", "type"],
)
def test_invalid_plans_name_the_step_the_time_and_the_condition(plan: str, reason: str) -> None:
    result = check(plan)
    assert not result.valid
    assert re.search(reason, result.reason), result.reason


def test_independent_happenings_may_coincide() -> None:
    assert check("0: (recharge r) [2.5]\n0: (recharge s) [2.5]\n2.6: (move r p q) [4]\n2.6: (drain s) [1]").valid


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "0: (a) [1]\n1 (b) [1]",
            r"^plan\.txt:2: error: expected 'START: \(action arg \.\.\.\) \[DURATION\]', found '1 \(b\) \[1\]'$",
        ),
        ("; a comment\n\n0: () [1]", r"^plan\.txt:3: error: expected an action name in '\(\)'$"),
        ("0: (a) [-1]", r"^plan\.txt:1: error: expected 'START"),
    ],
)
def test_a_plan_file_that_does_not_parse_names_its_line(text: str, message: str) -> None:
    with pytest.raises(TemporalPlanError, match=message):
        parse_temporal_plan(text, "plan.txt")
