"""Plan validation: simulate a plan from the initial state and check every step and the goal.

On a (domain, problem) pair the plan is checked at the lifted level (action
names, argument types, preconditions as formulas, conditional effects, costs
read from ``:init``); on a :class:`alica.prophet.ground.GroundTask` it is checked on
the ground operators.

Derived predicates are evaluated at the lifted level too: in each state, the
derived atoms are the stratified least fixpoint of the ``:derived`` rules over
the state's basic atoms (stratum by stratum, each rule's body read as a
formula, repeated until nothing more holds).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from alica.prophet.ground import GroundTask
from alica.prophet.pddl.adl import free_variables, nnf
from alica.prophet.pddl.model import (
    OBJECT,
    And,
    Atom,
    Axiom,
    Domain,
    Effect,
    Equals,
    Exists,
    FluentTerm,
    Forall,
    Formula,
    Imply,
    Increase,
    Not,
    Or,
    Problem,
    When,
)
from alica.prophet.pddl.normal import substitute
from alica.prophet.planner import Plan, PlanStep


@dataclass(frozen=True, slots=True)
class ValidationResult:
    """What validating a plan found.

    Attributes:
        valid: whether every step applies and the goal holds at the end.
        cost: the cost of the steps simulated (all of them when valid).
        failed_step: the 1-based number of the failing step (None when valid or when only the goal fails).
        reason: what is wrong (empty when valid).
    """

    valid: bool
    cost: float
    failed_step: int | None
    reason: str


def validate_plan(task: GroundTask | tuple[Domain, Problem], plan: Plan | Sequence[PlanStep]) -> ValidationResult:
    """Check ``plan`` against a ground task or a ``(domain, problem)`` pair.

    Args:
        task: the ground task, or the lifted domain and problem.
        plan: the plan or its steps.

    Returns:
        The result; its reason names the step and the unmet precondition literal.
    """
    steps = tuple(plan.steps) if isinstance(plan, Plan) else tuple(plan)
    if isinstance(task, GroundTask):
        return _validate_ground(task, steps)
    domain, problem = task
    return LiftedSimulation(domain, problem).validate(steps)


def _validate_ground(task: GroundTask, steps: tuple[PlanStep, ...]) -> ValidationResult:
    state = task.init
    cost = 0.0
    for number, step in enumerate(steps, 1):
        name = str(step).lower()
        candidates = task.operator(name)
        if not candidates:
            return ValidationResult(
                False, cost, number, f"step {number} {name}: no such ground operator (unknown or unreachable)"
            )
        op = next((o for o in candidates if task.applicable(state, o)), None)
        if op is None:
            unmet = [task.facts[p] for p in candidates[0].pre if p not in state]
            return ValidationResult(False, cost, number, f"step {number} {name}: precondition {unmet[0]} does not hold")
        state = task.apply(state, op)
        cost += op.cost
    unmet_goal = [task.facts[g] for g in task.goal if g not in state]
    if unmet_goal:
        return ValidationResult(False, cost, None, f"goal {unmet_goal[0]} does not hold after the plan")
    return ValidationResult(True, cost, None, "")


class LiftedSimulation:
    """Lifted simulation: a state is a set of ground atoms."""

    def __init__(self, domain: Domain, problem: Problem) -> None:
        self.domain = domain
        self.objects = dict((*domain.constants, *problem.objects))
        self._pools: dict[str, list[str]] = {}
        self._plans: dict[int, tuple] = {}
        self.problem = problem
        self.values = problem.fluent_values
        self.has_costs = any(isinstance(e, Increase) for a in domain.actions for e in _walk(a.effect))
        self.strata = _strata(domain.axioms, domain.derived)
        self._stratum_plans: dict[int, tuple[list, dict[str, list]]] = {}

    def close(self, state: set[Atom]) -> set[Atom]:
        """``state`` (basic atoms) with the derived atoms that follow from it.

        Stratum by stratum, every rule is tried on every binding of its head once; after that, only
        the bindings a new fact can make true are tried again: those of rules whose body names the
        new fact's predicate, with the head variables that atom shares equal to the fact's arguments
        (within a stratum, derived predicates occur only positively, so facts are only ever added).
        """
        if not self.strata:
            return state
        full = set(state)
        facts: set[tuple[str, ...]] = {(a.predicate, *a.args) for a in state}
        for k, stratum in enumerate(self.strata):
            heads, triggers = self._stratum_plan(k, stratum)
            todo: Sequence[int] = range(len(heads))
            while todo:
                new: list[Atom] = []
                for i in todo:
                    body, binding, head = heads[i]
                    if head not in full and body(binding, facts):
                        full.add(head)
                        facts.add((head.predicate, *head.args))
                        new.append(head)
                again: set[int] = set()
                for fact in new:
                    for positions, index in triggers.get(fact.predicate, ()):
                        again.update(index.get(tuple(fact.args[p] for p in positions), ()))
                todo = sorted(again)
        return full

    def _stratum_plan(self, k: int, stratum: list[Axiom]) -> tuple[list, dict[str, list]]:
        """The stratum's (compiled body, binding, head) triples, and per derived predicate the bindings to try again.

        A trigger is ``(positions, index)``: the argument positions of a body atom that hold head
        variables, and an index from their values to the triples whose head has those values.
        """
        cached = self._stratum_plans.get(k)
        if cached is not None:
            return cached
        heads: list[tuple[_Test, dict[str, str], Atom]] = []
        triggers: dict[str, list[tuple[tuple[int, ...], dict[tuple[str, ...], list[int]]]]] = {}
        names = {a.predicate for a in stratum}
        for axiom in stratum:
            first = len(heads)
            body = self._compile(axiom.body)
            for binding in self.bindings(axiom.parameters):
                heads.append((body, binding, Atom(axiom.predicate, tuple(binding[v] for v, _ in axiom.parameters))))
            variables = {v for v, _ in axiom.parameters}
            for atom in _atoms_with_free(axiom.body, names, variables):
                pairs = [(p, a) for p, a in enumerate(atom.args) if a in variables]
                index: dict[tuple[str, ...], list[int]] = {}
                for i in range(first, len(heads)):
                    binding = heads[i][1]
                    index.setdefault(tuple(binding[a] for _, a in pairs), []).append(i)
                triggers.setdefault(atom.predicate, []).append((tuple(p for p, _ in pairs), index))
        self._stratum_plans[k] = (heads, triggers)
        return heads, triggers

    def _compile(self, formula: Formula) -> _Test:
        """``formula`` as a function of a binding and a set of ``(predicate, *args)`` facts (for :meth:`close`).

        It decides what :meth:`true` decides, without walking the formula on every call.
        """
        if isinstance(formula, Atom):
            predicate, args = formula.predicate, formula.args
            if len(args) == 1 and args[0].startswith("?"):
                only = args[0]
                return lambda env, facts: (predicate, env[only]) in facts
            flags = tuple(a.startswith("?") for a in args)
            return lambda env, facts: (predicate, *[env[a] if v else a for a, v in zip(args, flags)]) in facts
        if isinstance(formula, Equals):
            left, right = formula.left, formula.right
            return lambda env, facts: env.get(left, left) == env.get(right, right)
        if isinstance(formula, Not):
            inner = self._compile(formula.formula)
            return lambda env, facts: not inner(env, facts)
        if isinstance(formula, And | Or):
            parts = tuple(self._compile(p) for p in formula.parts)  # type: ignore[arg-type]
            if isinstance(formula, And):
                return lambda env, facts: all(p(env, facts) for p in parts)
            return lambda env, facts: any(p(env, facts) for p in parts)
        if isinstance(formula, Imply):
            condition, consequence = self._compile(formula.condition), self._compile(formula.consequence)
            return lambda env, facts: not condition(env, facts) or consequence(env, facts)
        if isinstance(formula, Exists | Forall):
            variables, levels = _join_plan(formula)
            names = tuple(v for v, _ in variables)
            pools = tuple(tuple(self.objects_of(t)) for _, t in variables)
            tests = tuple(tuple(self._compile(p) for p in level) for level in levels)
            last = len(names)

            def search(k: int, env: dict[str, str], facts: set[tuple[str, ...]]) -> bool:
                for test in tests[k]:
                    if not test(env, facts):
                        return False
                if k == last:
                    return True
                name = names[k]
                for obj in pools[k]:
                    env[name] = obj
                    if search(k + 1, env, facts):
                        return True
                return False

            if isinstance(formula, Exists):
                return lambda env, facts: search(0, dict(env), facts)
            return lambda env, facts: not search(0, dict(env), facts)
        raise TypeError(f"not a formula: {formula!r}")

    def objects_of(self, kind: str) -> list[str]:
        if kind not in self._pools:
            self._pools[kind] = [
                o for o, t in self.objects.items() if kind == OBJECT or self.domain.is_subtype(t, kind)
            ]
        return self._pools[kind]

    def true(self, formula: Formula, env: dict[str, str], state: set[Atom]) -> bool:
        """Whether ``formula`` holds in ``state`` with its free variables bound as ``env`` says."""
        if isinstance(formula, Atom):
            return Atom(formula.predicate, tuple([env.get(a, a) for a in formula.args])) in state
        if isinstance(formula, Equals):
            return env.get(formula.left, formula.left) == env.get(formula.right, formula.right)
        if isinstance(formula, Not):
            return not self.true(formula.formula, env, state)
        if isinstance(formula, And):
            return all(self.true(p, env, state) for p in formula.parts)  # type: ignore[arg-type]
        if isinstance(formula, Or):
            return any(self.true(p, env, state) for p in formula.parts)
        if isinstance(formula, Imply):
            return not self.true(formula.condition, env, state) or self.true(formula.consequence, env, state)
        if isinstance(formula, Exists | Forall):
            plan = self._plans.get(id(formula))
            if plan is None:
                plan = self._plans[id(formula)] = (formula, *_join_plan(formula))
            _, variables, levels = plan
            found = self._search(variables, levels, 0, dict(env), state)
            return found if isinstance(formula, Exists) else not found
        raise TypeError(f"not a formula: {formula!r}")

    def _search(self, variables: tuple, levels: tuple, k: int, env: dict[str, str], state: set[Atom]) -> bool:
        """Whether some binding of ``variables[k:]`` makes every part of ``levels`` true (checked once bound)."""
        for part in levels[k]:
            if not self.true(part, env, state):
                return False
        if k == len(variables):
            return True
        name, kind = variables[k]
        for obj in self.objects_of(kind):
            env[name] = obj
            if self._search(variables, levels, k + 1, env, state):
                return True
        return False

    def validate(self, steps: tuple[PlanStep, ...]) -> ValidationResult:
        state = set(self.problem.facts)
        cost = 0.0
        for number, step in enumerate(steps, 1):
            where = f"step {number} {str(step).lower()}"
            action = self.domain.action(step.action.lower())
            if action is None:
                return ValidationResult(False, cost, number, f"{where}: unknown action '{step.action}'")
            args = tuple(a.lower() for a in step.args)
            wrong = self.wrong_arguments(action.parameters, args)
            if wrong:
                return ValidationResult(False, cost, number, f"{where}: {wrong}")
            mapping = dict(zip((p for p, _ in action.parameters), args, strict=True))
            full = self.close(state)
            unmet = self.unmet(substitute(action.precondition, mapping), full)  # type: ignore[arg-type]
            if unmet is not None:
                return ValidationResult(False, cost, number, f"{where}: precondition {unmet} does not hold")
            add: set[Atom] = set()
            delete: set[Atom] = set()
            step_cost = 0.0 if self.has_costs else 1.0
            for effect in self.effects(substitute(action.effect, mapping), full):  # type: ignore[arg-type]
                if isinstance(effect, Increase):
                    value = effect.value
                    if isinstance(value, FluentTerm):
                        if value not in self.values:
                            return ValidationResult(
                                False, cost, number, f"{where}: fluent {value} has no value in :init"
                            )
                        value = self.values[value]
                    step_cost += value
                elif isinstance(effect, Not):
                    delete.add(effect.formula)  # type: ignore[arg-type]
                else:
                    add.add(effect)  # type: ignore[arg-type]
            state = (state - delete) | add
            cost += step_cost
        unmet_goal = self.unmet(self.problem.goal, self.close(state))
        if unmet_goal is not None:
            return ValidationResult(False, cost, None, f"goal {unmet_goal} does not hold after the plan")
        return ValidationResult(True, cost, None, "")

    def wrong_arguments(self, parameters: tuple[tuple[str, str], ...], args: tuple[str, ...]) -> str:
        """What is wrong with ``args`` for ``parameters`` (their number, an unknown object, a type); empty if nothing."""
        if len(args) != len(parameters):
            return f"expected {len(parameters)} arguments, found {len(args)}"
        for arg, (param, kind) in zip(args, parameters, strict=True):
            if arg not in self.objects:
                return f"unknown object '{arg}'"
            if not self.domain.is_subtype(self.objects[arg], kind):
                return f"'{arg}' is no {kind} (parameter {param})"
        return ""

    def holds(self, formula: Formula, state: set[Atom]) -> bool:
        return self.true(formula, {}, state)

    def unmet(self, formula: Formula, state: set[Atom]) -> str | None:
        """None when ``formula`` holds, else the first literal (or subformula) that does not."""
        if isinstance(formula, Atom):
            return None if formula in state else str(formula)
        if isinstance(formula, Equals):
            return None if formula.left == formula.right else str(formula)
        if isinstance(formula, Not):
            inner = formula.formula
            if isinstance(inner, Atom | Equals):
                return None if self.unmet(inner, state) is not None else f"(not {inner})"
            return None if not self.holds(inner, state) else "(not ...) of a formula that holds"
        if isinstance(formula, And):
            for part in formula.parts:
                failed = self.unmet(part, state)  # type: ignore[arg-type]
                if failed is not None:
                    return failed
            return None
        if isinstance(formula, Or):
            return None if any(self.holds(p, state) for p in formula.parts) else "(or ...): no part holds"
        if isinstance(formula, Imply):
            return None if not self.holds(formula.condition, state) else self.unmet(formula.consequence, state)
        if isinstance(formula, Exists | Forall):
            for binding in self.bindings(formula.variables):
                failed = self.unmet(substitute(formula.body, binding), state)  # type: ignore[arg-type]
                if isinstance(formula, Exists) and failed is None:
                    return None
                if isinstance(formula, Forall) and failed is not None:
                    return failed
            return None if isinstance(formula, Forall) else "(exists ...): no binding holds"
        raise TypeError(f"not a formula: {formula!r}")

    def bindings(self, variables: tuple[tuple[str, str], ...]) -> list[dict[str, str]]:
        pools = [self.objects_of(t) for _, t in variables]
        return [dict(zip((v for v, _ in variables), c, strict=True)) for c in itertools.product(*pools)]

    def effects(self, effect: Effect, state: set[Atom]) -> list[Effect]:
        """The literals and increases that fire (``when`` conditions read in ``state``)."""
        if isinstance(effect, And):
            return [e for part in effect.parts for e in self.effects(part, state)]  # type: ignore[arg-type]
        if isinstance(effect, Forall):
            return [e for b in self.bindings(effect.variables) for e in self.effects(substitute(effect.body, b), state)]  # type: ignore[arg-type]
        if isinstance(effect, When):
            return self.effects(effect.effect, state) if self.holds(effect.condition, state) else []
        return [effect]


def _join_plan(formula: Exists | Forall) -> tuple[tuple[tuple[str, str], ...], tuple[tuple[Formula, ...], ...]]:
    """A quantifier as a search for a witness: ``exists`` of a conjunction, ``forall`` as ``not exists not``.

    Nested quantifiers of the same kind are merged; each part of the conjunction is checked as soon
    as its quantified variables are bound (a nested-loop join that prunes early).
    """
    variables = list(formula.variables)
    body = formula.body
    while isinstance(body, type(formula)) and not {v for v, _ in body.variables} & {v for v, _ in variables}:
        variables.extend(body.variables)
        body = body.body
    parts: list[Formula]
    if isinstance(formula, Exists):
        parts = list(body.parts) if isinstance(body, And) else [body]  # type: ignore[arg-type,list-item]
    else:
        parts = [Not(p) for p in body.parts] if isinstance(body, Or) else [Not(body)]  # type: ignore[arg-type]
    names = [v for v, _ in variables]
    levels: list[list[Formula]] = [[] for _ in range(len(variables) + 1)]
    for part in parts:
        free = free_variables(part)
        levels[max((names.index(v) + 1 for v in free if v in names), default=0)].append(part)
    return tuple(variables), tuple(tuple(level) for level in levels)


_Test = Callable[[dict[str, str], set[tuple[str, ...]]], bool]
"""A compiled formula: whether it holds under a binding in a set of ``(predicate, *args)`` facts."""


def _atoms_with_free(formula: Formula, predicates: set[str], free: set[str]) -> list[Atom]:
    """The atoms of ``predicates`` in ``formula``, with the variables no quantifier above them rebinds
    (an argument naming a rebound variable is renamed so that it matches no head variable)."""
    out: list[Atom] = []
    stack: list[tuple[object, frozenset[str]]] = [(formula, frozenset())]
    while stack:
        node, bound = stack.pop()
        if isinstance(node, Atom):
            if node.predicate in predicates:
                out.append(Atom(node.predicate, tuple("?@" if a in bound else a for a in node.args)))
        elif isinstance(node, Not):
            stack.append((node.formula, bound))
        elif isinstance(node, And | Or):
            stack.extend((p, bound) for p in node.parts)
        elif isinstance(node, Imply):
            stack.extend([(node.condition, bound), (node.consequence, bound)])
        elif isinstance(node, Exists | Forall):
            stack.append((node.body, bound | {v for v, _ in node.variables} & free))
    return out


def _strata(axioms: tuple[Axiom, ...], derived: frozenset[str]) -> list[list[Axiom]]:
    """The rules by stratum (a rule's negated derived predicates, in NNF, in lower strata)."""
    if not axioms:
        return []
    edges: set[tuple[str, str, int]] = set()
    for axiom in axioms:
        stack: list[tuple[object, bool]] = [(nnf(axiom.body), True)]
        while stack:
            node, positive = stack.pop()
            if isinstance(node, Atom) and node.predicate in derived:
                edges.add((axiom.predicate, node.predicate, 0 if positive else 1))
            elif isinstance(node, Not):
                stack.append((node.formula, False))
            elif isinstance(node, And | Or):
                stack.extend((p, positive) for p in node.parts)
            elif isinstance(node, Exists | Forall):
                stack.append((node.body, positive))
    level = dict.fromkeys(derived, 0)
    for _ in range(len(level) + 1):
        changed = False
        for head, body, weight in edges:
            if level[head] < level[body] + weight:
                level[head] = level[body] + weight
                changed = True
        if not changed:
            break
    top = max(level.values(), default=0)
    return [[a for a in axioms if level[a.predicate] == k] for k in range(top + 1)]


def _walk(effect: Effect) -> list[Effect]:
    if isinstance(effect, And):
        return [e for p in effect.parts for e in _walk(p)]  # type: ignore[arg-type]
    if isinstance(effect, Forall | When):
        return _walk(effect.body if isinstance(effect, Forall) else effect.effect)  # type: ignore[arg-type]
    return [effect]
