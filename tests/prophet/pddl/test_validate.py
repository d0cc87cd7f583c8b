"""The plan validator, lifted and ground, on blocks 4-0 and a cost domain."""

from __future__ import annotations

import pytest

from alica.prophet.ground import ground
from alica.prophet.pddl import parse_domain, parse_problem, read_domain, read_problem
from alica.prophet.planner import Plan, PlanStep
from alica.prophet.validate import validate_plan
from tests.conftest import benchmark_set

GOOD = [
    ("pick-up", "b"),
    ("stack", "b", "a"),
    ("pick-up", "c"),
    ("stack", "c", "b"),
    ("pick-up", "d"),
    ("stack", "d", "c"),
]


@pytest.fixture
def blocks() -> tuple:
    blocks = benchmark_set("pddl") / "blocks"
    domain = read_domain(blocks / "domain.pddl")
    return domain, read_problem(blocks / "probBLOCKS-4-0.pddl", domain)


def _steps(raw: list[tuple[str, ...]]) -> list[PlanStep]:
    return [PlanStep(a, tuple(args)) for a, *args in raw]


@pytest.mark.parametrize("lifted", [True, False])
def test_known_plan_accepted(blocks: tuple, lifted: bool) -> None:
    task = blocks if lifted else ground(*blocks)
    result = validate_plan(task, Plan(tuple(_steps(GOOD)), 6))
    assert result.valid and result.cost == 6 and result.failed_step is None and result.reason == ""


@pytest.mark.parametrize("lifted", [True, False])
def test_wrong_plan_rejected_with_step_and_literal(blocks: tuple, lifted: bool) -> None:
    task = blocks if lifted else ground(*blocks)
    wrong = [("pick-up", "b"), ("stack", "b", "a"), ("stack", "c", "b")]
    result = validate_plan(task, _steps(wrong))
    assert not result.valid and result.failed_step == 3
    assert "step 3 (stack c b)" in result.reason and "(holding c)" in result.reason


@pytest.mark.parametrize("lifted", [True, False])
def test_goal_not_reached(blocks: tuple, lifted: bool) -> None:
    task = blocks if lifted else ground(*blocks)
    result = validate_plan(task, _steps(GOOD[:2]))
    assert (
        not result.valid
        and result.failed_step is None
        and result.reason.startswith("goal (on ")
        and "does not hold" in result.reason
    )


def test_lifted_checks_names_and_types() -> None:
    domain = parse_domain(
        "(define (domain t) (:types a b) (:predicates (p ?x - a)) (:action go :parameters (?x - a) :effect (p ?x)))"
    )
    problem = parse_problem(
        "(define (problem q) (:domain t) (:objects x - a y - b) (:init) (:goal (p x)))", domain=domain
    )
    assert "unknown action" in validate_plan((domain, problem), [PlanStep("fly", ("x",))]).reason
    assert "'y' is no a" in validate_plan((domain, problem), [PlanStep("go", ("y",))]).reason
    assert "unknown object 'z'" in validate_plan((domain, problem), [PlanStep("go", ("z",))]).reason
    assert validate_plan((domain, problem), [PlanStep("go", ("x",))]).valid


def test_costs_summed() -> None:
    domain = parse_domain("""(define (domain roads) (:requirements :action-costs)
      (:predicates (at ?p) (road ?a ?b)) (:functions (total-cost) (length ?a ?b))
      (:action drive :parameters (?a ?b) :precondition (and (at ?a) (road ?a ?b))
        :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (length ?a ?b)))))""")
    problem = parse_problem(
        "(define (problem r) (:domain roads) (:objects x y z) (:init (at x) (road x y) (road y z) (= (length x y) 2) (= (length y z) 5)) (:goal (at z)))",
        domain=domain,
    )
    plan = [PlanStep("drive", ("x", "y")), PlanStep("drive", ("y", "z"))]
    assert validate_plan((domain, problem), plan).cost == 7
    assert validate_plan(ground(domain, problem), plan).cost == 7
