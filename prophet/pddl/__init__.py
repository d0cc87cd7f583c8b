"""PDDL: the lifted model, a reader with ``FILE:LINE:COL`` errors, and a writer.

>>> domain = parse_domain("(define (domain d) (:predicates (p ?x)) (:action a :parameters (?x) :precondition (p ?x) :effect (not (p ?x))))")
>>> domain.actions[0].name
'a'
"""

from __future__ import annotations

from alica.prophet.pddl.errors import PddlError
from alica.prophet.pddl.model import (
    OBJECT,
    TOTAL_TIME,
    Action,
    And,
    Atom,
    Axiom,
    Domain,
    DurativeAction,
    Effect,
    Equals,
    Exists,
    FluentTerm,
    FluentValue,
    Forall,
    Formula,
    Imply,
    Increase,
    Metric,
    Not,
    Or,
    Predicate,
    Problem,
    TypedName,
    When,
    either,
)
from alica.prophet.pddl.parser import SUPPORTED_REQUIREMENTS, parse_domain, parse_problem, read_domain, read_problem
from alica.prophet.pddl.writer import write_domain, write_formula, write_problem

__all__ = [
    "OBJECT",
    "SUPPORTED_REQUIREMENTS",
    "TOTAL_TIME",
    "Action",
    "And",
    "Atom",
    "Axiom",
    "Domain",
    "DurativeAction",
    "Effect",
    "Equals",
    "Exists",
    "FluentTerm",
    "FluentValue",
    "Forall",
    "Formula",
    "Imply",
    "Increase",
    "Metric",
    "Not",
    "Or",
    "PddlError",
    "Predicate",
    "Problem",
    "TypedName",
    "When",
    "either",
    "parse_domain",
    "parse_problem",
    "read_domain",
    "read_problem",
    "write_domain",
    "write_formula",
    "write_problem",
]
