"""From a running plan tree to one constraint problem: the query of a plan or behaviour.

ALICA collects a query's problem by walking up the running plan tree: every
plan on the way contributes the constraints that are active while it runs,
and the bindings of the children unify a child's variables with its
parent's, so that constraints of several levels are solved together
(``../shared/reference/alica_semantics.md`` Section 1.9).

Here a running plan tree is described by :class:`Level` objects, root first:
the plan, who is in it (each agent's entry point and state) and how the
level's variables are bound to the level above. The engine builds them from
its plan nodes, ``alica solve`` from an allocation computed offline; both
then call :func:`collect`.

* A variable read as ``v(a)`` in any constraint of its class is a per-agent
  variable: one decision variable for every agent of the level that declares
  it. A variable only read as ``v`` is static: one value for the team.
* Bound variables form one class (union-find over ``(level, name)``), named
  after its outermost declaration; the formulas of inner levels are renamed to
  that name. Its domain is the first declaration (outermost first) that has a
  type other than ``any``.
* ``agents(E)`` lists the agents whose entry point, task or state in a level
  is ``E``, looked up from the innermost level out.
* The seed comes from the levels' keys and who is where, so agents with the
  same view build the same problem with the same seed.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

from alica.errors import AlicaError
from alica.lang import BeliefBase, Registry, parse
from alica.lang.ast import (
    And,
    Attr,
    Binary,
    Call,
    Compare,
    Iff,
    Implies,
    Name,
    Node,
    Not,
    Or,
    Quantified,
    Unary,
    agents_of,
)
from alica.lang.evaluator import evaluate
from alica.lang.walk import walk
from alica.model import Plan, Variable
from alica.solver.problem import Domain, Finite, Integer, Point, Problem, Real, Term, Var

#: One agent's place in a plan: its entry point and its state (either may be unknown).
Place = tuple[str | None, str | None]


class QueryError(AlicaError):
    """A plan's variables cannot be turned into a problem (a variable without a domain, say)."""


@dataclass(frozen=True)
class Level:
    """One running plan of the tree, as the query sees it.

    Args:
        key: the plan instance's key, e.g. ``Mission/Explore/ExploreFrontiers``.
        plan: the plan.
        places: agent -> (entry point, state) of the agents in this plan.
        bindings: this plan's variable -> the variable of the level above it is bound to
            (the child reference's bindings whose value is a bare variable name).
    """

    key: str
    plan: Plan
    places: Mapping[str, Place]
    bindings: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Query:
    """The problem of a query, with what maps it back to the plans' variables.

    Attributes:
        problem: the problem to solve.
        names: ``(level index, variable name)`` -> the name of its class in the problem.
        digest: a hash of the levels' keys and places: equal views give equal digests.
    """

    problem: Problem
    names: Mapping[tuple[int, str], str]
    digest: str

    def local(self, level: int) -> dict[str, str]:
        """Problem name -> the variable's name in level ``level``."""
        return {solved: name for (i, name), solved in self.names.items() if i == level}


class _Classes:
    """Union-find over ``(level, variable)``."""

    def __init__(self) -> None:
        self.parent: dict[tuple[int, str], tuple[int, str]] = {}

    def find(self, item: tuple[int, str]) -> tuple[int, str]:
        parent = self.parent.setdefault(item, item)
        while parent != self.parent[parent]:
            parent = self.parent[parent]
        self.parent[item] = parent
        return parent

    def union(self, outer: tuple[int, str], inner: tuple[int, str]) -> None:
        a, b = self.find(outer), self.find(inner)
        if a != b:
            # the outermost (lowest level) stays the representative: the class is named after it
            keep, drop = (a, b) if a <= b else (b, a)
            self.parent[drop] = keep


def _rename(node: Node, names: Mapping[str, str], bound: frozenset[str] = frozenset()) -> Node:
    """``node`` with free variable names (``v`` and per-agent reads ``v(a)``) renamed by ``names``."""
    if not any(n in names for n in _identifiers(node)):
        return node
    if isinstance(node, Name):
        return replace(node, name=names[node.name]) if node.name in names and node.name not in bound else node
    if isinstance(node, Quantified):
        inner = bound | {var for var, _ in node.binders}
        return replace(node, body=_rename(node.body, names, inner))
    if isinstance(node, Call):
        args = tuple(_rename(arg, names, bound) for arg in node.args)
        name = names[node.name] if node.name in names and node.name not in bound and len(args) == 1 else node.name
        return replace(node, name=name, args=args)
    if isinstance(node, (And, Or)):
        return replace(node, items=tuple(_rename(item, names, bound) for item in node.items))
    if isinstance(node, Not):
        return replace(node, operand=_rename(node.operand, names, bound))
    if isinstance(node, Unary):
        return replace(node, operand=_rename(node.operand, names, bound))
    if isinstance(node, Attr):
        return replace(node, obj=_rename(node.obj, names, bound))
    if isinstance(node, (Binary, Compare, Implies, Iff)):
        return replace(node, left=_rename(node.left, names, bound), right=_rename(node.right, names, bound))
    return node


def _identifiers(node: Node) -> set[str]:
    return {sub.name for sub in walk(node) if isinstance(sub, (Name, Call))}


def per_agent_reads(node: Node) -> set[str]:
    """Names read with one argument (``v(a)``): per-agent variables, when they are variables."""
    return {sub.name for sub in walk(node) if isinstance(sub, Call) and len(sub.args) == 1}


def _domain(variable: Variable, belief: BeliefBase, registry: Registry | None) -> Domain:
    kind = variable.type
    low, high = variable.low, variable.high
    if kind in ("real", "int", "point"):
        if low is None or high is None or not (math.isfinite(low) and math.isfinite(high)) or low > high:
            raise QueryError(f"variable '{variable.name}' of type {kind} needs a finite range [low, high]")
        if kind == "real":
            return Real(float(low), float(high))
        if kind == "point":
            return Point(float(low), float(high))
        return Integer(math.ceil(low), math.floor(high))
    if kind == "any":
        raise QueryError(
            f"variable '{variable.name}' has no type, so it cannot be solved; "
            "declare it as real[lo, hi], int[lo, hi], point[lo, hi] or an object type"
        )
    if variable.candidates:
        try:
            found = evaluate(variable.candidates, belief, registry=registry)
        except AlicaError as exc:
            raise QueryError(f"candidates of variable '{variable.name}' ({variable.candidates}): {exc}") from exc
        if isinstance(found, (str, bytes)) or not isinstance(found, Iterable):
            raise QueryError(
                f"candidates of variable '{variable.name}' ({variable.candidates}) gave {found!r}, not a list"
            )
        values = tuple(found)
        where = f"its candidates {variable.candidates} are none"
    else:
        values = tuple(belief.objects(kind))
        where = f"no object of type {kind} is known"
    if not values:
        raise QueryError(f"variable '{variable.name}' has no value to choose from: {where}")
    return Finite(values)


class LevelBelief:
    """A belief base that adds the ``agents(E)`` domains of the levels to another one."""

    def __init__(self, belief: BeliefBase, levels: Sequence[Level]) -> None:
        self.belief = belief
        self.levels = levels

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        return self.belief.lookup(name, args)

    def objects(self, type_name: str) -> Iterable[object]:
        which = agents_of(type_name)
        if which is None:
            return self.belief.objects(type_name)
        return agents_in(self.levels, which)


def agents_in(levels: Sequence[Level], which: str) -> tuple[str, ...]:
    """The agents whose entry point, task or state is ``which``, in the innermost level that has it, sorted."""
    for level in reversed(levels):
        plan = level.plan
        entries = {ep.name: ep for ep in plan.entry_points}
        tasks = {ep.task for ep in plan.entry_points}
        states = {s.name for s in plan.states}
        if which not in entries and which not in tasks and which not in states:
            continue
        found = []
        for agent, (entry, state) in level.places.items():
            ep = entries.get(entry) if entry is not None else None
            if entry == which or state == which or (ep is not None and ep.task == which):
                found.append(agent)
        return tuple(sorted(found))
    return ()


def digest(levels: Sequence[Level]) -> str:
    """A hash of the levels' keys and places."""
    text = "|".join(f"{lv.key}:{sorted((a, p) for a, p in lv.places.items())!r}" for lv in levels)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def collect(
    levels: Sequence[Level], belief: BeliefBase, *, registry: Registry | None = None, names: Iterable[str] = ()
) -> Query:
    """The problem of the constraints of ``levels`` (root first), with their bindings unified.

    Args:
        levels: the running plans from the root to the plan that asks.
        belief: what the agent believes (facts, functions, objects).
        registry: registered functions and predicates (``None``: the built-ins).
        names: variables of the innermost level to solve even if no constraint mentions them.

    Raises:
        QueryError: a variable that must be solved has no domain, or its candidates cannot be listed.
    """
    classes = _Classes()
    declared: dict[tuple[int, str], Variable] = {}
    for i, level in enumerate(levels):
        for variable in level.plan.variables:
            declared[(i, variable.name)] = variable
            classes.find((i, variable.name))
        if i:
            for child, parent in level.bindings.items():
                if (i, child) in declared and (i - 1, parent) in declared:
                    classes.union((i - 1, parent), (i, child))
    name_of = {item: classes.find(item)[1] for item in declared}
    scoped = LevelBelief(belief, levels)
    constraints: list[Term] = []
    utilities: list[Term] = []
    used: set[str] = set()
    per_agent: set[str] = set()
    for i, level in enumerate(levels):
        renames = {name: name_of[(i, name)] for (j, name) in declared if j == i}
        for constraint in level.plan.constraints:
            for text, into in ((constraint.text, constraints), (constraint.utility, utilities)):
                if not text:
                    continue
                node = _rename(parse(text), renames)
                mentioned = _identifiers(node) & set(renames.values())
                used |= mentioned
                per_agent |= per_agent_reads(node) & mentioned
                into.append(Term(f"{level.plan.name}.{constraint.name}", node, text))
    wanted = {name_of[(len(levels) - 1, n)] for n in names if (len(levels) - 1, n) in declared}
    variables: list[Var] = []
    problem_names: dict[tuple[int, str], str] = {}
    for item, variable in sorted(declared.items()):
        solved = name_of[item]
        if solved not in used and solved not in wanted:
            continue
        problem_names[item] = solved
        if classes.find(item) != item:
            continue  # the class is declared once, at its outermost level
        domain_source = next(
            (
                declared[other]
                for other in sorted(declared)
                if name_of[other] == solved and declared[other].type != "any"
            ),
            variable,
        )
        domain = _domain(domain_source, scoped, registry)
        if solved in per_agent:
            variables.extend(Var(solved, agent, domain) for agent in sorted(levels[item[0]].places))
        else:
            variables.append(Var(solved, None, domain))
    view = digest(levels)
    problem = Problem(
        variables=tuple(variables),
        constraints=tuple(constraints),
        utilities=tuple(utilities),
        belief=scoped,
        registry=registry,
        seed=int(view, 16) % (2**31),
    )
    return Query(problem, problem_names, view)
