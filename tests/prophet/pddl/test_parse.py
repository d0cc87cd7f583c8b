"""Reading the shipped benchmarks, writing them back, and error messages with FILE:LINE:COL."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.prophet.pddl import (
    PddlError,
    parse_domain,
    parse_problem,
    read_domain,
    read_problem,
    write_domain,
    write_problem,
)
from alica.prophet.planner import Feature
from tests.conftest import benchmark_set


def benchmark_sets() -> list[tuple[Path, list[Path]]]:
    """Every benchmark folder with its problem files; fails loudly when the folder is missing."""
    out = []
    for folder in sorted(p for p in benchmark_set("pddl").iterdir() if p.is_dir()):
        problems = sorted(p for p in folder.glob("*.pddl") if p.name != "domain.pddl")
        out.append((folder / "domain.pddl", problems))
    assert len(out) == 2 and sum(len(p) for _, p in out) == 75
    return out


def test_every_benchmark_parses_and_round_trips() -> None:
    # (how fast: bench/planners.py and bench/planning_limits.py; no wall-clock assertions in tests)
    parsed = []
    for domain_path, problems in benchmark_sets():
        domain = read_domain(domain_path)
        parsed.append((domain, [read_problem(p, domain) for p in problems]))
    for domain, problems in parsed:
        assert parse_domain(write_domain(domain)) == domain
        for problem in problems:
            assert parse_problem(write_problem(problem), domain=domain) == problem


def test_model_of_blocks_and_rovers() -> None:
    (blocks_path, blocks), (rovers_path, rovers) = benchmark_sets()
    blocks_domain = read_domain(blocks_path)
    assert blocks_domain.name == "blocks"
    assert [a.name for a in blocks_domain.actions] == ["pick-up", "put-down", "stack", "unstack"]
    assert blocks_domain.requirements == frozenset({Feature.STRIPS})
    problem = read_problem(blocks[blocks.index(blocks_path.parent / "probBLOCKS-4-0.pddl")], blocks_domain)
    assert problem.objects == (("d", "object"), ("b", "object"), ("a", "object"), ("c", "object"))
    rovers_domain = read_domain(rovers_path)
    assert rovers_domain.requirements == frozenset({Feature.STRIPS, Feature.TYPING})
    assert rovers_domain.types["rover"] == ("object",)
    p01 = read_problem(rovers[0], rovers_domain)
    assert ("rover0", "rover") in p01.objects  # upper case in the file


BROKEN = [
    (
        "missing paren at the end",
        "(define (domain d)\n  (:predicates (p ?x))",
        r"d\.pddl:2:23: error: expected '\)' to close '\(define' opened at 1:1",
    ),
    (
        "missing paren in an action",
        "(define (domain d)\n  (:predicates (p ?x))\n  (:action pick-up :parameters (?x)\n    :precondition (p ?x) :effect (not (p ?x))\n  (:action b :parameters ()))",
        r"d\.pddl:5:3: error: expected '\)' to close '\(:action pick-up' opened at 3:3",
    ),
    ("extra paren", "(define (domain d)))", r"d\.pddl:1:20: error: unexpected '\)'"),
    (
        "unknown predicate",
        "(define (domain d) (:predicates (p ?x))\n (:action a :parameters (?x) :precondition (q ?x)))",
        r"d\.pddl:2:45: error: undefined predicate 'q'",
    ),
    (
        "wrong arity",
        "(define (domain d) (:predicates (p ?x))\n (:action a :parameters (?x) :effect (p ?x ?x)))",
        r"d\.pddl:2:38: error: wrong number of arguments for 'p': expected 1, found 2",
    ),
    (
        "unknown type",
        "(define (domain d) (:types a)\n (:predicates (p ?x - b)))",
        r"d\.pddl:2:23: error: unknown type 'b'",
    ),
    (
        "unsupported requirement",
        "(define (domain d)\n (:requirements :strips :fluents))",
        r"d\.pddl:2:25: error: unsupported requirement ':fluents'",
    ),
    (
        "unknown requirement",
        "(define (domain d) (:requirements :teleport))",
        r"d\.pddl:1:35: error: unknown requirement ':teleport'",
    ),
    (
        "undefined variable",
        "(define (domain d) (:predicates (p ?x))\n (:action a :parameters (?x) :precondition (p ?y)))",
        r"d\.pddl:2:47: error: undefined variable '\?y'",
    ),
    (
        "undeclared derived predicate",
        "(define (domain d) (:derived (p) (q)))",
        r"d\.pddl:1:31: error: undefined derived predicate 'p'",
    ),
    (
        "numeric effect",
        "(define (domain d) (:functions (f)) (:action a :parameters () :effect (assign (f) 1)))",
        r"d\.pddl:1:71: error: unsupported construct: numeric effect",
    ),
    (
        "bad number in a cost",
        "(define (domain d) (:requirements :action-costs) (:functions (total-cost))\n (:action a :parameters () :effect (increase (total-cost) 1x)))",
        r"d\.pddl:2:59: error: bad number '1x' for the cost",
    ),
    ("not a domain", "(define (problem p))", r"d\.pddl:1:9: error: expected '\(domain NAME\)' after 'define'"),
    ("empty", "  ; nothing\n", r"d\.pddl:2:1: error: expected '\(define \.\.\.\)'"),
]


@pytest.mark.parametrize(("case", "text", "message"), BROKEN, ids=[b[0] for b in BROKEN])
def test_broken_domains_name_the_place(case: str, text: str, message: str) -> None:
    with pytest.raises(PddlError, match=message):
        parse_domain(text, "d.pddl")


DOMAIN = "(define (domain d) (:requirements :typing :action-costs) (:types block) (:predicates (p ?x - block))\n (:functions (total-cost) - number))"

BROKEN_PROBLEMS = [
    (
        "unknown object",
        "(define (problem x) (:domain d) (:objects a - block)\n (:init (p b)) (:goal (p a)))",
        r"p\.pddl:2:12: error: undefined object or constant 'b'",
    ),
    (
        "bad number in init",
        "(define (problem x) (:domain d) (:init (= (total-cost) zero)) (:goal (and)))",
        r"p\.pddl:1:56: error: bad number 'zero'",
    ),
    (
        "wrong domain",
        "(define (problem x) (:domain e) (:goal (and)))",
        r"p\.pddl:1:30: error: problem is for domain 'e', not 'd'",
    ),
    (
        "unknown object type",
        "(define (problem x) (:domain d) (:objects a - ball) (:goal (and)))",
        r"p\.pddl:1:47: error: unknown type 'ball'",
    ),
    ("no goal", "(define (problem x) (:domain d))", r"p\.pddl:1:1: error: expected a '\(:goal \.\.\.\)' section"),
    (
        "negative init",
        "(define (problem x) (:domain d) (:objects a - block) (:init (not (p a))) (:goal (p a)))",
        r"p\.pddl:1:61: error: unsupported construct '\(not",
    ),
]


@pytest.mark.parametrize(("case", "text", "message"), BROKEN_PROBLEMS, ids=[b[0] for b in BROKEN_PROBLEMS])
def test_broken_problems_name_the_place(case: str, text: str, message: str) -> None:
    domain = parse_domain(DOMAIN)
    with pytest.raises(PddlError, match=message):
        parse_problem(text, "p.pddl", domain)


def test_pddl_error_is_a_planner_and_value_error() -> None:
    from alica.errors import AlicaError, PlannerError

    with pytest.raises(PddlError) as caught:
        parse_domain("(", "x.pddl")
    assert isinstance(caught.value, PlannerError | ValueError | AlicaError)
    assert str(caught.value).startswith("x.pddl:1:2: error:")


def test_missing_file_is_a_pddl_error(tmp_path: Path) -> None:
    with pytest.raises(PddlError, match="cannot read"):
        read_domain(tmp_path / "nope.pddl")


def test_adl_features_parse_and_round_trip() -> None:
    text = """
    (define (domain adl) (:requirements :adl :action-costs)
      (:types ball room - object)
      (:constants home - room)
      (:predicates (at ?b - ball ?r - room) (free) (road ?a ?b - room))
      (:functions (total-cost) - number (dist ?a ?b - room) - number)
      (:action move :parameters (?a ?b - room)
        :precondition (and (road ?a ?b) (not (= ?a ?b)) (or (free) (exists (?x - ball) (at ?x ?a)))
                           (forall (?y - ball) (imply (at ?y ?b) (free))))
        :effect (and (forall (?x - ball) (when (at ?x ?a) (and (not (at ?x ?a)) (at ?x ?b))))
                     (increase (total-cost) (dist ?a ?b)))))"""
    domain = parse_domain(text)
    assert Feature.CONDITIONAL_EFFECTS in domain.requirements and Feature.ACTION_COSTS in domain.requirements
    assert "disjunctive-preconditions" in domain.extra_requirements
    assert parse_domain(write_domain(domain)) == domain
    assert domain.actions[0].cost is not None
