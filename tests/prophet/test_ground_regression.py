"""Grounding results pinned: fact and operator counts and a digest of the whole task.

The digests were taken before the grounding was made faster, so a change in
what the grounding produces (ids, order, operators, effects) shows up here.
"""

from __future__ import annotations

import hashlib

import pytest

from alica.prophet.ground import GroundTask, ground
from alica.prophet.pddl import parse_domain, parse_problem, read_domain, read_problem
from tests.conftest import benchmark_set

MIXED = """(define (domain mixed) (:requirements :typing :negative-preconditions :equality :conditional-effects)
  (:types item place)
  (:predicates (at ?i - item ?p - place) (here ?p - place) (lit ?p - place) (held ?i - item) (link ?a ?b - place))
  (:action go :parameters (?a ?b - place) :precondition (and (here ?a) (link ?a ?b) (not (= ?a ?b)))
    :effect (and (not (here ?a)) (here ?b)
                 (forall (?i - item) (when (and (held ?i) (not (lit ?b))) (and (at ?i ?b) (not (held ?i)))))))
  (:action light :parameters (?p - place) :precondition (and (here ?p) (not (lit ?p))) :effect (lit ?p))
  (:action take :parameters (?i - item ?p - place) :precondition (and (here ?p) (at ?i ?p) (not (held ?i)))
    :effect (and (held ?i) (not (at ?i ?p)))))"""

MIXED_PROBLEM = """(define (problem m) (:domain mixed)
  (:objects i1 i2 - item p1 p2 p3 - place)
  (:init (here p1) (at i1 p1) (at i2 p2) (link p1 p2) (link p2 p3) (link p3 p1) (link p2 p1))
  (:goal (and (at i1 p3) (at i2 p1) (not (lit p2)))))"""


def digest(task: GroundTask) -> tuple[int, int, str]:
    """(facts, operators, sha256 of everything the task holds)."""
    ops = [(o.name, o.action, o.args, o.pre, o.add, o.delete, o.cost, o.conditional) for o in task.operators]
    text = repr((task.name, task.facts, sorted(task.init), task.goal, ops, task.has_costs, task.unsolvable_reason))
    return len(task.facts), len(task.operators), hashlib.sha256(text.encode()).hexdigest()[:16]


PINNED = {
    ("blocks", "probBLOCKS-4-0"): (29, 40, "05d3a1a98c3b0c76"),
    ("blocks", "probBLOCKS-12-1"): (181, 312, "dc364950204043ba"),
    ("rovers", "p05"): (59, 144, "8e37c4513cb9bde2"),
    ("rovers", "p20"): (480, 3976, "3830962dcc804175"),
}


@pytest.mark.parametrize(("domain", "problem"), sorted(PINNED))
def test_benchmark_grounding_unchanged(domain: str, problem: str) -> None:
    folder = benchmark_set("pddl") / domain
    d = read_domain(folder / "domain.pddl")
    assert digest(ground(d, read_problem(folder / f"{problem}.pddl", d))) == PINNED[(domain, problem)]


def test_mixed_grounding_unchanged() -> None:
    d = parse_domain(MIXED)
    assert digest(ground(d, parse_problem(MIXED_PROBLEM, domain=d))) == (19, 13, "6f9e619ac554b0fb")


ROADS = """(define (domain roads) (:requirements :typing :action-costs :negative-preconditions)
  (:types place)
  (:predicates (at ?p - place) (road ?a ?b - place) (closed ?p - place))
  (:functions (total-cost) - number (length ?a ?b - place) - number)
  (:action drive :parameters (?a ?b - place) :precondition (and (at ?a) (road ?a ?b) (not (closed ?b)))
    :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (length ?a ?b))))
  (:action close :parameters (?p - place) :precondition (at ?p) :effect (and (closed ?p) (increase (total-cost) 2))))"""

ROADS_PROBLEM = """(define (problem r) (:domain roads) (:objects x y z w - place)
  (:init (at x) (road x y) (road y z) (road z x) (road w x) (= (length x y) 7) (= (length y z) 1) (= (length z x) 4)
         (= (length w x) 1) (= (total-cost) 0))
  (:goal (and (at z) (closed y))) (:metric minimize (total-cost)))"""


def test_costs_grounding_unchanged() -> None:
    d = parse_domain(ROADS)
    assert digest(ground(d, parse_problem(ROADS_PROBLEM, domain=d))) == (9, 6, "3c7b49a6d1b4df31")
