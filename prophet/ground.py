"""Grounding: a lifted domain and problem as a positive STRIPS task with conditional effects.

Only what is reachable from the initial state under the delete relaxation is
kept. The reachable ground actions are found by a fixpoint over the lifted
actions: each new fact is joined with the facts already known, atom by atom,
through indexes on the bound argument positions (never a cross product of all
objects). Negative preconditions and negated goals become positive
``(not-p ...)`` facts that the effects keep up to date; equality is decided
while grounding; static facts (changed by no action) leave the preconditions.
Those ``not-`` facts and when-effects need a second, ground relaxed exploration
(over local integer fact ids); a task without them (plain STRIPS, such as
Rovers) skips it, since the fixpoint's exploration is then exact. Derived
predicates become ground axioms (:class:`GroundAxiom`) evaluated in every state
(:func:`evaluate_axioms`); a negated derived fact is the derived fact
``(not@p ...)``, never a ``not-`` fact. The garbage collector is paused while
grounding (many objects, no cycles).

With :class:`~alica.prophet.planner.Limits`, grounding checks the deadline and
its estimated memory (:mod:`alica.prophet.pddl.reach`) inside the fixpoint and
every few thousand actions after it, and raises
:class:`~alica.prophet.planner.LimitReached` (stage ``grounding``).

>>> from alica.prophet.pddl import parse_domain, parse_problem
>>> d = parse_domain("(define (domain d) (:predicates (p ?x) (q ?x)) (:action a :parameters (?x) :precondition (p ?x) :effect (q ?x)))")
>>> task = ground(d, parse_problem("(define (problem x) (:domain d) (:objects o) (:init (p o)) (:goal (q o)))", domain=d))
>>> [op.name for op in task.operators], task.facts
(['(a o)'], ('(q o)',))
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from operator import itemgetter

from alica.prophet.pddl import Domain, PddlError, Problem
from alica.prophet.pddl.model import Equals
from alica.prophet.pddl.reach import CHECK_EVERY, Fixpoint, GroundAction, fact_text
from alica.prophet.planner import LimitReached, Limits, collector_paused

#: A grounded PDDL atom as a flat tuple ``(predicate, *objects)``: a node of the grounding, not a
#: :class:`alica.lang.fact.Fact` of the world model (flat tuples keep the grounding fast).
GroundAtom = tuple[str, ...]


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


@dataclass(frozen=True, slots=True)
class GroundAxiom:
    """A ground rule of a derived fact, over fact ids.

    Attributes:
        head: the derived fact it makes true.
        pos: fact ids that must hold (sorted).
        neg: derived fact ids (of lower layers) that must not hold, by negation as failure (sorted).
        layer: the stratum: layers are evaluated in increasing order, each to its fixpoint.
    """

    head: int
    pos: tuple[int, ...]
    neg: tuple[int, ...]
    layer: int


def evaluate_axioms(axioms: tuple[GroundAxiom, ...], derived: frozenset[int], state: frozenset[int]) -> frozenset[int]:
    """``state`` with its derived facts recomputed from the basic ones (the stratified least fixpoint)."""
    if not axioms:
        return state
    facts = set(state - derived)
    by_layer: dict[int, list[GroundAxiom]] = {}
    for axiom in axioms:
        by_layer.setdefault(axiom.layer, []).append(axiom)
    for layer in sorted(by_layer):
        rules = by_layer[layer]
        changed = True
        while changed:
            changed = False
            for a in rules:
                if a.head not in facts and all(p in facts for p in a.pos) and not any(n in facts for n in a.neg):
                    facts.add(a.head)
                    changed = True
    return frozenset(facts)


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
        axioms: the ground rules of the derived facts (empty without derived predicates).
        derived: the derived fact ids (a state's derived facts follow from its other facts through
            ``axioms``; :attr:`init` and :meth:`apply` include them).
        relaxed_axioms: the rules the delete relaxation uses instead of ``axioms``, ``(head, body)``:
            each axiom with its negated derived facts read through their ``(not@p ...)`` facts, and
            for each ``(not@p ...)`` fact, rules saying that every rule of ``p`` fails (the rules'
            bodies negated and multiplied out; see :func:`_relaxed_rules`).
    """

    name: str
    facts: tuple[str, ...]
    init: frozenset[int]
    goal: tuple[int, ...]
    operators: tuple[GroundOperator, ...]
    has_costs: bool
    unsolvable_reason: str | None = None
    axioms: tuple[GroundAxiom, ...] = ()
    derived: frozenset[int] = frozenset()
    relaxed_axioms: tuple[tuple[int, tuple[int, ...]], ...] = ()
    _ids: dict[str, int] = field(default_factory=dict, init=False, repr=False, compare=False)
    _by_name: dict[str, list[GroundOperator]] = field(default_factory=dict, init=False, repr=False, compare=False)

    def fact_id(self, text: str) -> int:
        """The id of the fact written as ``text`` (case and spacing as in :attr:`facts`).

        Raises:
            KeyError: no such fact in the task.
        """
        if not self._ids:
            self._ids.update((f, i) for i, f in enumerate(self.facts))
        key = (
            " ".join(text.lower().replace("(", " ( ").replace(")", " ) ").split()).replace("( ", "(").replace(" )", ")")
        )
        return self._ids[key]

    def applicable(self, state: frozenset[int], op: GroundOperator) -> bool:
        """Whether every precondition of ``op`` holds in ``state``."""
        return all(p in state for p in op.pre)

    def apply(self, state: frozenset[int], op: GroundOperator) -> frozenset[int]:
        """The state after ``op`` (reference semantics: conditions read in ``state``, adds win, derived facts
        recomputed)."""
        if not op.conditional:
            after = (state - frozenset(op.delete)) | frozenset(op.add)
        else:
            add = set(op.add)
            delete = set(op.delete)
            for condition, cond_add, cond_delete in op.conditional:
                if all(c in state for c in condition):
                    add.update(cond_add)
                    delete.update(cond_delete)
            after = (state - delete) | add
        return evaluate_axioms(self.axioms, self.derived, after) if self.axioms else after

    def is_goal(self, state: frozenset[int]) -> bool:
        """Whether ``state`` satisfies the goal."""
        return all(g in state for g in self.goal)

    def operator(self, name: str) -> list[GroundOperator]:
        """The operators called ``name`` (``(pick-up a)``); several when a disjunction was split."""
        if not self._by_name and self.operators:
            for op in self.operators:
                self._by_name.setdefault(op.name, []).append(op)
        return list(self._by_name.get(name, ()))


NOT_DERIVED = "not@"
"""The prefix of the derived facts that hold when a derived fact does not (for negated derived preconditions)."""


def _not_name(predicate: str, taken: set[str]) -> str:
    name = f"not-{predicate}"
    while name in taken:
        name = f"not-{name}"
    return name


def ground(domain: Domain, problem: Problem, limits: Limits | None = None) -> GroundTask:
    """Ground ``problem`` over ``domain``.

    Args:
        domain: the lifted domain.
        problem: a problem of that domain.
        limits: a deadline and memory bound, checked while grounding.

    Returns:
        The reachable positive task. When a goal fact is unreachable (relaxed) or a
        static goal is false, :attr:`GroundTask.unsolvable_reason` says so.

    Raises:
        PddlError: the problem uses names the domain lacks, a cost is missing or
            not a non-negative integer, the derived predicates are not stratifiable,
            or conditional effects make a negative precondition impossible to compile.
        LimitReached: a limit was reached while grounding (the message says how far it got).
    """
    with collector_paused():
        try:
            return _ground(domain, problem, limits)
        except LimitReached as exc:
            # Drop the frames, and with them the abandoned grounding, while the collector is still
            # paused: with it running, freeing millions of objects took longer than building them.
            raise exc.with_traceback(None) from None


def _ground(domain: Domain, problem: Problem, limits: Limits | None) -> GroundTask:
    fix = Fixpoint(domain, problem, limits)
    fix.run()
    fix.check()
    return _build(domain, problem, fix, fix.goal_literals, fix.goal_reason)


def _build(domain: Domain, problem: Problem, fix: Fixpoint, goal_literals: tuple, reason: str | None) -> GroundTask:
    fluent = fix.fluent
    negated: set[GroundAtom] = set()
    goal_pos: list[GroundAtom] = []
    goal_neg: list[GroundAtom] = []
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
        for _cond_pos, cond_neg, _, _ in action.conditional:
            negated.update(cond_neg)
    init_fluent = {f for f in fix.init if f[0] in fluent and f[0] not in fix.derived}
    if not negated and not fix.rules and not any(action.conditional for action in fix.actions):
        return _build_positive(problem, fix, init_fluent, goal_pos, reason)
    derived = fix.derived
    negated_derived = {f for f in negated if f[0] in derived}  # through (not@p ...) rules, never effects
    negated -= negated_derived
    for rule in fix.rules:
        negated.update(f for f in rule.neg if f[0] not in derived)
    if fix.rules:
        _negations_for_relaxation(fix, negated, negated_derived)
    taken = {p.name for p in domain.predicates}
    not_names = {pred: _not_name(pred, taken) for pred in sorted({f[0] for f in negated})}
    not_names.update((pred, NOT_DERIVED + pred) for pred in {f[0] for f in negated_derived})

    def nf(fact: GroundAtom) -> GroundAtom:
        return (not_names[fact[0]], *fact[1:])

    init = init_fluent | {nf(f) for f in negated if f not in init_fluent}
    table = _Facts()
    compiled = []
    for k, a in enumerate(fix.actions, 1):
        compiled.append(_compile(a, negated, nf, table))
        if not k % CHECK_EVERY:
            fix.check()
    rules = [
        (
            frozenset(table.id(f) for f in (*r.pos, *(nf(g) for g in r.neg if g[0] not in derived))),
            table.id(r.head),
            frozenset(table.id(g) for g in r.neg if g[0] in derived),
            r.layer,
        )
        for r in fix.rules
    ]
    rules += [
        (frozenset(), table.id(nf(f)), frozenset({table.id(f)}), fix.layer[f[0]] + 1) for f in sorted(negated_derived)
    ]
    n_actions = len(compiled)
    compiled += [(pre, frozenset({head}), frozenset(), ()) for pre, head, _, _ in rules]
    init_ids = {table.id(f) for f in init}
    goal_facts = [*goal_pos, *(nf(f) for f in goal_neg)]
    goal_ids = [table.id(f) for f in goal_facts]
    reached, fired = _reachable(len(table.ids), init_ids, compiled)
    fired_rules = [rules[k - n_actions] for k in fired if k >= n_actions]
    fired = [k for k in fired if k < n_actions]
    missing = [f for f, i in zip(goal_facts, goal_ids, strict=True) if not reached[i]]
    if reason is None and missing:
        reason = f"goal fact {fact_text(missing[0])} is not reachable even ignoring deletes"
    facts = table.facts
    wanted = {i for i, ok in enumerate(reached) if ok} | set(goal_ids)
    text_of = {i: fact_text(facts[i]) for i in wanted}
    names = sorted(set(text_of.values()))
    ids = {text: i for i, text in enumerate(names)}
    final = [-1] * len(facts)  # -1: not reached (left out of the operators)
    for i, text in text_of.items():
        if reached[i]:
            final[i] = ids[text]
    goal_final = {ids[text_of[i]] for i in goal_ids}
    fix.check()
    operators = _operators([(fix.actions[k], compiled[k]) for k in fired], final)
    axioms = tuple(
        sorted(
            {
                GroundAxiom(
                    final[head],
                    tuple(sorted({final[i] for i in pre})),
                    tuple(sorted({final[i] for i in naf if final[i] >= 0})),
                    layer,
                )
                for pre, head, naf, layer in fired_rules
            },
            key=lambda a: (a.layer, a.head, a.pos, a.neg),
        )
    )
    derived_names = derived | {NOT_DERIVED + p for p in derived}
    derived_ids = frozenset(final[i] for i, f in enumerate(facts) if f[0] in derived_names and final[i] >= 0)
    derived_ids |= frozenset(ids[text_of[i]] for i in goal_ids if facts[i][0] in derived_names)
    init_state = frozenset(final[i] for i in init_ids if final[i] >= 0)
    relaxed = _relaxed_rules(negated, negated_derived, nf, table, fired_rules, final)
    return GroundTask(
        problem.name,
        tuple(names),
        evaluate_axioms(axioms, derived_ids, init_state),
        tuple(sorted(goal_final)),
        operators,
        fix.has_costs,
        reason,
        axioms,
        derived_ids,
        relaxed,
    )


MAX_NEGATED_CLAUSES = 64
"""The most conjunctions the negation of a derived fact's rules may multiply out into (beyond: true)."""


def _negations_for_relaxation(fix: Fixpoint, negated: set[GroundAtom], negated_derived: set[GroundAtom]) -> None:
    """Add what the relaxation needs to read derived facts negated (in place).

    Every derived fact negated somewhere (a precondition, goal, condition or a rule's body) gets a
    ``(not@p ...)`` fact; so does every derived fact in a body of its rules, and the basic facts of
    those bodies get their ``(not-p ...)`` twins (kept up to date by the effects), so that the
    negation of each rule can be written over facts. A basic fact an action both adds and deletes
    under conditions gets no twin (its ``not-`` fact could not be kept up to date): its rules' failure
    is over-approximated.
    """
    derived = fix.derived
    rules_of: dict[GroundAtom, list] = {}
    for rule in fix.rules:
        rules_of.setdefault(rule.head, []).append(rule)
    risky: set[GroundAtom] = set()
    for action in fix.actions:
        if action.conditional:
            adds = set(action.add)
            dels = set(action.delete)
            for _, _, c_add, c_del in action.conditional:
                adds.update(c_add)
                dels.update(c_del)
            risky |= adds & dels
    work = list(negated_derived) + [g for rule in fix.rules for g in rule.neg if g[0] in derived]
    seen: set[GroundAtom] = set()
    while work:
        f = work.pop()
        if f in seen:
            continue
        seen.add(f)
        negated_derived.add(f)
        for rule in rules_of.get(f, ()):
            for g in rule.pos:
                if g[0] in derived:
                    work.append(g)
                elif g not in risky:
                    negated.add(g)


def _relaxed_rules(  # type: ignore[no-untyped-def]
    negated: set[GroundAtom], negated_derived: set[GroundAtom], nf, table: _Facts, rules, final
) -> tuple[tuple[int, tuple[int, ...]], ...]:
    """The rules of the relaxation (:attr:`GroundTask.relaxed_axioms`), over final fact ids.

    An axiom's negated derived fact is read through its ``(not@p ...)`` fact. ``(not@p ...)`` holds
    when every rule of ``p`` has a false body: a body literal's complement is the ``not-`` fact of
    a basic fact (or the basic fact of a ``not-`` fact), the ``not@`` fact of a derived fact, or, for
    a negated derived fact, the fact itself; without one the rule's failure is taken as possible
    (true), which over-approximates as the relaxation may.
    """
    ids = table.ids  # looked up, never extended: ``final`` covers the facts numbered so far
    complement: dict[int, int] = {}
    for f in negated:
        if f in ids and nf(f) in ids:
            complement[ids[f]] = ids[nf(f)]
            complement[ids[nf(f)]] = ids[f]
    for f in negated_derived:
        if f in ids and nf(f) in ids:
            complement[ids[f]] = ids[nf(f)]
    by_head: dict[int, list[tuple[frozenset[int], frozenset[int]]]] = {}
    for pre, head, naf, _ in rules:
        by_head.setdefault(head, []).append((pre, naf))
    out: set[tuple[int, tuple[int, ...]]] = set()
    not_heads = {ids[nf(f)] for f in negated_derived if nf(f) in ids}
    for pre, head, naf, _ in rules:
        if head in not_heads:
            continue
        body = [final[x] for x in pre] + [final[complement[x]] if x in complement else -2 for x in naf]
        body = [x for x in body if x != -2]  # no not@ fact: left out (true), as the relaxation may
        if all(x >= 0 for x in body):
            out.add((final[head], tuple(sorted(set(body)))))
    for f in sorted(negated_derived):
        head = final[ids[nf(f)]]
        if head < 0:
            continue
        clauses: list[frozenset[int]] = [frozenset()]
        for pre, naf in by_head.get(ids.get(f, -1), []):
            options = [complement.get(x) for x in pre] + list(naf)
            if any(o is None for o in options):
                continue  # this rule may fail in ways the task has no fact for: over-approximate
            clauses = [c | {o} for c in clauses for o in options if o is not None]
            if len(clauses) > MAX_NEGATED_CLAUSES:
                clauses = [frozenset()]
                break
        for clause in clauses:
            body = [final[x] for x in clause]
            if all(i >= 0 for i in body):
                out.add((head, tuple(sorted(body))))
    return tuple(sorted(out))


def _build_positive(
    problem: Problem, fix: Fixpoint, init: set[GroundAtom], goal_facts: list[GroundAtom], reason: str | None
) -> GroundTask:
    """The task when no action has a negative precondition or a when-effect and no goal is negated.

    Then the fixpoint's relaxed exploration is exact: every action it found is reachable,
    and the reached facts are the initial fluent facts and the actions' adds.
    """
    reached = set(init)
    for action in fix.actions:
        reached.update(action.add)
    missing = [f for f in goal_facts if f not in reached]
    if reason is None and missing:
        reason = f"goal fact {fact_text(missing[0])} is not reachable even ignoring deletes"
    text_of = {f: fact_text(f) for f in reached}
    text_of.update((f, fact_text(f)) for f in missing)
    names = sorted(set(text_of.values()))
    ids = {text: i for i, text in enumerate(names)}
    final = {f: ids[text_of[f]] for f in reached}

    def ids_of(facts: tuple[GroundAtom, ...]) -> tuple[int, ...]:
        if len(facts) == 1:
            return (final[facts[0]],)
        return tuple(sorted({final[f] for f in facts}))

    operators: dict[tuple, GroundOperator] = {}
    for k, action in enumerate(fix.actions, 1):
        if not k % CHECK_EVERY:
            fix.check()
        name = "(" + " ".join((action.action, *action.args)) + ")"
        add_ids = ids_of(action.add)  # an action's adds are reached, and so are its preconditions
        pre_ids = ids_of(action.pos)
        delete = action.delete
        del_ids: tuple[int, ...]
        if len(delete) == 1:
            i = final.get(delete[0])
            del_ids = () if i is None or i in add_ids else (i,)
        else:
            del_ids = tuple(sorted({final[f] for f in delete if f in final}.difference(add_ids)))
        key = (name, pre_ids, add_ids, del_ids, action.cost, ())
        if key not in operators:
            operators[key] = GroundOperator(name, action.action, action.args, pre_ids, add_ids, del_ids, action.cost)
    return GroundTask(
        problem.name,
        tuple(names),
        frozenset(final[f] for f in init),
        tuple(sorted({ids[text_of[f]] for f in goal_facts})),
        _ordered(operators),
        fix.has_costs,
        reason,
    )


def _ordered(operators: dict[tuple, GroundOperator]) -> tuple[GroundOperator, ...]:
    """The operators by name, pre, add and delete (stable: ties in the order found)."""
    return tuple(operators[k] for k in sorted(operators, key=_FIRST_FOUR))


_FIRST_FOUR = itemgetter(slice(0, 4))


class _Facts:
    """Ground atoms numbered in the order first seen (ids local to one grounding)."""

    __slots__ = ("ids",)

    def __init__(self) -> None:
        self.ids: dict[GroundAtom, int] = {}

    @property
    def facts(self) -> list[GroundAtom]:
        """The facts by id."""
        return list(self.ids)

    def id(self, fact: GroundAtom) -> int:
        """The id of ``fact`` (a new one the first time)."""
        ids = self.ids
        return ids.setdefault(fact, len(ids))

    def ids_of(self, facts: set[GroundAtom] | frozenset[GroundAtom]) -> frozenset[int]:
        """The ids of ``facts``."""
        ids = self.ids
        new = ids.setdefault
        return frozenset([new(f, len(ids)) for f in facts])


Compiled = tuple[
    frozenset[int], frozenset[int], frozenset[int], tuple[tuple[frozenset[int], frozenset[int], frozenset[int]], ...]
]
"""Pre, add, delete (minus add) and the when-effects (condition, add, delete) of one action, over local fact ids."""


def _operators(kept: list[tuple[GroundAction, Compiled]], final: list[int]) -> tuple[GroundOperator, ...]:
    """The ground operators in their fixed order, duplicates dropped, over the final fact ids.

    ``final`` maps a local fact id to its id in the task, -1 for a fact never reached; the
    preconditions and adds of an action that fires are all reached.
    """
    operators: dict[tuple, GroundOperator] = {}
    for action, (pre, add, delete, conditional) in kept:
        cond = []
        for c_pre, c_add, c_del in conditional:
            if any(final[f] < 0 for f in c_pre):
                continue
            c_add_ids = tuple(sorted([final[i] for i in c_add if final[i] >= 0]))
            c_del_ids = tuple(sorted([final[i] for i in c_del - c_add if final[i] >= 0]))
            if c_add_ids or c_del_ids:
                cond.append((tuple(sorted([final[i] for i in c_pre])), c_add_ids, c_del_ids))
        name = fact_text((action.action, *action.args))
        pre_ids = tuple(sorted([final[i] for i in pre]))
        add_ids = tuple(sorted([final[i] for i in add]))
        del_ids = tuple(sorted([final[i] for i in delete if final[i] >= 0]))
        conds = tuple(sorted(set(cond))) if cond else ()
        key = (name, pre_ids, add_ids, del_ids, action.cost, conds)
        if key not in operators:
            operators[key] = GroundOperator(
                name, action.action, action.args, pre_ids, add_ids, del_ids, action.cost, conds
            )
    return _ordered(operators)


def _compile(
    action: GroundAction, negated: set[GroundAtom], nf: Callable[[GroundAtom], GroundAtom], table: _Facts
) -> Compiled:
    """Pre, add, delete and conditional effects with ``not-`` facts kept up to date, as local fact ids."""
    if not negated and not action.neg and not action.conditional:  # the common case: nothing to keep up to date
        ids = table.ids
        new = ids.setdefault
        add_ids = frozenset([new(f, len(ids)) for f in action.add])
        pre_ids = frozenset([new(f, len(ids)) for f in action.pos])
        return pre_ids, add_ids, frozenset([new(f, len(ids)) for f in action.delete]) - add_ids, ()
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
                f"cannot compile the negative precondition on {fact_text(min(clash))}: "
                f"action {fact_text((action.action, *action.args))} both adds and deletes it under different conditions"
            )
        c_pre = set(c_pos) | {nf(f) for f in c_neg}
        extra_add = {nf(f) for f in c_del & negated}
        extra_del = {nf(f) for f in c_add & negated}
        conditional.append((table.ids_of(c_pre), table.ids_of(c_add | extra_add), table.ids_of(c_del | extra_del)))
    return table.ids_of(pre), table.ids_of(add), table.ids_of(delete - add), tuple(conditional)


def _reachable(n_facts: int, init: set[int], compiled: list[Compiled]) -> tuple[list[bool], list[int]]:
    """Relaxed reachability over the ground actions (counting unmet preconditions).

    Returns:
        Per local fact id whether it is reached, and the indexes of the actions that fire (increasing).
    """
    reached = [False] * n_facts
    fired = [False] * len(compiled)
    # A record: [unmet count, facts it adds, action index or -1 for a when-effect].
    waiting: list[list[list]] = [[] for _ in range(n_facts)]
    effects_of: list[list[list]] = [[] for _ in compiled]
    stack: list[int] = sorted(init)
    ready: list[list] = []
    for index, (pre, add, _delete, conditional) in enumerate(compiled):
        record = [len(pre), add, index]
        for fact in pre:
            waiting[fact].append(record)
        if not pre:
            ready.append(record)
        for c_pre, c_add, _ in conditional:
            effect = [len(c_pre) + 1, c_add, -1]  # + 1: the action itself must fire
            effects_of[index].append(effect)
            for fact in c_pre:
                waiting[fact].append(effect)
    while stack or ready:
        while ready:
            _, add, index = ready.pop()
            stack.extend(add)
            if index >= 0:
                fired[index] = True
                for effect in effects_of[index]:
                    effect[0] -= 1
                    if effect[0] == 0:
                        ready.append(effect)
        while stack:
            fact = stack.pop()
            if reached[fact]:
                continue
            reached[fact] = True
            for waiter in waiting[fact]:
                waiter[0] -= 1
                if waiter[0] == 0:
                    ready.append(waiter)
    return reached, [i for i, ok in enumerate(fired) if ok]
