"""Plan validation: simulate a plan from the initial state and check every step and the goal.

On a (domain, problem) pair the plan is checked at the lifted level (action
names, argument types, preconditions as formulas, conditional effects, costs
read from ``:init``); on a :class:`alica.prophet.ground.GroundTask` it is checked on
the ground operators.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from alica.prophet.ground import GroundTask
from alica.prophet.pddl.model import (
    OBJECT,
    And,
    Atom,
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
    return _Lifted(domain, problem).validate(steps)


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


class _Lifted:
    """Lifted simulation: a state is a set of ground atoms."""

    def __init__(self, domain: Domain, problem: Problem) -> None:
        self.domain = domain
        self.objects = dict((*domain.constants, *problem.objects))
        self.problem = problem
        self.values = problem.fluent_values
        self.has_costs = any(isinstance(e, Increase) for a in domain.actions for e in _walk(a.effect))

    def objects_of(self, kind: str) -> list[str]:
        return [o for o, t in self.objects.items() if kind == OBJECT or self.domain.is_subtype(t, kind)]

    def validate(self, steps: tuple[PlanStep, ...]) -> ValidationResult:
        state = set(self.problem.facts)
        cost = 0.0
        for number, step in enumerate(steps, 1):
            where = f"step {number} {str(step).lower()}"
            action = self.domain.action(step.action.lower())
            if action is None:
                return ValidationResult(False, cost, number, f"{where}: unknown action '{step.action}'")
            args = tuple(a.lower() for a in step.args)
            if len(args) != len(action.parameters):
                return ValidationResult(
                    False, cost, number, f"{where}: expected {len(action.parameters)} arguments, found {len(args)}"
                )
            for arg, (param, kind) in zip(args, action.parameters, strict=True):
                if arg not in self.objects:
                    return ValidationResult(False, cost, number, f"{where}: unknown object '{arg}'")
                if not self.domain.is_subtype(self.objects[arg], kind):
                    return ValidationResult(False, cost, number, f"{where}: '{arg}' is no {kind} (parameter {param})")
            mapping = dict(zip((p for p, _ in action.parameters), args, strict=True))
            unmet = self.unmet(substitute(action.precondition, mapping), state)  # type: ignore[arg-type]
            if unmet is not None:
                return ValidationResult(False, cost, number, f"{where}: precondition {unmet} does not hold")
            add: set[Atom] = set()
            delete: set[Atom] = set()
            step_cost = 0.0 if self.has_costs else 1.0
            for effect in self.effects(substitute(action.effect, mapping), state):  # type: ignore[arg-type]
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
        unmet_goal = self.unmet(self.problem.goal, state)
        if unmet_goal is not None:
            return ValidationResult(False, cost, None, f"goal {unmet_goal} does not hold after the plan")
        return ValidationResult(True, cost, None, "")

    def holds(self, formula: Formula, state: set[Atom]) -> bool:
        return self.unmet(formula, state) is None

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


def _walk(effect: Effect) -> list[Effect]:
    if isinstance(effect, And):
        return [e for p in effect.parts for e in _walk(p)]  # type: ignore[arg-type]
    if isinstance(effect, Forall | When):
        return _walk(effect.body if isinstance(effect, Forall) else effect.effect)  # type: ignore[arg-type]
    return [effect]
