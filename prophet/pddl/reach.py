"""The relaxed-reachability fixpoint over lifted actions, used by :func:`alica.prophet.ground.ground`.

Each action precondition is put in DNF (one schema per conjunction). Facts
are processed in order; a new fact is unified with every precondition atom
of its predicate and then joined with the facts processed before it, the
atom with the most bound arguments first, through hash indexes on the bound
positions (built on first use and kept up to date). Negative preconditions on
changing predicates count as true here (an over-approximation the ground
pass of :mod:`alica.prophet.ground` tightens).

With :class:`~alica.prophet.planner.Limits`, the fixpoint counts its work (facts
taken, joins, ground actions) and every :data:`CHECK_EVERY` steps checks the
deadline and the estimated size of what it grounded so far
(:data:`BYTES_PER_ACTION`, :data:`BYTES_PER_FACT`), before allocating more.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from operator import itemgetter

from alica.prophet.pddl.adl import GOAL_PREDICATE, Compiler, strata
from alica.prophet.pddl.errors import PddlError
from alica.prophet.pddl.model import (
    OBJECT,
    Action,
    And,
    Atom,
    Domain,
    Effect,
    Equals,
    FluentTerm,
    FluentValue,
    Forall,
    Formula,
    Not,
    Or,
    Problem,
    TypedName,
    When,
)
from alica.prophet.pddl.normal import TOO_MANY, Clause, EffectItem, dnf, expand, flatten_effect
from alica.prophet.planner import Limits
from alica.source import SourceSpan

CHECK_EVERY = 4096
"""Steps of the fixpoint between two checks of the limits."""
BYTES_PER_ACTION = 2048
"""The memory estimate per ground action, to the end of the grounding (measured: about 1,800 bytes)."""
BYTES_PER_FACT = 256
"""The memory estimate per reached fact."""
FREE_SHARE = 0.35
"""Freeing an abandoned grounding takes about this share of the time spent building it (measured 0.2-0.3):
the deadline check keeps that much time in reserve."""

#: A grounded PDDL atom as a flat tuple ``(predicate, *objects)``: a node of the grounding, not a
#: :class:`alica.lang.fact.Fact` of the world model (flat tuples keep the grounding fast).
GroundAtom = tuple[str, ...]
Arg = int | str
"""A parameter slot (int) or an object name (str)."""


def _getter(slots: tuple[int, ...]) -> Callable[[Sequence[str | None]], tuple]:
    """A function picking ``slots`` out of a sequence, as a tuple."""
    if not slots:
        return lambda _: ()
    if len(slots) == 1:
        only = slots[0]
        return lambda seq: (seq[only],)
    return itemgetter(*slots)


def fact_text(fact: GroundAtom) -> str:
    """``("on", "a", "b")`` as ``(on a b)``."""
    return f"({' '.join(fact)})"


@dataclass(frozen=True, slots=True)
class GroundAction:
    """A reachable ground action over fact tuples (before fact ids are given).

    Attributes:
        action: the action name.
        args: the arguments.
        pos: positive preconditions on changing predicates.
        neg: negative preconditions on changing predicates.
        add: unconditional adds.
        delete: unconditional deletes.
        conditional: ``(positive condition, negative condition, add, delete)`` per condition.
        cost: the cost.
    """

    action: str
    args: tuple[str, ...]
    pos: tuple[GroundAtom, ...]
    neg: tuple[GroundAtom, ...]
    add: tuple[GroundAtom, ...]
    delete: tuple[GroundAtom, ...]
    conditional: tuple[
        tuple[tuple[GroundAtom, ...], tuple[GroundAtom, ...], tuple[GroundAtom, ...], tuple[GroundAtom, ...]], ...
    ]
    cost: int


@dataclass(frozen=True, slots=True)
class GroundRule:
    """A reachable ground rule of a derived predicate: ``head`` holds when ``pos`` hold and ``neg`` do not.

    Attributes:
        head: the derived fact.
        pos: positive body facts on changing (or derived) predicates.
        neg: negated body facts on changing (or derived) predicates.
        layer: the stratum of the head's predicate (negated derived body facts are of lower strata).
    """

    head: GroundAtom
    pos: tuple[GroundAtom, ...]
    neg: tuple[GroundAtom, ...]
    layer: int


CompiledAtom = tuple[str, tuple[Arg, ...]]


@dataclass(slots=True)
class _Schema:
    """One conjunction of an action's precondition, with slots for the parameters."""

    action: str
    params: tuple[str, ...]
    allowed: tuple[frozenset[str] | None, ...]
    pools: tuple[tuple[str, ...], ...]
    pos: tuple[CompiledAtom, ...]
    neg: tuple[CompiledAtom, ...]
    eqs: tuple[tuple[bool, Arg, Arg], ...]
    effects: tuple[tuple[tuple[tuple[tuple[bool, str, tuple[Arg, ...]], ...], ...] | None, bool, CompiledAtom], ...]
    costs: tuple[int | float | tuple[str, tuple[Arg, ...]], ...]
    plans: tuple[tuple, ...] = ()
    fast: tuple = ()
    n_args: int = -1
    """How many of ``params`` are the action's (the rest come from an ``exists``); -1: all."""
    axiom: bool = False
    """Whether this is the rule of a derived predicate (its one effect adds the head)."""


class Fixpoint:
    """The reachable ground actions of a problem (see the module docstring).

    Derived predicates (the domain's ``:derived`` rules and those that
    :mod:`alica.prophet.pddl.adl` makes for conditions too large to multiply
    out) are grounded as rule schemas whose one effect adds the head: they are
    kept apart from the actions in :attr:`rules`.

    Attributes:
        fluent: predicates some action changes, and the derived ones (the others are static).
        derived: the derived predicates (the domain's and the generated ones).
        layer: per derived predicate, its stratum.
        init: the initial facts.
        actions: the reachable ground actions, in the order found.
        rules: the reachable ground rules of derived predicates.
        goal_literals: the goal as one conjunction of literals (a goal that is no conjunction
            is the derived atom ``(goal@)``).
        goal_reason: why the goal is false in every state (else None).
        has_costs: whether some action increases total-cost.
    """

    def __init__(self, domain: Domain, problem: Problem, limits: Limits | None = None) -> None:
        self._limits = limits
        self._work = 0
        self._started = limits.clock() if limits is not None else 0.0
        self.objects: dict[str, str] = {}
        for name, kind in (*domain.constants, *problem.objects):
            if kind != OBJECT and kind not in domain.types:
                raise PddlError(f"object '{name}' has type '{kind}', which domain '{domain.name}' does not declare")
            self.objects[name] = kind
        self._domain = domain
        self._types: dict[str, tuple[str, ...]] = {}
        self.init: set[GroundAtom] = set()
        self._init_order: list[GroundAtom] = []
        self.values: dict[GroundAtom, int | float] = {}
        predicates = {p.name: p.arity for p in domain.predicates}
        for item in problem.init:
            if isinstance(item, FluentValue):
                self.values[(item.fluent.function, *item.fluent.args)] = item.value
                continue
            if predicates.get(item.predicate) != len(item.args):
                raise PddlError(f"initial fact {item} does not match a predicate of domain '{domain.name}'")
            fact = (item.predicate, *item.args)
            if fact not in self.init:
                self.init.add(fact)
                self._init_order.append(fact)
        self._init_predicates = {f[0] for f in self._init_order}
        compiler = Compiler(self.objects_of)
        for axiom in domain.axioms:
            compiler.add_rules(axiom.predicate, axiom.parameters, axiom.body, f"'{axiom.predicate}'", axiom.span)
        effects = {a.name: self._conditions(a, a.effect, dict(a.parameters), compiler) for a in domain.actions}
        flat = {a.name: self._flatten(a, effects[a.name]) for a in domain.actions}
        self.fluent = {item.atom.predicate for items, _ in flat.values() for item in items}
        self.has_costs = any(costs for _, costs in flat.values())
        preconditions = {a.name: self._precondition(a, compiler) for a in domain.actions}
        self.fluent |= domain.derived | set(compiler.arity)
        self.goal_literals, self.goal_reason = self._goal(problem.goal, compiler)
        self.derived = set(domain.derived) | set(compiler.arity) | {r.predicate for r in compiler.rules}
        self.derived |= {
            a.predicate for _, a in self.goal_literals if isinstance(a, Atom) and a.predicate == GOAL_PREDICATE
        }
        self.fluent |= self.derived
        self.layer = strata(compiler.rules, self.derived, compiler.origin)
        self._schemas: list[_Schema] = []
        for action in domain.actions:
            for extra, clause in preconditions[action.name]:
                schema = self._schema(action.name, action.parameters + extra, clause, *flat[action.name])
                if schema is not None:
                    schema.n_args = len(action.parameters)
                    self._schemas.append(schema)
        for rule in compiler.rules:
            head = [EffectItem(None, True, Atom(rule.predicate, rule.head))]
            schema = self._schema(rule.predicate, rule.parameters, rule.clause, head, [])
            if schema is not None:
                schema.axiom = True
                self._schemas.append(schema)
        self.rules: list[GroundRule] = []
        self._rule_seen: set[tuple] = set()
        self.actions: list[GroundAction] = []
        self._seen: set[tuple] = set()
        self._reached: set[GroundAtom] = set()
        self._queue: deque[GroundAtom] = deque()
        self._watch: dict[GroundAtom, list[list]] = {}
        self._known: dict[str, list[tuple[str, ...]]] = {}
        self._known_sets: dict[str, set[tuple[str, ...]]] = {}
        self._stats: dict[str, tuple[int, list[int]]] = {}
        self._tables: dict[str, dict[tuple[int, ...], dict]] = {}
        self._index: dict[str, list[tuple[Callable, dict]]] = {}
        self._triggers: dict[str, list[tuple[_Schema, int]]] = {}
        for schema in self._schemas:
            for i, (pred, _) in enumerate(schema.pos):
                self._triggers.setdefault(pred, []).append((schema, i))

    def _flatten(self, action: Action, effect: Effect) -> tuple[list[EffectItem], list]:
        """The effect flattened (:func:`flatten_effect`); a refusal names the action's place."""
        try:
            return flatten_effect(effect, self.objects_of)
        except PddlError as exc:
            if exc.span is not None:
                raise
            raise PddlError(f"the effect of action '{action.name}': {exc.message}", action.span) from None

    def _precondition(self, action: Action, compiler: Compiler) -> list[tuple[tuple[TypedName, ...], Clause]]:
        """The precondition's conjunctions (with the variables of an ``exists`` each adds, if lifted).

        Multiplied out as it is while that stays small; else through derived predicates.
        """
        try:
            return [((), c) for c in dnf(expand(action.precondition, self.objects_of))]
        except PddlError as exc:
            if exc.span is not None:
                raise
            if exc.message != TOO_MANY:
                raise PddlError(f"the precondition of action '{action.name}': {exc.message}", action.span) from None
        return compiler.clauses(
            action.precondition, action.parameters, f"action '{action.name}'", action.span, lift=True
        )

    def _conditions(self, action: Action, effect: Effect, scope: dict[str, str], compiler: Compiler) -> Effect:
        """``effect`` with every ``when`` condition too large to multiply out written over derived predicates."""
        if isinstance(effect, And):
            return And(tuple(self._conditions(action, p, scope, compiler) for p in effect.parts))  # type: ignore[arg-type]
        if isinstance(effect, Forall):
            inner = {**scope, **dict(effect.variables)}
            return Forall(effect.variables, self._conditions(action, effect.body, inner, compiler))  # type: ignore[arg-type]
        if isinstance(effect, When):
            body = self._conditions(action, effect.effect, scope, compiler)
            try:
                dnf(expand(effect.condition, self.objects_of))
                return When(effect.condition, body)
            except PddlError as exc:
                if exc.span is not None or exc.message != TOO_MANY:
                    raise
            clauses = compiler.clauses(
                effect.condition, tuple(scope.items()), f"action '{action.name}'", action.span, lift=False
            )
            condition: Formula = Or(
                tuple(And(tuple(a if positive else Not(a) for positive, a in clause)) for _, clause in clauses)
            )
            return When(condition, body)
        return effect

    def _goal(self, goal: Formula, compiler: Compiler) -> tuple[Clause, str | None]:
        """The goal as one conjunction: multiplied out if that gives one possible conjunction, else ``(goal@)``."""
        try:
            clauses = [c for c in dnf(expand(goal, self.objects_of)) if self.clause_possible(c)]
        except PddlError as exc:
            if exc.span is not None or exc.message != TOO_MANY:
                raise
            clauses = [(), ()]  # too many: the derived goal below
        if not clauses:
            return (), "the goal is false in every state (static facts or equalities)"
        if len(clauses) == 1:
            return clauses[0], None
        compiler.add_rules(GOAL_PREDICATE, (), goal, "the goal", None)
        return ((True, Atom(GOAL_PREDICATE, ())),), None

    def objects_of(self, kind: str) -> list[str]:
        """The objects of type ``kind`` or below it, in declaration order."""
        if kind not in self._types:
            is_sub = self._domain.is_subtype
            self._types[kind] = tuple(o for o, t in self.objects.items() if kind == OBJECT or is_sub(t, kind))
        return list(self._types[kind])

    def clause_possible(self, clause: Clause) -> bool:
        """Whether the static and equality literals of a ground clause hold."""
        for positive, atom in clause:
            if isinstance(atom, Equals):
                if (atom.left == atom.right) != positive:
                    return False
            elif (
                atom.predicate not in self.fluent
                and atom.predicate not in self._domain.derived
                and (((atom.predicate, *atom.args) in self.init) != positive)
            ):
                return False
        return True

    def _schema(self, name, parameters, clause, items, costs) -> _Schema | None:  # type: ignore[no-untyped-def]
        slots = {p: i for i, (p, _) in enumerate(parameters)}

        def arg(a: str) -> Arg:
            return slots.get(a, a)

        def atom(a: Atom) -> CompiledAtom:
            return (a.predicate, tuple(arg(x) for x in a.args))

        pos, neg, eqs = [], [], []
        for positive, lit in clause:
            if isinstance(lit, Equals):
                eqs.append((positive, arg(lit.left), arg(lit.right)))
            elif positive:
                if lit.predicate not in self.fluent and lit.predicate not in self._init_predicates:
                    return None
                pos.append(atom(lit))
            else:
                neg.append(atom(lit))
        effects = []
        for item in items:
            cond = None
            if item.condition is not None:
                cond = tuple(
                    tuple(
                        (
                            p,
                            lit.predicate if isinstance(lit, Atom) else "=",
                            (arg(lit.left), arg(lit.right))
                            if isinstance(lit, Equals)
                            else tuple(arg(x) for x in lit.args),
                        )
                        for p, lit in c
                    )
                    for c in item.condition
                )
            effects.append((cond, item.positive, atom(item.atom)))
        compiled_costs = tuple(
            (c.function, tuple(arg(x) for x in c.args)) if isinstance(c, FluentTerm) else c for c in costs
        )
        kinds = [k for _, k in parameters]
        schema = _Schema(
            name,
            tuple(p for p, _ in parameters),
            tuple(None if k == OBJECT else frozenset(self.objects_of(k)) for k in kinds),
            tuple(tuple(self.objects_of(k)) for k in kinds),
            tuple(pos),
            tuple(neg),
            tuple(eqs),
            tuple(effects),
            compiled_costs,
        )
        return schema

    def _plan(self, schema: _Schema, first: int) -> tuple:
        """The join program after unifying a new fact with atom ``first``.

        Object names in atoms get slots after the parameters (filled in the
        template), so every argument is a slot. Returns the template, the
        trigger's (position, slot) pairs, the checks the trigger alone makes
        possible, the join steps ``(table, key, binds, repeats, checks)`` and the
        parameters no positive atom binds.
        """
        consts: dict[str, int] = {}
        nparams = len(schema.params)

        def slot(a: Arg) -> int:
            if isinstance(a, int):
                return a
            return consts.setdefault(a, nparams + len(consts))

        atoms = [(pred, tuple(slot(a) for a in args)) for pred, args in schema.pos]
        template: list[str | None] = [None] * (nparams + len(consts))
        for name, index in consts.items():
            template[index] = name
        bound = set(range(nparams, len(template)))
        trigger = tuple(enumerate(atoms[first][1]))
        bound |= set(atoms[first][1])
        remaining = [i for i in range(len(atoms)) if i != first]

        def take_checks() -> tuple:
            done = [i for i in remaining if all(a in bound for a in atoms[i][1])]
            for i in done:
                remaining.remove(i)
            return tuple((self._known_set(atoms[i][0]), _getter(atoms[i][1])) for i in done)

        first_checks = take_checks()
        steps = []
        while remaining:
            best = min(remaining, key=lambda i: (self._estimate(schema, atoms[i], bound), i))
            remaining.remove(best)
            pred, args = atoms[best]
            positions = tuple(p for p, a in enumerate(args) if a in bound)
            key_slots = tuple(a for a in args if a in bound)
            binds, repeats, fresh = [], [], set()
            for pos, a in enumerate(args):
                if a in bound:
                    continue
                if a in fresh:
                    repeats.append((pos, a))
                else:
                    fresh.add(a)
                    binds.append((pos, a, schema.allowed[a]))
            bound |= fresh
            table = self._table(pred, positions) if positions else self._known.setdefault(pred, [])
            steps.append(
                (table, _getter(key_slots) if positions else None, tuple(binds), tuple(repeats), take_checks())
            )
        unbound = tuple(i for i in range(nparams) if i not in bound)
        return template, trigger, first_checks, tuple(steps), unbound

    def _estimate(self, schema: _Schema, atom: tuple[str, tuple[int, ...]], bound: set[int]) -> float:
        """How many facts an atom may match once ``bound`` slots are known (static: from :init)."""
        pred, args = atom
        if pred not in self.fluent:
            size, distinct = self._static_stats(pred)
            estimate = float(size)
            for pos, a in enumerate(args):
                if a in bound:
                    estimate /= max(distinct[pos], 1)
            return estimate
        estimate = 1.0
        for a in args:
            if a not in bound:
                estimate *= len(schema.pools[a]) if a < len(schema.pools) else 1
        return estimate * 4.0

    def _static_stats(self, pred: str) -> tuple[int, list[int]]:
        if pred not in self._stats:
            facts = [f[1:] for f in self._init_order if f[0] == pred]
            arity = len(facts[0]) if facts else 0
            self._stats[pred] = (len(facts), [len({f[p] for f in facts}) for p in range(arity)])
        return self._stats[pred]

    def estimate_bytes(self) -> int:
        """The estimated memory of the grounding so far (see :data:`BYTES_PER_ACTION`)."""
        return (len(self.actions) + len(self.rules) // 2) * BYTES_PER_ACTION + len(self._reached) * BYTES_PER_FACT

    def check(self) -> None:
        """Check the limits (if any) now.

        Raises:
            LimitReached: past the deadline, or the estimate passes the memory bound.
        """
        limits = self._limits
        if limits is not None:
            limits.check(
                "grounding",
                self.estimate_bytes(),
                f"{len(self.actions)} ground actions, "
                + (f"{len(self.rules)} ground rules, " if self.rules else "")
                + f"{len(self._reached)} facts so far",
                FREE_SHARE * (limits.clock() - self._started),
            )

    def run(self) -> None:
        """Find every reachable ground action.

        Raises:
            LimitReached: a limit was reached (see the module docstring).
        """
        limited = self._limits is not None
        self.check()
        for schema in self._schemas:
            schema.plans = tuple(self._plan(schema, i) for i in range(len(schema.pos)))
        for fact in self._init_order:
            self._reach(fact)
        for schema in self._schemas:
            if not schema.pos:
                self._finish(schema, [None] * len(schema.params), tuple(range(len(schema.params))))
        while self._queue:
            if limited:
                self._work += 1
                if not self._work % CHECK_EVERY:
                    self.check()
            fact = self._queue.popleft()
            pred, args = fact[0], fact[1:]
            self._known.setdefault(pred, []).append(args)
            self._known_sets.setdefault(pred, set()).add(args)
            for getter, table in self._index.get(pred, ()):
                key = getter(args)
                if key in table:
                    table[key].append(args)
                else:
                    table[key] = [args]
            for schema, first in self._triggers.get(pred, ()):
                template, trigger, checks, steps, unbound = schema.plans[first]
                binding = list(template)
                ok = True
                for pos, slot in trigger:
                    value = args[pos]
                    if binding[slot] is None:
                        allowed = schema.allowed[slot]
                        if allowed is not None and value not in allowed:
                            ok = False
                            break
                        binding[slot] = value
                    elif binding[slot] != value:
                        ok = False
                        break
                if ok and all(getter(binding) in known for known, getter in checks):
                    self._join(schema, steps, 0, binding, unbound)

    def _reach(self, fact: GroundAtom) -> None:
        if fact in self._reached:
            return
        self._reached.add(fact)
        self._queue.append(fact)
        for record in self._watch.pop(fact, ()):
            record[0] -= 1
            if record[0] == 0:
                for add in record[1]:
                    self._reach(add)

    def _known_set(self, pred: str) -> set[tuple[str, ...]]:
        return self._known_sets.setdefault(pred, set())

    def _table(self, pred: str, positions: tuple[int, ...]) -> dict[tuple[str, ...], list[tuple[str, ...]]]:
        tables = self._tables.setdefault(pred, {})
        if positions not in tables:
            tables[positions] = {}
            self._index.setdefault(pred, []).append((_getter(positions), tables[positions]))
        return tables[positions]

    def _join(self, schema: _Schema, steps: tuple, k: int, binding: list, unbound: tuple[int, ...]) -> None:
        if self._limits is not None:
            self._work += 1
            if not self._work % CHECK_EVERY:
                self.check()
        if k == len(steps):
            self._finish(schema, binding, unbound)
            return
        table, key, binds, repeats, checks = steps[k]
        candidates = table.get(key(binding), ()) if key is not None else table
        last = k + 1 == len(steps)
        for args in candidates:
            ok = True
            for pos, slot, allowed in binds:
                value = args[pos]
                if allowed is not None and value not in allowed:
                    ok = False
                    break
                binding[slot] = value
            if not ok:
                continue
            if repeats and any(args[pos] != binding[slot] for pos, slot in repeats):
                continue
            if checks and not all(getter(binding) in known for known, getter in checks):
                continue
            if last:
                self._finish(schema, binding, unbound)
            else:
                self._join(schema, steps, k + 1, binding, unbound)
        for _, slot, _ in binds:
            binding[slot] = None

    def _finish(self, schema: _Schema, binding: list, unbound: tuple[int, ...]) -> None:
        if not unbound:
            self._emit(schema, tuple(binding[: len(schema.params)]))
            return
        pools = [schema.pools[i] for i in unbound]
        limited = self._limits is not None
        for combo in itertools.product(*pools):
            if limited:
                self._work += 1
                if not self._work % CHECK_EVERY:
                    self.check()
            full = binding[: len(schema.params)]
            for slot, value in zip(unbound, combo, strict=True):
                full[slot] = value
            self._emit(schema, tuple(full))

    def _fast(self, schema: _Schema) -> tuple:
        """Atoms as (predicate, getter over args + constants) for :meth:`_emit`."""
        if schema.fast:
            return schema.fast
        consts: dict[str, int] = {}
        nparams = len(schema.params)

        def compiled(pred: str, spec: tuple[Arg, ...]) -> tuple[str, Callable]:
            idx = tuple(a if isinstance(a, int) else consts.setdefault(a, nparams + len(consts)) for a in spec)
            return pred, _getter(idx)

        pos = tuple(compiled(p, s) for p, s in schema.pos if p in self.fluent)
        neg = tuple((p in self.fluent, *compiled(p, s)) for p, s in schema.neg)
        plain = tuple((positive, *compiled(p, s)) for cond, positive, (p, s) in schema.effects if cond is None)
        schema.fast = (tuple(consts), pos, neg, plain)
        return schema.fast

    def _emit(self, schema: _Schema, args: tuple[str, ...]) -> None:
        def value(a: Arg) -> str:
            return args[a] if isinstance(a, int) else a

        for positive, left, right in schema.eqs:
            if (value(left) == value(right)) != positive:
                return
        key = (id(schema), args)
        if key in self._seen:
            return
        consts, fast_pos, fast_neg, plain = self._fast(schema)
        ext = args + consts if consts else args
        neg = []
        for fluent, pred, getter in fast_neg:
            fact = (pred, *getter(ext))
            if fluent:
                neg.append(fact)
            elif fact in self.init:
                return
        self._seen.add(key)
        pos = [(pred, *getter(ext)) for pred, getter in fast_pos]
        if schema.axiom:
            head = (plain[0][1], *plain[0][2](ext))
            rule = (head, tuple(pos), tuple(neg))
            if rule not in self._rule_seen:
                self._rule_seen.add(rule)
                self.rules.append(GroundRule(head, rule[1], rule[2], self.layer[head[0]]))
            self._reach(head)
            return
        add: list[GroundAtom] = []
        delete: list[GroundAtom] = []
        for positive, pred, getter in plain:
            (add if positive else delete).append((pred, *getter(ext)))
        conditional: dict[
            tuple[tuple[GroundAtom, ...], tuple[GroundAtom, ...]], tuple[list[GroundAtom], list[GroundAtom]]
        ] = {}
        for cond, positive, (pred, spec) in schema.effects:
            if cond is None:
                continue
            fact = (pred, *(value(a) for a in spec))
            for condition in self._ground_condition(cond, value):
                if condition == ((), ()):
                    (add if positive else delete).append(fact)
                else:
                    entry = conditional.setdefault(condition, ([], []))
                    entry[0 if positive else 1].append(fact)
        cost = self._cost(schema, value)
        action = GroundAction(
            schema.action,
            args if schema.n_args < 0 else args[: schema.n_args],
            tuple(pos),
            tuple(neg),
            tuple(add),
            tuple(delete),
            tuple((c[0], c[1], tuple(e[0]), tuple(e[1])) for c, e in conditional.items()),
            cost,
        )
        self.actions.append(action)
        if self._limits is not None:
            self._work += 1
            if not self._work % CHECK_EVERY:
                self.check()
        for fact in add:
            self._reach(fact)
        for (c_pos, _), (c_add, _) in conditional.items():
            if not c_add:
                continue
            missing = [f for f in set(c_pos) if f not in self._reached]
            if not missing:
                for fact in c_add:
                    self._reach(fact)
            else:
                record = [len(missing), c_add]
                for fact in missing:
                    self._watch.setdefault(fact, []).append(record)

    def _ground_condition(self, cond, value) -> list[tuple[tuple[GroundAtom, ...], tuple[GroundAtom, ...]]]:  # type: ignore[no-untyped-def]
        out = []
        for clause in cond:
            c_pos: list[GroundAtom] = []
            c_neg: list[GroundAtom] = []
            possible = True
            for positive, pred, spec in clause:
                if pred == "=":
                    if (value(spec[0]) == value(spec[1])) != positive:
                        possible = False
                        break
                    continue
                fact = (pred, *(value(a) for a in spec))
                if pred not in self.fluent:
                    if (fact in self.init) != positive:
                        possible = False
                        break
                    continue
                (c_pos if positive else c_neg).append(fact)
            if possible:
                out.append((tuple(sorted(set(c_pos))), tuple(sorted(set(c_neg)))))
        return out

    def _span(self, action: str) -> SourceSpan | None:
        found = self._domain.action(action)
        return found.span if found is not None else None

    def _cost(self, schema: _Schema, value) -> int:  # type: ignore[no-untyped-def]
        if not self.has_costs:
            return 1
        total: int | float = 0
        for cost in schema.costs:
            if isinstance(cost, tuple):
                fluent = (cost[0], *(value(a) for a in cost[1]))
                if fluent not in self.values:
                    raise PddlError(
                        f"action {schema.action}: fluent {fact_text(fluent)} has no value in :init",
                        self._span(schema.action),
                    )
                amount = self.values[fluent]
            else:
                amount = cost
            if amount < 0 or amount != int(amount):
                raise PddlError(
                    f"action {schema.action}: cost {amount} is not a non-negative integer", self._span(schema.action)
                )
            total += amount
        return int(total)
