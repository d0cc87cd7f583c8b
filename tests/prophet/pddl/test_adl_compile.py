"""Full ADL conditions compiled into derived predicates (issue 22): small domains, a property test, IPC problems."""

from __future__ import annotations

import json
import time
from contextlib import ExitStack
from unittest import mock

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.prophet.ground import ground
from alica.prophet.pddl import normal, parse_domain, parse_problem, read_domain, read_problem, write_formula
from alica.prophet.pddl.adl import Compiler, nnf
from alica.prophet.pddl.model import And, Atom, Equals, Exists, Forall, Formula, Imply, Not, Or
from alica.prophet.planner import PlanStatus, PlanStep
from alica.prophet.planners import get_planner
from alica.prophet.search.encoding import compile_task
from alica.prophet.validate import LiftedSimulation, validate_plan
from tests.conftest import benchmark_set

# A tiny miconic-fulladl: the lift may stop at a floor only if every boarded passenger with the
# non-stop flag gets off there, and no passenger of a conflicting group is waiting or riding.
LIFT = """(define (domain lift)
  (:requirements :adl)
  (:types passenger floor)
  (:predicates (origin ?p - passenger ?f - floor) (destin ?p - passenger ?f - floor)
               (boarded ?p - passenger) (served ?p - passenger) (lift-at ?f - floor)
               (nonstop ?p - passenger) (conflict-a ?p - passenger) (conflict-b ?p - passenger)
               (above ?f1 ?f2 - floor))
  (:action stop
    :parameters (?f - floor)
    :precondition (and (lift-at ?f)
      (forall (?p - passenger) (imply (nonstop ?p) (imply (boarded ?p) (destin ?p ?f))))
      (imply (exists (?p - passenger) (and (conflict-a ?p)
                                           (or (and (not (served ?p)) (origin ?p ?f))
                                               (and (boarded ?p) (not (destin ?p ?f))))))
             (forall (?q - passenger) (imply (conflict-b ?q)
                                             (and (or (destin ?q ?f) (not (boarded ?q)))
                                                  (or (served ?q) (not (origin ?q ?f))))))))
    :effect (and (forall (?p - passenger) (when (and (boarded ?p) (destin ?p ?f))
                                               (and (not (boarded ?p)) (served ?p))))
                 (forall (?p - passenger) (when (and (origin ?p ?f) (not (served ?p))) (boarded ?p)))))
  (:action up :parameters (?f1 ?f2 - floor) :precondition (and (lift-at ?f1) (above ?f1 ?f2))
    :effect (and (lift-at ?f2) (not (lift-at ?f1))))
  (:action down :parameters (?f1 ?f2 - floor) :precondition (and (lift-at ?f1) (above ?f2 ?f1))
    :effect (and (lift-at ?f2) (not (lift-at ?f1)))))
"""

LIFT_PROBLEM = """(define (problem three) (:domain lift)
  (:objects p1 p2 p3 - passenger f0 f1 f2 - floor)
  (:init (lift-at f0) (above f0 f1) (above f0 f2) (above f1 f2)
         (origin p1 f0) (destin p1 f2) (origin p2 f1) (destin p2 f0) (origin p3 f0) (destin p3 f1)
         (nonstop p1) (conflict-a p2) (conflict-b p3))
  (:goal (forall (?p - passenger) (served ?p))))
"""


def test_quantified_disjunctions_under_forall_become_derived_predicates_and_plan() -> None:
    domain = parse_domain(LIFT, "lift.pddl")
    problem = parse_problem(LIFT_PROBLEM, "three.pddl", domain)
    with mock.patch.object(normal, "MAX_CLAUSES", 2):  # as if multiplying out gave too many conjunctions
        task = ground(domain, problem)
        assert task.axioms and any("new-axiom@" in f for f in task.facts)
        result = get_planner("builtin").solve(domain, problem)
    assert result.status in (PlanStatus.SOLVED, PlanStatus.OPTIMAL) and result.plan is not None
    assert not any("@" in str(s) for s in result.plan.steps)
    assert validate_plan((domain, problem), result.plan).valid
    # p1 rides non-stop to f2: stopping at f1 with p1 aboard breaks the precondition
    bad = [PlanStep("stop", ("f0",)), PlanStep("up", ("f0", "f1")), PlanStep("stop", ("f1",))]
    check = validate_plan((domain, problem), bad)
    assert not check.valid and check.failed_step == 3


def test_a_forall_over_an_or_is_one_negated_new_predicate() -> None:
    compiler = Compiler(lambda kind: ["a", "b", "c"])
    formula = Forall((("?x", "object"),), Or((Atom("red", ("?x",)), Atom("green", ("?x", "?y")))))
    clauses = compiler.clauses(formula, (("?y", "object"),), "test", None, lift=True)
    assert clauses == [((), ((False, Atom("new-axiom@0", ("?y",))),))]
    (rule,) = compiler.rules
    assert rule.predicate == "new-axiom@0" and rule.head == ("?y",)
    assert [(p, a.predicate) for p, a in rule.clause] == [(False, "red"), (False, "green")]
    assert len(rule.parameters) == 2  # ?y and the renamed ?x of the exists


def test_a_large_and_of_ors_gets_a_predicate_per_or() -> None:
    compiler = Compiler(lambda kind: ["a"])
    parts = tuple(Or((Atom(f"p{i}", ()), Atom(f"q{i}", ()))) for i in range(6))  # 64 conjunctions
    clauses = compiler.clauses(And(parts), (), "test", None, lift=True)
    assert len(clauses) == 1 and len(clauses[0][1]) == 6
    assert len(compiler.rules) == 12  # two rules per new predicate


# ----------------------------------------------------------------------- property
OBJECTS = ("a", "b", "c")
BASE = """(define (domain random)
  (:requirements :adl :derived-predicates)
  (:constants a b c)
  (:predicates (p ?x) (q ?x) (r ?x ?y) (d ?x) (e ?x) (done))
  (:derived (d ?x) (or (p ?x) (exists (?y) (and (r ?x ?y) (not (q ?y))))))
  (:derived (e ?x) (forall (?y) (imply (r ?x ?y) (or (q ?y) (not (d ?y))))))
  (:action flip-p :parameters (?x) :precondition (p ?x) :effect (not (p ?x)))
  (:action flip-q :parameters (?x) :precondition (q ?x) :effect (not (q ?x)))
  (:action flip-r :parameters (?x ?y) :precondition (r ?x ?y) :effect (not (r ?x ?y)))
  (:action check :parameters () :precondition {pre} :effect (done)))
"""


@st.composite
def formulas(draw: st.DrawFn, depth: int = 3, scope: tuple[str, ...] = ()) -> Formula:
    terms = st.sampled_from((*scope, *OBJECTS))
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        kind = draw(st.sampled_from(["p", "q", "r", "d", "e", "="]))
        if kind == "=":
            return Equals(draw(terms), draw(terms))
        if kind == "r":
            return Atom("r", (draw(terms), draw(terms)))
        return Atom(kind, (draw(terms),))
    kind = draw(st.sampled_from(["and", "or", "not", "imply", "exists", "forall"]))
    if kind in ("and", "or"):
        parts = tuple(draw(formulas(depth - 1, scope)) for _ in range(draw(st.integers(0, 3))))
        return And(parts) if kind == "and" else Or(parts)
    if kind == "not":
        return Not(draw(formulas(depth - 1, scope)))
    if kind == "imply":
        return Imply(draw(formulas(depth - 1, scope)), draw(formulas(depth - 1, scope)))
    var = f"?v{len(scope)}"
    body = draw(formulas(depth - 1, (*scope, var)))
    return (Exists if kind == "exists" else Forall)(((var, "object"),), body)


STATES = st.tuples(
    st.frozensets(st.sampled_from(OBJECTS)),
    st.frozensets(st.sampled_from(OBJECTS)),
    st.frozensets(st.tuples(st.sampled_from(OBJECTS), st.sampled_from(OBJECTS))),
)


@settings(max_examples=120, deadline=None)
@given(formula=formulas(), state=STATES, cap=st.sampled_from([1, 2, normal.MAX_CLAUSES]))
def test_compiled_conditions_hold_exactly_where_the_formula_holds(formula: Formula, state, cap: int) -> None:  # type: ignore[no-untyped-def]
    """The goal and a precondition, compiled (axioms + DNF), agree with the validator's direct evaluation."""
    ps, qs, rs = state
    init = [f"(p {x})" for x in sorted(ps)] + [f"(q {x})" for x in sorted(qs)]
    init += [f"(r {x} {y})" for x, y in sorted(rs)]
    domain = parse_domain(BASE.format(pre=write_formula(formula)))
    text = write_formula(formula)
    problem = parse_problem(
        f"(define (problem x) (:domain random) (:init {' '.join(init)}) (:goal {text}))",
        domain=domain,
    )
    lifted = LiftedSimulation(domain, problem)
    expected = lifted.holds(formula, lifted.close(set(problem.facts)))
    with ExitStack() as stack:
        stack.enter_context(mock.patch.object(normal, "MAX_CLAUSES", cap))
        task = ground(domain, problem)
    ct = compile_task(task)
    goal_holds = task.unsolvable_reason is None and task.is_goal(task.init)
    assert goal_holds == expected, nnf(formula)
    assert (task.unsolvable_reason is None and ct.is_goal(ct.init)) == expected
    assert any(task.applicable(task.init, op) for op in task.operator("(check)")) == expected


# ------------------------------------------------------------------ IPC problems
CASES = [
    ("miconic-fulladl", "f1-0.pddl"),
    ("psr-middle", "p01-s17-n2-l2-f30.pddl"),
    ("optical-telegraphs", "p01-opt2.pddl"),
    ("airport-adl", "p01-airport1-p1.pddl"),
    ("assembly", "prob01.pddl"),
]


@pytest.mark.parametrize(("folder", "name"), CASES, ids=[c[0] for c in CASES])
def test_alica_plan_solves_the_adl_benchmarks(folder: str, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    ipc = benchmark_set("ipc")
    domain_path, problem_path = ipc / folder / "domain.pddl", ipc / folder / name
    started = time.monotonic()
    code = main(["plan", str(domain_path), str(problem_path), "--json", "--time-limit", "20"])
    answer = json.loads(capsys.readouterr().out)
    assert code == 0 and answer["solved"] is True, answer
    assert time.monotonic() - started < 20
    domain = read_domain(domain_path)
    problem = read_problem(problem_path, domain)
    steps = [PlanStep(s.strip("()").split()[0], tuple(s.strip("()").split()[1:])) for s in answer["plan"]]
    result = validate_plan((domain, problem), steps)
    assert result.valid, result.reason
    assert result.cost == answer["cost"]
