"""RDDL: a reader with ``FILE:LINE:COL`` errors, a syntax tree and a writer.

The subset of RDDL that ProTaP's domain uses: ``domain``, ``non-fluents`` and
``instance`` blocks, every kind of pvariable, cpfs, reward and constraints,
aggregations, quantifiers and distributions (read and written, not evaluated).

>>> blocks = parse_rddl("domain d { pvariables { p : {state-fluent, bool, default = false}; }; reward = p; }")
>>> blocks.domain.name
'd'
>>> print(write_expr(parse_expr("sum_{?x : t} [f(?x)] <= 1")))
sum_{?x : t} [f(?x) <= 1]
"""

from __future__ import annotations

from alica.prophet.rddl.ast import (
    Aggregate,
    Apply,
    Assignment,
    Binary,
    BoolConst,
    Constant,
    Cpf,
    Distribution,
    Domain,
    EnumValue,
    Expr,
    If,
    Instance,
    IntConst,
    Name,
    Neg,
    NonFluents,
    Not,
    ObjectsDecl,
    Param,
    PVariable,
    RddlFile,
    RealConst,
    TypeDecl,
    TypedParam,
)
from alica.prophet.rddl.check import check_domain, check_instance, check_non_fluents
from alica.prophet.rddl.errors import RddlError
from alica.prophet.rddl.expressions import AGGREGATES, DISTRIBUTIONS, KEYWORDS
from alica.prophet.rddl.parser import PVARIABLE_KINDS
from alica.prophet.rddl.reader import parse_expr, parse_rddl, read_rddl
from alica.prophet.rddl.writer import write_domain, write_expr, write_instance, write_non_fluents, write_rddl

__all__ = [
    "AGGREGATES",
    "DISTRIBUTIONS",
    "KEYWORDS",
    "PVARIABLE_KINDS",
    "Aggregate",
    "Apply",
    "Assignment",
    "Binary",
    "BoolConst",
    "Constant",
    "Cpf",
    "Distribution",
    "Domain",
    "EnumValue",
    "Expr",
    "If",
    "Instance",
    "IntConst",
    "Name",
    "Neg",
    "NonFluents",
    "Not",
    "ObjectsDecl",
    "PVariable",
    "Param",
    "RddlError",
    "RddlFile",
    "RealConst",
    "TypeDecl",
    "TypedParam",
    "check_domain",
    "check_instance",
    "check_non_fluents",
    "parse_expr",
    "parse_rddl",
    "read_rddl",
    "write_domain",
    "write_expr",
    "write_instance",
    "write_non_fluents",
    "write_rddl",
]
