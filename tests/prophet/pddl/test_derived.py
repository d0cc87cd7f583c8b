"""Derived predicates (issue 22): reading, refusals with their place, grounding, search, validation, writing."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from alica.app.cli import main
from alica.prophet.ground import GroundTask, ground
from alica.prophet.pddl import Axiom, PddlError, parse_domain, parse_problem, write_domain
from alica.prophet.pddl.model import Atom, Domain, Problem
from alica.prophet.planner import Feature, PlanStatus, PlanStep
from alica.prophet.planners import get_planner
from alica.prophet.search.encoding import compile_task
from alica.prophet.validate import validate_plan

# A robot on a graph of rooms: (reach ?x ?y) is the transitive closure of (door ?x ?y) over open
# doors, (cut-off ?x) holds for a room no longer reachable from the base (a negation over a
# lower stratum), (safe) holds when no room is cut off (a forall over a derived predicate).
ROOMS = """(define (domain rooms)
  (:requirements :strips :typing :derived-predicates :negative-preconditions :universal-preconditions)
  (:types room)
  (:constants base - room)
  (:predicates (door ?x ?y - room) (open ?x ?y - room) (at ?x - room) (visited ?x - room)
               (reach ?x ?y - room) (cut-off ?x - room) (safe))
  (:derived (reach ?x ?y - room) (and (door ?x ?y) (open ?x ?y)))
  (:derived (reach ?x ?y - room) (exists (?z - room) (and (reach ?x ?z) (reach ?z ?y))))
  (:derived (cut-off ?x - room) (and (not (= ?x base)) (not (reach base ?x))))
  (:derived (safe) (forall (?x - room) (not (cut-off ?x))))
  (:action go
    :parameters (?x ?y - room)
    :precondition (and (at ?x) (reach ?x ?y))
    :effect (and (not (at ?x)) (at ?y) (visited ?y)))
  (:action close
    :parameters (?x ?y - room)
    :precondition (and (open ?x ?y) (at ?y) (not (cut-off ?x)))
    :effect (not (open ?x ?y)))
  (:action reopen
    :parameters (?x ?y - room)
    :precondition (and (door ?x ?y) (not (open ?x ?y)) (at ?x))
    :effect (open ?x ?y)))
"""

ROOMS_PROBLEM = """(define (problem three) (:domain rooms)
  (:objects a b c - room)
  (:init (door base a) (door a b) (door b c) (open base a) (open a b) (at base))
  (:goal (and (visited c) (safe))))
"""


def _rooms() -> tuple[Domain, Problem]:
    domain = parse_domain(ROOMS, "rooms.pddl")
    return domain, parse_problem(ROOMS_PROBLEM, "three.pddl", domain)


def test_derived_rules_are_read_with_their_place() -> None:
    domain, _ = _rooms()
    assert [a.predicate for a in domain.axioms] == ["reach", "reach", "cut-off", "safe"]
    assert domain.derived == {"reach", "cut-off", "safe"}
    assert Feature.DERIVED_PREDICATES in domain.requirements
    first = domain.axioms[0]
    assert isinstance(first, Axiom) and first.parameters == (("?x", "room"), ("?y", "room"))
    assert first.head == Atom("reach", ("?x", "?y"))
    assert first.span is not None and first.span.line == 7


def test_the_writer_writes_the_rules_back() -> None:
    domain, _ = _rooms()
    text = write_domain(domain)
    assert "(:derived (reach ?x ?y - room)" in text
    assert parse_domain(text) == domain


def test_grounding_keeps_axioms_apart_and_the_initial_state_holds_the_derived_facts() -> None:
    domain, problem = _rooms()
    task = ground(domain, problem)
    assert task.axioms and task.derived
    names = {task.facts[i] for i in task.init}
    assert {"(reach base a)", "(reach a b)", "(reach base b)"} <= names  # recursion: base -> a -> b
    assert "(reach base c)" not in names and "(cut-off c)" in names and "(safe)" not in names
    assert not any("@" in op.name for op in task.operators)
    assert all(task.facts[a.head] in task.facts for a in task.axioms)
    assert all(a.layer >= 0 for a in task.axioms)


def test_a_plan_needs_the_derived_goal_and_passes_the_validator() -> None:
    domain, problem = _rooms()
    result = get_planner("builtin").solve(domain, problem)
    assert result.status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL)
    plan = result.plan
    assert plan is not None
    steps = [str(s) for s in plan.steps]
    assert "(reopen b c)" in steps and "(go b c)" in steps
    assert not any("@" in s for s in steps)
    assert validate_plan((domain, problem), plan).valid
    assert validate_plan(ground(domain, problem), plan).valid


def test_the_validator_rejects_a_plan_that_breaks_a_derived_precondition() -> None:
    domain, problem = _rooms()
    bad = [PlanStep("go", ("base", "c"))]  # c is not reachable yet
    result = validate_plan((domain, problem), bad)
    assert not result.valid and result.failed_step == 1
    assert "step 1 (go base c)" in result.reason and "(reach base c)" in result.reason
    closing = [
        PlanStep("go", ("base", "a")),
        PlanStep("go", ("a", "b")),
        PlanStep("reopen", ("b", "c")),
        PlanStep("go", ("b", "c")),
        PlanStep("close", ("b", "c")),
    ]
    # closing the door behind leaves (cut-off c): the goal (safe) fails though c is visited
    result = validate_plan((domain, problem), closing)
    assert not result.valid and result.failed_step is None and "(safe)" in result.reason
    assert not validate_plan(ground(domain, problem), closing).valid


def test_compiled_states_recompute_derived_facts_after_each_step() -> None:
    domain, problem = _rooms()
    task = ground(domain, problem)
    ct = compile_task(task)
    reach_ac = task.fact_id("(reach base c)")
    assert not ct.init >> reach_ac & 1
    state = ct.init
    for name in ("(go base a)", "(go a b)", "(reopen b c)"):
        op = next(o for o in ct.applicable(state) if task.operators[ct.source[o]].name == name)
        state = ct.successor(state, op)
    assert state >> reach_ac & 1  # the door b-c is open again: base reaches c
    assert state >> task.fact_id("(safe)") & 1


NEGATED = """(define (domain strata)
  (:requirements :strips :derived-predicates :negative-preconditions)
  (:predicates (p ?x) (q ?x) (r ?x) (done ?x))
  (:derived (q ?x) (p ?x))
  (:derived (r ?x) (not (q ?x)))
  (:action mark
    :parameters (?x)
    :precondition (and (r ?x) (not (q ?x)))
    :effect (done ?x))
  (:action set
    :parameters (?x)
    :precondition (not (p ?x))
    :effect (p ?x)))
"""


def test_negated_derived_preconditions_over_strata() -> None:
    domain = parse_domain(NEGATED)
    problem = parse_problem(
        "(define (problem s) (:domain strata) (:objects a b) (:init (p a)) (:goal (and (done b) (p b))))",
        domain=domain,
    )
    task = ground(domain, problem)
    layers = {task.facts[a.head].split()[0][1:]: a.layer for a in task.axioms}
    assert layers["q"] < layers["r"]
    result = get_planner("builtin").solve(domain, problem)
    assert result.plan is not None
    assert [str(s) for s in result.plan.steps] == ["(mark b)", "(set b)"]
    assert validate_plan((domain, problem), result.plan).valid
    wrong = [PlanStep("set", ("b",)), PlanStep("mark", ("b",))]
    result_wrong = validate_plan((domain, problem), wrong)
    assert not result_wrong.valid and result_wrong.failed_step == 2


def test_a_disjunctive_and_existential_goal_is_a_derived_goal() -> None:
    domain = parse_domain(
        """(define (domain lamps) (:requirements :adl)
  (:predicates (on ?x) (broken ?x))
  (:action switch :parameters (?x) :precondition (not (broken ?x)) :effect (on ?x)))"""
    )
    problem = parse_problem(
        """(define (problem p) (:domain lamps) (:objects a b c) (:init (broken a) (broken b))
  (:goal (or (and (on a) (on b)) (exists (?x) (and (on ?x) (not (broken ?x)))))))""",
        domain=domain,
    )
    task = ground(domain, problem)
    assert [task.facts[g] for g in task.goal] == ["(goal@)"]
    result = get_planner("builtin").solve(domain, problem)
    assert result.plan is not None and [str(s) for s in result.plan.steps] == ["(switch c)"]
    assert validate_plan((domain, problem), result.plan).valid
    assert not validate_plan((domain, problem), []).valid


def _error(domain_text: str, problem_text: str | None = None) -> str:
    with pytest.raises(PddlError) as info:
        domain = parse_domain(domain_text, "d.pddl")
        if problem_text is not None:
            ground(domain, parse_problem(problem_text, "p.pddl", domain))
    return str(info.value)


def test_a_derived_predicate_in_an_effect_is_refused_at_its_place() -> None:
    text = """(define (domain d) (:requirements :derived-predicates)
  (:predicates (p) (q))
  (:derived (q) (p))
  (:action a :parameters () :precondition (p)
    :effect (and (not (p)) (q))))"""
    message = _error(text)
    assert message.startswith("d.pddl:5:28: error: derived predicate 'q' in an action effect")


def test_a_derived_predicate_in_the_init_is_refused_at_its_place() -> None:
    domain = parse_domain("(define (domain d) (:predicates (p) (q)) (:derived (q) (p)))")
    with pytest.raises(PddlError, match=r"p\.pddl:2:14: error: derived predicate 'q' in :init"):
        parse_problem("(define (problem x) (:domain d)\n  (:init (p) (q)) (:goal (q)))", "p.pddl", domain)


def test_an_undeclared_derived_predicate_is_refused_at_its_place() -> None:
    message = _error("(define (domain d)\n  (:predicates (p))\n  (:derived (q ?x) (p)))")
    assert message.startswith("d.pddl:3:14: error: undefined derived predicate 'q'")


def test_a_derived_rule_of_the_wrong_arity_is_refused() -> None:
    message = _error("(define (domain d)\n  (:predicates (p) (q ?x))\n  (:derived (q) (p)))")
    assert message.startswith("d.pddl:3:13: error: wrong number of arguments for 'q'")


def test_non_stratifiable_negation_is_refused_naming_the_predicates_and_the_rule() -> None:
    text = """(define (domain d) (:requirements :derived-predicates :negative-preconditions)
  (:predicates (p ?x) (q ?x) (s ?x) (goal-reached))
  (:derived (p ?x) (and (s ?x) (not (q ?x))))
  (:derived (q ?x) (p ?x))
  (:action a :parameters (?x) :precondition (p ?x) :effect (s ?x)))"""
    message = _error(text, "(define (problem x) (:domain d) (:objects o) (:init (s o)) (:goal (p o)))")
    assert message.startswith("d.pddl:3:3: error: unsupported construct: the derived predicates 'p', 'q'")
    assert "not stratifiable" in message


def test_a_domain_without_derived_predicates_compiles_to_the_plain_task() -> None:
    domain = parse_domain(
        "(define (domain d) (:predicates (p) (q)) (:action a :parameters () :precondition (p) :effect (q)))"
    )
    task = ground(domain, parse_problem("(define (problem x) (:domain d) (:init (p)) (:goal (q)))", domain=domain))
    assert isinstance(task, GroundTask) and not task.axioms and not task.derived
    assert type(compile_task(task)).__name__ == "CompiledTask"


def test_alica_plan_json_prints_a_derived_refusal_with_its_place(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    domain = tmp_path / "d.pddl"
    domain.write_text(
        "(define (domain d) (:requirements :derived-predicates)\n  (:predicates (p) (q))\n  (:derived (q) (p))\n"
        "  (:action a :parameters () :precondition (p) :effect (q)))\n",
        encoding="utf-8",
    )
    problem = tmp_path / "p.pddl"
    problem.write_text("(define (problem x) (:domain d) (:init (p)) (:goal (q)))\n", encoding="utf-8")
    code = main(["plan", str(domain), str(problem), "--json"])
    answer = json.loads(capsys.readouterr().out)
    assert code == 1 and answer["solved"] is False
    assert answer["error"].startswith(f"{domain}:4:55: error: derived predicate 'q' in an action effect")


def test_derived_facts_over_static_facts_only_are_compiled_away() -> None:
    domain = parse_domain(
        """(define (domain links) (:requirements :strips :derived-predicates)
  (:predicates (link ?x ?y) (linked ?x ?y) (at ?x) (seen ?x))
  (:derived (linked ?x ?y) (link ?x ?y))
  (:derived (linked ?x ?y) (exists (?z) (and (link ?x ?z) (linked ?z ?y))))
  (:action go :parameters (?x ?y) :precondition (and (at ?x) (linked ?x ?y))
    :effect (and (not (at ?x)) (at ?y) (seen ?y))))"""
    )
    problem = parse_problem(
        "(define (problem p) (:domain links) (:objects a b c d) (:init (link a b) (link b c) (at a))"
        " (:goal (and (seen c) (linked a c))))",
        domain=domain,
    )
    task = ground(domain, problem)
    ct = compile_task(task)
    assert task.axioms and not getattr(ct, "axioms", None)  # (linked ...) never changes
    assert all(task.fact_id("(linked a c)") not in pre for pre in ct.pre)
    result = get_planner("builtin").solve(domain, problem)
    assert result.plan is not None and [str(s) for s in result.plan.steps] == ["(go a c)"]
    assert validate_plan((domain, problem), result.plan).valid
    unreachable = parse_problem(
        "(define (problem q) (:domain links) (:objects a b c d) (:init (link a b) (at a)) (:goal (linked a d)))",
        domain=domain,
    )
    assert get_planner("builtin").solve(domain, unreachable).status is PlanStatus.UNSOLVABLE


@pytest.mark.parametrize(
    "rule",
    [
        "(or (start ?x) (exists (?y) (and (linked ?y) (edge ?y ?x))))",
        # the recursive atom under a quantifier that rebinds the head's ?x: it is not the head's ?x
        "(or (start ?x) (exists (?z) (and (edge ?z ?x) (exists (?x) (and (= ?x ?z) (linked ?x))))))",
    ],
)
@pytest.mark.parametrize("broken", [False, True])
def test_the_validator_closes_a_long_recursive_chain(rule: str, broken: bool) -> None:
    """Objects in reverse order: each pass over the rule's bindings links one more node."""
    domain = parse_domain(
        "(define (domain chain) (:requirements :adl :derived-predicates)"
        " (:predicates (start ?x) (edge ?x ?y) (linked ?x))"
        f" (:derived (linked ?x) {rule}))"
    )
    names = " ".join(f"n{i}" for i in reversed(range(12)))
    edges = " ".join(f"(edge n{i} n{i + 1})" for i in range(11) if not (broken and i == 7))
    problem = parse_problem(
        f"(define (problem p) (:domain chain) (:objects {names}) (:init (start n0) {edges})"
        " (:goal (forall (?x) (linked ?x))))",
        domain=domain,
    )
    result = validate_plan((domain, problem), [])
    assert result.valid is not broken
    task = ground(domain, problem)
    linked = {task.facts[f] for f in task.init if task.facts[f].startswith("(linked")}
    assert len(linked) == (8 if broken else 12)  # the grounder's axioms agree
