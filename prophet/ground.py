"""Grounding: a lifted domain and problem as a positive STRIPS task with conditional effects.

Only what is reachable from the initial state under the delete relaxation is
kept. The reachable ground actions are found by a fixpoint over the lifted
actions: each new fact is joined with the facts already known, atom by atom,
through indexes on the bound argument positions (never a cross product of all
objects). Negative preconditions and negated goals become positive
``(not-p ...)`` facts that the effects keep up to date; equality is decided
while grounding; static facts (changed by no action) leave the preconditions.

>>> from prophet.pddl import parse_domain, parse_problem
>>> d = parse_domain("(define (domain d) (:predicates (p ?x) (q ?x)) (:action a :parameters (?x) :precondition (p ?x) :effect (q ?x)))")
>>> task = ground(d, parse_problem("(define (problem x) (:domain d) (:objects o) (:init (p o)) (:goal (q o)))", domain=d))
>>> [op.name for op in task.operators], task.facts
(['(a o)'], ('(q o)',))
"""

from __future__ import annotations

from dataclasses import dataclass, field

from prophet.pddl import Domain, PddlError, Problem
from prophet.pddl.model import Equals
from prophet.pddl.normal import dnf, expand
from prophet.pddl.reach import Fixpoint, GroundAction, fact_text

Fact = tuple[str, ...]


@dataclass(frozen=True, slots=True)
class GroundOperator:
    """A ground action over fact ids.

    Attributes:
        name: ``(pick-up a)``: the PDDL action name and arguments.
        action: the action name.
        args: the arguments.
        pre: fact ids that must hold (sorted).
        add: fact ids made true (sorted).
        delete: fact ids made false (sorted; an add wins over a delete of the same fact).
        cost: the action cost (1 without action costs).
        conditional: ``(condition, add, delete)`` fact ids per when-effect, conditions read in the old state.
    """

    name: str
    action: str
    args: tuple[str, ...]
    pre: tuple[int, ...]
    add: tuple[int, ...]
    delete: tuple[int, ...]
    cost: int
    conditional: tuple[tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]], ...] = ()


@dataclass(frozen=True)
class GroundTask:
    """A grounded planning task: facts by id, the initial state, the goal and the operators.

    Attributes:
        name: the problem name.
        facts: ``(on a b)`` strings; a fact's id is its index.
        init: the facts true at the start.
        goal: the fact ids that must hold at the end (sorted).
        operators: the reachable ground operators.
        has_costs: whether the domain uses action costs.
        unsolvable_reason: why the task has no plan, when grounding already shows it (else None).
    """

    name: str
    facts: tuple[str, ...]
    init: frozenset[int]
    goal: tuple[int, ...]
    operators: tuple[GroundOperator, ...]
    has_costs: bool
    unsolvable_reason: str | None = None
    _ids: dict[str, int] = field(default_factory=dict, init=False, repr=False, compare=False)

    def fact_id(self, text: str) -> int:
        """The id of the fact written as ``text`` (case and spacing as in :attr:`facts`).

        Raises:
            KeyError: no such fact in the task.
        """
        if not self._ids:
            self._ids.update((f, i) for i, f in enumerate(self.facts))
        key = " ".join(text.lower().replace("(", " ( ").replace(")", " ) ").split()).replace("( ", "(").replace(" )", ")")
        return self._ids[key]

    def applicable(self, state: frozenset[int], op: GroundOperator) -> bool:
        """Whether every precondition of ``op`` holds in ``state``."""
        return all(p in state for p in op.pre)

    def apply(self, state: frozenset[int], op: GroundOperator) -> frozenset[int]:
        """The state after ``op`` (reference semantics: conditions read in ``state``, adds win)."""
        if not op.conditional:
            return (state - frozenset(op.delete)) | frozenset(op.add)
        add = set(op.add)
        delete = set(op.delete)
        for condition, cond_add, cond_delete in op.conditional:
            if all(c in state for c in condition):
                add.update(cond_add)
                delete.update(cond_delete)
        return (state - delete) | add

    def is_goal(self, state: frozenset[int]) -> bool:
        """Whether ``state`` satisfies the goal."""
        return all(g in state for g in self.goal)

    def operator(self, name: str) -> list[GroundOperator]:
        """The operators called ``name`` (``(pick-up a)``); several when a disjunction was split."""
        return [op for op in self.operators if op.name == name]


def _not_name(predicate: str, taken: set[str]) -> str:
    name = f"not-{predicate}"
    while name in taken:
        name = f"not-{name}"
    return name


def ground(domain: Domain, problem: Problem) -> GroundTask:
    """Ground ``problem`` over ``domain``.

    Args:
        domain: the lifted domain.
        problem: a problem of that domain.

    Returns:
        The reachable positive task. When a goal fact is unreachable (relaxed) or a
        static goal is false, :attr:`GroundTask.unsolvable_reason` says so.

    Raises:
        PddlError: the problem uses names the domain lacks, a cost is missing or
            not a non-negative integer, a goal is disjunctive, or conditional
            effects make a negative precondition impossible to compile.
    """
    fix = Fixpoint(domain, problem)
    fix.run()
    goal_clauses = [c for c in dnf(expand(problem.goal, fix.objects_of)) if fix.clause_possible(c)]
    if len(goal_clauses) > 1:
        raise PddlError("unsupported construct: a disjunctive goal (or, exists, imply) cannot be grounded")
    goal_literals = goal_clauses[0] if goal_clauses else ()
    reason = None if goal_clauses else "the goal is false in every state (static facts or equalities)"
    return _build(domain, problem, fix, goal_literals, reason)


def _build(domain: Domain, problem: Problem, fix: Fixpoint, goal_literals: tuple, reason: str | None) -> GroundTask:
    fluent = fix.fluent
    negated: set[Fact] = set()
    goal_pos: list[Fact] = []
    goal_neg: list[Fact] = []
    for positive, atom in goal_literals:
        if isinstance(atom, Equals):
            continue
        fact = (atom.predicate, *atom.args)
        if atom.predicate not in fluent:
            continue
        (goal_pos if positive else goal_neg).append(fact)
    negated.update(goal_neg)
    for action in fix.actions:
        negated.update(action.neg)
        for cond_pos, cond_neg, _, _ in action.conditional:
            negated.update(cond_neg)
    taken = {p.name for p in domain.predicates}
    not_names = {pred: _not_name(pred, taken) for pred in sorted({f[0] for f in negated})}

    def nf(fact: Fact) -> Fact:
        return (not_names[fact[0]], *fact[1:])

    init_fluent = {f for f in fix.init if f[0] in fluent}
    init = init_fluent | {nf(f) for f in negated if f not in init_fluent}
    compiled = [_compile(a, negated, nf) for a in fix.actions]
    reached, kept = _reachable(init, compiled)
    goal_facts = [*goal_pos, *(nf(f) for f in goal_neg)]
    missing = [f for f in goal_facts if f not in reached]
    if reason is None and missing:
        reason = f"goal fact {fact_text(missing[0])} is not reachable even ignoring deletes"
    names = sorted({fact_text(f) for f in reached} | {fact_text(f) for f in goal_facts})
    ids = {text: i for i, text in enumerate(names)}
    by_fact = {f: ids[fact_text(f)] for f in reached | set(goal_facts)}

    def idset(facts: set[Fact] | frozenset[Fact]) -> tuple[int, ...]:
        return tuple(sorted(by_fact[f] for f in facts if f in reached))

    operators: dict[tuple, GroundOperator] = {}
    for action, (pre, add, delete, conditional) in kept:
        cond = []
        for c_pre, c_add, c_del in conditional:
            if not all(f in reached for f in c_pre):
                continue
            entry = (idset(c_pre), idset(c_add), idset(c_del - c_add))
            if entry[1] or entry[2]:
                cond.append(entry)
        op = GroundOperator(
            fact_text((action.action, *action.args)), action.action, action.args, idset(pre), idset(add),
            idset(delete - add), action.cost, tuple(sorted(set(cond))),
        )
        operators.setdefault((op.name, op.pre, op.add, op.delete, op.cost, op.conditional), op)
    ordered = tuple(operators[k] for k in sorted(operators, key=lambda k: (k[0], k[1], k[2], k[3])))
    return GroundTask(
        problem.name, tuple(names), frozenset(by_fact[f] for f in init if f in reached),
        tuple(sorted({by_fact[f] for f in goal_facts})), ordered, fix.has_costs, reason,
    )


def _compile(action: GroundAction, negated: set[Fact], nf) -> tuple:  # type: ignore[no-untyped-def]
    """Pre, add, delete and conditional effects with ``not-`` facts kept up to date."""
    pre = set(action.pos) | {nf(f) for f in action.neg}
    add = set(action.add)
    delete = set(action.delete) - add
    for fact in sorted(add & negated):
        delete.add(nf(fact))
    for fact in sorted(delete & negated):
        add.add(nf(fact))
    conditional = []
    for i, (c_pos, c_neg, c_add_t, c_del_t) in enumerate(action.conditional):
        c_add = set(c_add_t)
        c_del = set(c_del_t) - c_add - add
        clash = (c_add & set(action.delete) - add) & negated
        for j, other in enumerate(action.conditional):
            if j != i:
                clash |= ((set(other[2]) & c_del) | (set(other[3]) & c_add)) & negated
        if clash:
            raise PddlError(
                f"cannot compile the negative precondition on {fact_text(sorted(clash)[0])}: "
                f"action {fact_text((action.action, *action.args))} both adds and deletes it under different conditions"
            )
        c_pre = set(c_pos) | {nf(f) for f in c_neg}
        extra_add = {nf(f) for f in c_del & negated}
        extra_del = {nf(f) for f in c_add & negated}
        conditional.append((frozenset(c_pre), frozenset(c_add | extra_add), frozenset(c_del | extra_del)))
    return action, (pre, add, delete, conditional)


def _reachable(init: set[Fact], compiled: list[tuple]) -> tuple[set[Fact], list[tuple]]:
    """Relaxed reachability over the ground actions (counting unmet preconditions)."""
    reached: set[Fact] = set()
    waiting: dict[Fact, list[list]] = {}
    records = []
    for index, (_action, (pre, add, _delete, conditional)) in enumerate(compiled):
        records.append([len(pre), add, index])
        for fact in pre:
            waiting.setdefault(fact, []).append(records[-1])
        for c_pre, c_add, _ in conditional:
            record = [len(c_pre) + 1, c_add, -1]
            waiting.setdefault(("$op", str(index)), []).append(record)
            for fact in c_pre:
                waiting.setdefault(fact, []).append(record)
    queue = sorted(init)
    for record in records:
        if record[0] == 0:
            queue.extend(record[1])
            queue.append(("$op", str(record[2])))
    fired: set[int] = set()
    while queue:
        fact = queue.pop()
        if fact in reached:
            continue
        reached.add(fact)
        if fact[0] == "$op":
            fired.add(int(fact[1]))
        for record in waiting.get(fact, ()):
            record[0] -= 1
            if record[0] == 0:
                queue.extend(record[1])
                if record[2] >= 0:
                    queue.append(("$op", str(record[2])))
    reached = {f for f in reached if f[0] != "$op"}
    return reached, [compiled[i] for i in sorted(fired)]
