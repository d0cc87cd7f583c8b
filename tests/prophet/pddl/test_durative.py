"""Durative actions (PDDL 2.1, ``:durative-actions``): read, written back, and refused clearly where unsupported."""

from __future__ import annotations

import pytest

from alica.prophet.pddl import (
    TOTAL_TIME,
    And,
    Atom,
    FluentTerm,
    Not,
    PddlError,
    parse_domain,
    parse_problem,
    write_domain,
    write_problem,
)
from alica.prophet.planner import Feature

DOMAIN = """(define (domain rovers-t)
  (:requirements :typing :durative-actions)
  (:types rover place)
  (:predicates (at ?r - rover ?p - place) (path ?a ?b - place) (visited ?p - place) (charged ?r - rover))
  (:functions (travel ?a ?b - place))
  (:durative-action move
    :parameters (?r - rover ?a ?b - place)
    :duration (= ?duration (travel ?a ?b))
    :condition (and (at start (at ?r ?a)) (over all (path ?a ?b)) (at start (charged ?r)) (at end (charged ?r)))
    :effect (and (at start (not (at ?r ?a))) (at end (at ?r ?b)) (at end (visited ?b))))
  (:durative-action recharge
    :parameters (?r - rover)
    :duration (= ?duration 2.5)
    :condition ()
    :effect (at end (charged ?r)))
  (:durative-action close
    :parameters (?a ?b - place)
    :duration (= ?duration 1)
    :condition (at start (path ?a ?b))
    :effect (at end (not (path ?a ?b))))
  (:durative-action drain
    :parameters (?r - rover)
    :duration (= ?duration 1)
    :condition ()
    :effect (at start (not (charged ?r)))))
"""
"""Rovers that drive for a function's time and recharge; ``close`` and ``drain`` break what a drive needs."""

PROBLEM = """(define (problem two) (:domain rovers-t)
  (:objects r - rover p q - place)
  (:init (at r p) (path p q) (= (travel p q) 4))
  (:goal (visited q))
  (:metric minimize (total-time)))
"""


def test_a_durative_action_reads_into_its_timed_parts() -> None:
    domain = parse_domain(DOMAIN, "d.pddl")
    assert Feature.DURATIVE_ACTIONS in domain.requirements and not domain.actions
    move = domain.durative_action("move")
    assert move is not None and move.duration == FluentTerm("travel", ("?a", "?b"))
    assert move.at_start == And((Atom("at", ("?r", "?a")), Atom("charged", ("?r",))))
    assert move.over_all == Atom("path", ("?a", "?b")) and move.at_end == Atom("charged", ("?r",))
    assert move.start_effect == Not(Atom("at", ("?r", "?a")))
    assert move.end_effect == And((Atom("at", ("?r", "?b")), Atom("visited", ("?b",))))
    assert move.span is not None and move.span.line == 6
    recharge = domain.durative_action("recharge")
    assert recharge is not None and recharge.duration == 2.5 and recharge.at_start == And(())
    assert recharge.end_effect == Atom("charged", ("?r",))


def test_durative_domains_and_the_makespan_metric_round_trip() -> None:
    domain = parse_domain(DOMAIN)
    assert parse_domain(write_domain(domain)) == domain
    problem = parse_problem(PROBLEM, domain=domain)
    assert problem.metric is not None and problem.metric.expression == FluentTerm(TOTAL_TIME)
    assert parse_problem(write_problem(problem), domain=domain) == problem


def _with(action: str) -> str:
    return f"(define (domain d) (:requirements :durative-actions) (:predicates (p) (q)) (:functions (f))\n{action})"


BROKEN = [
    (
        "inequality",
        "(:durative-action a :parameters () :duration (<= ?duration 5) :condition () :effect ())",
        r"d\.pddl:2:46: error: unsupported duration constraint '\(<= \.\.\.\)' in 'a'",
    ),
    (
        "no duration",
        "(:durative-action a :parameters () :condition () :effect ())",
        r"d\.pddl:2:1: error: expected ':duration \(= \?duration d\)' in '\(:durative-action a'",
    ),
    (
        "negative",
        "(:durative-action a :parameters () :duration (= ?duration -1) :effect ())",
        r"d\.pddl:2:59: error: negative duration -1 in 'a'",
    ),
    (
        "expression",
        "(:durative-action a :parameters () :duration (= ?duration (* 2 (f))) :effect ())",
        r"d\.pddl:2:59: error: unsupported duration expression '\(\* \.\.\.\)' in 'a'",
    ),
    (
        "undeclared function",
        "(:durative-action a :parameters () :duration (= ?duration (g)) :effect ())",
        r"d\.pddl:2:60: error: undefined function 'g'",
    ),
    (
        "untimed condition",
        "(:durative-action a :parameters () :duration (= ?duration 1) :condition (and (p)))",
        r"d\.pddl:2:78: error: expected \(at start \.\.\.\), \(over all \.\.\.\) or \(at end \.\.\.\) in the condition of 'a'",
    ),
    (
        "continuous effect",
        "(:durative-action a :parameters () :duration (= ?duration 1) :effect (over all (p)))",
        r"d\.pddl:2:80: error: expected \(at start \.\.\.\) or \(at end \.\.\.\) in the effect of 'a'",
    ),
    (
        "unknown key",
        "(:durative-action a :parameters () :precondition (p))",
        r"d\.pddl:2:36: error: expected :parameters, :duration, :condition or :effect in '\(:durative-action a'",
    ),
]


@pytest.mark.parametrize(("case", "action", "message"), BROKEN, ids=[b[0] for b in BROKEN])
def test_broken_durative_actions_name_the_place(case: str, action: str, message: str) -> None:
    with pytest.raises(PddlError, match=message):
        parse_domain(_with(action), "d.pddl")


def test_a_durative_action_and_an_action_may_not_share_a_name() -> None:
    text = _with(
        "(:action a :parameters () :effect (p))\n(:durative-action a :parameters () :duration (= ?duration 1))"
    )
    with pytest.raises(PddlError, match=r"d\.pddl:3:1: error: duplicate action 'a'"):
        parse_domain(text, "d.pddl")
