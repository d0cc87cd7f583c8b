"""Grounding: counts on blocks, negative preconditions, conditional effects, costs, unsolvable goals, speed."""

from __future__ import annotations

import pytest

from alica.prophet.ground import GroundTask, ground
from alica.prophet.pddl import PddlError, parse_domain, parse_problem, read_domain, read_problem
from tests.conftest import benchmark_set


def _task(domain_text: str, problem_text: str) -> GroundTask:
    domain = parse_domain(domain_text)
    return ground(domain, parse_problem(problem_text, domain=domain))


def test_blocks_4_counts() -> None:
    blocks = benchmark_set("pddl") / "blocks"
    domain = read_domain(blocks / "domain.pddl")
    task = ground(domain, read_problem(blocks / "probBLOCKS-4-0.pddl", domain))
    assert len(domain.actions) == 4
    # 4 pick-up + 4 put-down + 16 stack + 16 unstack (stack a a is relaxed-reachable)
    assert len(task.operators) == 40
    # 16 on + 4 ontable + 4 clear + 4 holding + handempty
    assert len(task.facts) == 29
    assert [task.facts[g] for g in task.goal] == ["(on b a)", "(on c b)", "(on d c)"]
    assert task.unsolvable_reason is None and not task.has_costs
    op = task.operator("(pick-up a)")[0]
    assert [task.facts[i] for i in op.pre] == ["(clear a)", "(handempty)", "(ontable a)"]
    assert op.cost == 1 and op.args == ("a",) and op.action == "pick-up"
    assert task.fact_id("(ON a  B)") == task.facts.index("(on a b)")


def test_rovers_static_facts_leave_preconditions() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    domain = read_domain(rovers / "domain.pddl")
    task = ground(domain, read_problem(rovers / "p01.pddl", domain))
    assert not any("visible" in f or "can_traverse" in f for f in task.facts)
    nav = task.operator("(navigate rover0 waypoint3 waypoint0)")[0]
    assert sorted(task.facts[p] for p in nav.pre) == ["(at rover0 waypoint3)", "(available rover0)"]
    # channel_free is deleted and added: the add wins
    comm = next(op for op in task.operators if op.action == "communicate_soil_data")
    assert (
        task.fact_id("(channel_free general)") in comm.add and task.fact_id("(channel_free general)") not in comm.delete
    )


@pytest.mark.parametrize("names", [[f"p{i:02d}" for i in range(1, 21)], ["p30", "p40"]])
def test_rovers_ground(names: list[str]) -> None:
    # (how fast: bench/planners.py's grounding table; no wall-clock assertions in tests)
    rovers = benchmark_set("pddl") / "rovers"
    domain = read_domain(rovers / "domain.pddl")
    for name in names:
        problem = read_problem(rovers / f"{name}.pddl", domain)
        task = ground(domain, problem)
        assert task.unsolvable_reason is None and task.operators


NEG = """(define (domain neg) (:requirements :negative-preconditions :equality)
  (:predicates (lit ?x) (p ?x ?y))
  (:action light :parameters (?x) :precondition (not (lit ?x)) :effect (lit ?x))
  (:action link :parameters (?x ?y) :precondition (and (lit ?x) (not (= ?x ?y)) (not (p ?x ?y))) :effect (p ?x ?y)))"""


def test_negative_preconditions_compiled() -> None:
    task = _task(
        NEG,
        "(define (problem q) (:domain neg) (:objects a b) (:init (lit b)) (:goal (and (p a b) (not (lit c)))))".replace(
            " (not (lit c))", ""
        ),
    )
    light_a = task.operator("(light a)")[0]
    assert [task.facts[i] for i in light_a.pre] == ["(not-lit a)"]
    assert [task.facts[i] for i in light_a.add] == ["(lit a)"]
    assert [task.facts[i] for i in light_a.delete] == ["(not-lit a)"]
    assert task.fact_id("(not-lit a)") in task.init and task.fact_id("(lit b)") in task.init
    assert task.operator("(light b)") == [] or task.fact_id("(not-lit b)") not in task.init
    assert task.operator("(link a a)") == []  # equality resolved
    state = task.init
    for name in ("(light a)", "(link a b)"):
        op = task.operator(name)[0]
        assert task.applicable(state, op)
        state = task.apply(state, op)
    assert task.is_goal(state)


def test_negated_goal() -> None:
    task = _task(NEG, "(define (problem q) (:domain neg) (:objects a) (:init) (:goal (not (lit a))))")
    assert [task.facts[g] for g in task.goal] == ["(not-lit a)"]
    assert task.is_goal(task.init)


COND = """(define (domain cond) (:requirements :conditional-effects :typing)
  (:types ball room)
  (:predicates (at ?b - ball ?r - room) (robot ?r - room))
  (:action move :parameters (?a ?b - room) :precondition (robot ?a)
    :effect (and (not (robot ?a)) (robot ?b)
                 (forall (?x - ball) (when (at ?x ?a) (and (not (at ?x ?a)) (at ?x ?b)))))))"""


def test_conditional_effects_applied() -> None:
    task = _task(
        COND,
        "(define (problem c) (:domain cond) (:objects r1 r2 - room b1 b2 - ball) (:init (robot r1) (at b1 r1) (at b2 r2)) (:goal (and (at b1 r2) (at b2 r2))))",
    )
    op = task.operator("(move r1 r2)")[0]
    assert len(op.conditional) >= 1
    after = task.apply(task.init, op)
    names = sorted(task.facts[i] for i in after)
    assert names == ["(at b1 r2)", "(at b2 r2)", "(robot r2)"]
    assert task.is_goal(after)


COSTS = """(define (domain roads) (:requirements :typing :action-costs)
  (:types place)
  (:predicates (at ?p - place) (road ?a ?b - place))
  (:functions (total-cost) - number (length ?a ?b - place) - number)
  (:action drive :parameters (?a ?b - place) :precondition (and (at ?a) (road ?a ?b))
    :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (length ?a ?b))))
  (:action wait :parameters () :effect (increase (total-cost) 3)))"""


def test_costs_read_from_fluents() -> None:
    task = _task(
        COSTS,
        "(define (problem r) (:domain roads) (:objects x y - place) (:init (at x) (road x y) (= (length x y) 7) (= (total-cost) 0)) (:goal (at y)) (:metric minimize (total-cost)))",
    )
    assert task.has_costs
    assert task.operator("(drive x y)")[0].cost == 7
    assert task.operator("(wait)")[0].cost == 3


def test_missing_cost_value_is_an_error() -> None:
    with pytest.raises(PddlError, match=r"\(length x y\) has no value"):
        _task(
            COSTS,
            "(define (problem r) (:domain roads) (:objects x y - place) (:init (at x) (road x y)) (:goal (at y)))",
        )


def test_unreachable_goal_marked() -> None:
    task = _task(
        COSTS,
        "(define (problem r) (:domain roads) (:objects x y - place) (:init (at x) (road y x) (= (length y x) 1)) (:goal (at y)))",
    )
    assert task.unsolvable_reason is not None and "(at y)" in task.unsolvable_reason


def test_deterministic() -> None:
    rovers = benchmark_set("pddl") / "rovers"
    domain = read_domain(rovers / "domain.pddl")
    problem = read_problem(rovers / "p05.pddl", domain)
    assert ground(domain, problem) == ground(domain, problem)
