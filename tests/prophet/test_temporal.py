"""Temporal planning: durative actions compiled to a sequential task, planned, deordered and scheduled."""

from __future__ import annotations

import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.errors import PlannerError
from alica.prophet.ground import ground
from alica.prophet.pddl import And, parse_domain, parse_problem
from alica.prophet.planner import PlanStatus, PlanStep
from alica.prophet.search.planner import BuiltinPlanner
from alica.prophet.temporal import schedule, sequential_task
from alica.prophet.validate import validate_plan
from alica.prophet.validate_temporal import validate_temporal_plan
from tests.prophet.pddl.test_durative import DOMAIN

APART = """(define (problem apart) (:domain rovers-t)
  (:objects r s - rover p q x y - place)
  (:init (at r p) (at s y) (path p q) (path y x) (= (travel p q) 4) (= (travel y x) 3))
  (:goal (and (visited q) (visited x)))
  (:metric minimize (total-time)))
"""
"""Each rover has a place of its own to reach."""

TWO_ROVERS = """(define (problem two) (:domain rovers-t)
  (:objects r s - rover p q x - place)
  (:init (at r p) (at s p) (path p q) (path p x) (path q x) (path x q) (= (travel p q) 4) (= (travel p x) 3)
         (= (travel q x) 2) (= (travel x q) 2))
  (:goal (and (visited q) (visited x)))
  (:metric minimize (total-time)))
"""


def test_two_rovers_drive_at_once_and_the_schedule_is_valid() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(APART, domain=domain)
    sequential = BuiltinPlanner().solve(*sequential_task(domain, problem), time_limit=30)
    assert sequential.status is PlanStatus.SOLVED and sequential.plan is not None
    done = schedule(domain, problem, sequential.plan.steps)
    result = validate_temporal_plan(domain, problem, done.plan)
    assert result.valid, result.reason
    assert done.plan.makespan == pytest.approx(6.501) and done.sequential_makespan == pytest.approx(12.003)
    starts = {str(t.step): t.start for t in done.plan.steps}
    assert starts["(recharge r)"] == starts["(recharge s)"] == 0.0  # independent: both at once
    for j, before in enumerate(done.after):  # a step starts after the end of each step it follows
        for i in before:
            assert done.plan.steps[j].start >= done.plan.steps[i].end


def test_the_sequential_task_costs_the_durations_in_thousandths() -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS, domain=domain)
    steps = [PlanStep("recharge", ("r",)), PlanStep("move", ("r", "p", "q")), PlanStep("move", ("r", "q", "x"))]
    result = validate_plan(sequential_task(domain, problem), steps)
    assert result.valid and result.cost == 2500 + 4000 + 2000


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (
            "(:durative-action a :parameters () :duration (= ?duration 1) :condition (over all (p)) :effect (at start (not (p))))",
            r"durative action a: its over all condition \(p\) is broken by its own start effects",
        ),
        (
            "(:durative-action a :parameters () :duration (= ?duration 1) :effect (at end (forall (?x) (p))))",
            r"durative action a: the temporal planner takes effects that are conjunctions of literals, not forall effects",
        ),
    ],
)
def test_actions_the_compilation_cannot_take_are_refused_by_name(action: str, message: str) -> None:
    domain = parse_domain(f"(define (domain d) (:requirements :durative-actions) (:predicates (p))\n{action})")
    problem = parse_problem("(define (problem e) (:domain d) (:init) (:goal (p)))", domain=domain)
    with pytest.raises(PlannerError, match=message):
        sequential_task(domain, problem)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6), st.integers(1, 14))
def test_any_valid_sequential_plan_schedules_to_a_valid_temporal_plan(seed: int, length: int) -> None:
    domain = parse_domain(DOMAIN)
    problem = parse_problem(TWO_ROVERS.replace("(:goal (and (visited q) (visited x)))", "(:goal (and))"), domain=domain)
    assert problem.goal == And(())
    task = ground(*sequential_task(domain, problem))
    rng = random.Random(seed)
    state, steps = task.init, []
    for _ in range(length):  # a random walk: a valid sequential plan
        ops = [op for op in task.operators if task.applicable(state, op)]
        if not ops:
            break
        op = rng.choice(ops)
        state = task.apply(state, op)
        steps.append(PlanStep(op.action, tuple(op.args)))
    done = schedule(domain, problem, steps)
    result = validate_temporal_plan(domain, problem, done.plan)
    assert result.valid, f"{result.reason}\n{done.plan}"
    assert done.plan.makespan <= done.sequential_makespan + 1e-9
