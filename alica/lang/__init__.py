"""The logic language of conditions, constraints and goals in plan files.

Formulas are strings such as ``forall f1, f2 in Frontier: MaximalDist(f1, f2,
eps) or f1 = f2``. :func:`parse` turns text into an immutable tree (see
:mod:`alica.lang.ast` and the grammar in :mod:`alica.lang.parser`),
:func:`check` finds static problems, :func:`evaluate` and :func:`holds` run a
formula against a :class:`BeliefBase` such as :class:`FactBase`.

Evaluation rules:

* A **name** is, in this order: its binding in ``env`` (which also holds
  quantifier variables and ``self``); else the result of a registered
  predicate or function accepting no arguments; else ``belief.lookup(name,
  ())`` when that is not None (a 0-ary fact such as ``explored``); else a
  symbol constant, the string ``name`` itself, so ``On(a, g)`` passes
  ``'a'`` and ``'g'``. Where a truth value is needed, an unknown name is
  false.
* A **call** ``f(x, ...)`` uses a registered callable first (receiving the
  belief base as first argument when registered with ``needs_belief``), else
  ``belief.lookup('f', (x, ...))``. An unknown fact (None) is false where a
  truth value is needed (closed world) and an error where a value is needed.
* Truth values are needed by the operands of ``and``, ``or``, ``not``,
  ``->``, ``<->``, by quantifier bodies and at the top of :func:`holds`.
  ``and``/``or`` short-circuit, ``A -> B`` is ``not A or B``.
* ``forall``/``exists`` range over ``belief.objects(type)``; over an empty
  domain ``forall`` is true and ``exists`` false.
* ``=``/``==``/``!=`` compare any values (a bool never equals a non-bool);
  ``< <= > >=`` compare two numbers or two strings; arithmetic needs numbers,
  ``/`` is true division and ``^`` is power.
* ``p.x`` reads an attribute, a mapping key, or for sequences ``.x .y .z``
  the items 0, 1, 2.
* Failures raise :class:`~alica.errors.EvaluationError` naming the
  sub-expression and its column.

The predicates and functions a formula may read are declared in a
:class:`Vocabulary`; :func:`check` given one reports unknown names and wrong
arities (see :mod:`alica.lang.vocabulary`).
"""

from __future__ import annotations

from alica.lang.ast import (
    And,
    Attr,
    Binary,
    Bool,
    Call,
    Compare,
    Iff,
    Implies,
    Name,
    Node,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
)
from alica.lang.belief import BeliefBase
from alica.lang.checker import check
from alica.lang.evaluator import compile_formula, evaluate, holds
from alica.lang.factbase import FactBase
from alica.lang.parser import parse
from alica.lang.prelude import default_registry
from alica.lang.registry import Entry, Registry
from alica.lang.unparse import unparse
from alica.lang.vocabulary import ENGINE_FACTS, ENGINE_VARIABLES, Symbol, Vocabulary, default_vocabulary
from alica.lang.walk import atoms, calls, free_names, literal_text, literals, walk

__all__ = [
    "ENGINE_FACTS",
    "ENGINE_VARIABLES",
    "And",
    "Attr",
    "BeliefBase",
    "Binary",
    "Bool",
    "Call",
    "Compare",
    "Entry",
    "FactBase",
    "Iff",
    "Implies",
    "Name",
    "Node",
    "Not",
    "Number",
    "Or",
    "Quantified",
    "Registry",
    "String",
    "Symbol",
    "Unary",
    "Vocabulary",
    "atoms",
    "calls",
    "check",
    "compile_formula",
    "default_registry",
    "default_vocabulary",
    "evaluate",
    "free_names",
    "holds",
    "literal_text",
    "literals",
    "parse",
    "unparse",
    "walk",
]
