"""Temporal planning for durative actions: a sequential plan, deordered and scheduled for makespan.

The planner covers temporally simple domains (no action needs another to run at the same time):

1. :func:`sequential_task` compiles each durative action into a classical action that does the
   whole action at once: its precondition is the ``at start`` condition with the ``over all`` and
   ``at end`` literals that its own start effects do not make true, its effect is what starting
   and then ending leaves (an end effect wins over a start effect on the same atom), and its cost
   is its duration in thousandths (:data:`SCALE`, the plan format's resolution). An action whose
   start effects break its own ``over all`` or ``at end`` condition can never end well and is
   refused, named.
2. The builtin planner searches that task (anytime, for the summed duration).
3. :func:`schedule` deorders the sequential plan: a step must follow an earlier one only when they
   are *dependent*, one's happening interferes with one of the other's
   (:func:`~alica.prophet.validate_temporal.interference`) or changes what the other needs over
   all. A dependent step starts :data:`~alica.prophet.temporal_plan.EPSILON` after the end of its
   last dependency; every other step starts at once. Steps that overlap then touch nothing of each
   other, so each reads what it read in the sequence: the schedule is valid when the sequential
   plan is (and it is validated anyway). Its makespan is the longest chain of dependent steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from alica.errors import PlannerError
from alica.prophet.pddl.model import (
    TOTAL_TIME,
    Action,
    And,
    Atom,
    Domain,
    DurativeAction,
    Effect,
    FluentTerm,
    FluentValue,
    Formula,
    Increase,
    Metric,
    Not,
    Predicate,
    Problem,
    top_level_parts,
)
from alica.prophet.pddl.normal import substitute
from alica.prophet.planner import Feature, Plan, PlanStep
from alica.prophet.temporal_ground import split_effect
from alica.prophet.temporal_plan import EPSILON, TemporalPlan, TimedStep
from alica.prophet.validate_temporal import Touches, interference, touches

SCALE = 1000
"""Durations become integer action costs in thousandths of a time unit."""
TOTAL_COST = "total-cost"
SCALED_PREFIX = "alica-duration-"
"""The prefix of the functions holding scaled durations in the sequential task."""


def sequential_task(domain: Domain, problem: Problem) -> tuple[Domain, Problem]:
    """The classical task whose plans are the temporal task's in sequence (see the module docstring).

    Raises:
        PlannerError: a durative action whose effects are not conjunctions of literals, or whose start
            breaks its own ``over all`` or ``at end`` condition.
    """
    scaled: set[str] = set()
    actions = [_sequential(a, scaled) for a in domain.durative_actions]
    actions += [_with_cost(a, 0) for a in domain.actions]  # instantaneous actions take no time
    declared = {f.name: f for f in domain.functions}
    functions = [f for f in domain.functions if f.name != TOTAL_COST]
    functions += [Predicate(SCALED_PREFIX + name, declared[name].parameters) for name in sorted(scaled)]
    functions.append(Predicate(TOTAL_COST))
    requirements = (domain.requirements - {Feature.DURATIVE_ACTIONS}) | {Feature.ACTION_COSTS}
    sequential = Domain(
        domain.name,
        frozenset(requirements),
        domain.types,
        domain.constants,
        domain.predicates,
        tuple(functions),
        tuple(actions),
        domain.extra_requirements,
        domain.axioms,
    )
    init: list[Atom | FluentValue] = [i for i in problem.init if not _is_total_cost(i)]
    for item in problem.init:
        if isinstance(item, FluentValue) and item.fluent.function in scaled:
            init.append(
                FluentValue(FluentTerm(SCALED_PREFIX + item.fluent.function, item.fluent.args), _ticks(item.value))
            )
    init.append(FluentValue(FluentTerm(TOTAL_COST), 0))
    task = Problem(
        problem.name,
        problem.domain_name,
        problem.objects,
        tuple(init),
        problem.goal,
        Metric("minimize", FluentTerm(TOTAL_COST)),
        (problem.requirements - {Feature.DURATIVE_ACTIONS}) | {Feature.ACTION_COSTS},
        problem.extra_requirements,
    )
    return sequential, task


def _is_total_cost(item: Atom | FluentValue) -> bool:
    return isinstance(item, FluentValue) and item.fluent.function == TOTAL_COST


def _ticks(value: float) -> int:
    return max(0, round(value * SCALE))


def _with_cost(action: Action, cost: int) -> Action:
    parts = [p for p in top_level_parts(action.effect) if not isinstance(p, Increase)]
    return Action(
        action.name,
        action.parameters,
        action.precondition,
        And((*parts, Increase(FluentTerm(TOTAL_COST), cost))),
        action.span,
    )


def _literals(effect: Effect, action: str) -> tuple[set[Atom], set[Atom]]:
    adds, deletes, others = split_effect(effect)
    if others:
        raise PlannerError(
            f"durative action {action}: the temporal planner takes effects that are conjunctions of literals, "
            f"not {type(others[0]).__name__.lower()} effects"
        )
    return adds, deletes


def _sequential(action: DurativeAction, scaled: set[str]) -> Action:
    start_add, start_del = _literals(action.start_effect, action.name)
    end_add, end_del = _literals(action.end_effect, action.name)
    needed: list[Formula] = list(top_level_parts(action.at_start))  # type: ignore[arg-type]
    for when, condition in (("over all", action.over_all), ("at end", action.at_end)):
        for part in top_level_parts(condition):  # type: ignore[arg-type]
            if (isinstance(part, Atom) and part in start_add) or (isinstance(part, Not) and part.formula in start_del):
                continue  # made true by its own start
            if (isinstance(part, Atom) and part in start_del) or (isinstance(part, Not) and part.formula in start_add):
                raise PlannerError(
                    f"durative action {action.name}: its {when} condition {part} is broken by its own start effects"
                )
            if part not in needed:
                needed.append(part)  # type: ignore[arg-type]
    adds = (start_add - end_del) | end_add
    deletes = (start_del - end_add) | end_del
    effects: list[Effect] = [*sorted(adds, key=str), *(Not(a) for a in sorted(deletes - adds, key=str))]
    duration = action.duration
    if isinstance(duration, FluentTerm):
        scaled.add(duration.function)
        cost: int | FluentTerm = FluentTerm(SCALED_PREFIX + duration.function, duration.args)
    else:
        cost = _ticks(duration)
    effects.append(Increase(FluentTerm(TOTAL_COST), cost))
    return Action(action.name, action.parameters, And(tuple(needed)), And(tuple(effects)), action.span)


@dataclass(frozen=True, slots=True)
class Schedule:
    """A temporal plan and the partial order it keeps.

    Attributes:
        plan: the steps at their start times, in the sequential plan's order.
        after: per step, the earlier steps it must follow (indices into ``plan.steps``).
        sequential_makespan: the makespan of doing the steps one after another.
    """

    plan: TemporalPlan
    after: tuple[tuple[int, ...], ...]
    sequential_makespan: float


@dataclass(frozen=True, slots=True)
class _Ground:
    start: Touches
    end: Touches
    over_all: Touches
    duration: float


def schedule(domain: Domain, problem: Problem, steps: Sequence[PlanStep]) -> Schedule:
    """The sequential plan ``steps`` deordered and scheduled (see the module docstring).

    Raises:
        PlannerError: a step that is no durative action of the domain, or a duration missing from ``:init``.
    """
    values = problem.fluent_values
    ground = [_ground(domain, values, step) for step in steps]
    starts: list[float] = []
    after: list[tuple[int, ...]] = []
    for j, g in enumerate(ground):
        before = tuple(i for i in range(j) if _dependent(ground[i], g))
        starts.append(round(max((starts[i] + ground[i].duration + EPSILON for i in before), default=0.0), 6))
        after.append(before)
    timed = tuple(TimedStep(s, step, g.duration) for s, step, g in zip(starts, steps, ground, strict=True))
    sequential = sum(g.duration for g in ground) + EPSILON * max(0, len(ground) - 1)
    return Schedule(TemporalPlan(timed), tuple(after), round(sequential, 6))


def timed_schedule(domain: Domain, problem: Problem, plan: TemporalPlan) -> Schedule:
    """A timed plan found otherwise (by :mod:`~alica.prophet.temporal_search`) as a :class:`Schedule`: its steps
    by start time, each with the earlier dependent steps (which it may overlap when their happenings allow).

    Raises:
        PlannerError: a step that is no action of the domain, or a duration missing from ``:init``.
    """
    values = problem.fluent_values
    timed = tuple(sorted(plan.steps, key=lambda t: t.start))
    ground = [_ground(domain, values, t.step) for t in timed]
    after = tuple(tuple(i for i in range(j) if _dependent(ground[i], g)) for j, g in enumerate(ground))
    sequential = sum(g.duration for g in ground) + EPSILON * max(0, len(ground) - 1)
    return Schedule(TemporalPlan(timed), after, round(sequential, 6))


@dataclass(frozen=True, slots=True)
class ScheduledPlan(Plan):
    """A plan whose timing is its own (not :func:`schedule` of its steps): the makespan search's.

    Attributes:
        schedule: the timed plan.
    """

    schedule: Schedule | None = None


def _ground(domain: Domain, values: dict[FluentTerm, int | float], step: PlanStep) -> _Ground:
    action = domain.durative_action(step.action)
    if action is None:
        # an instantaneous action: zero duration, what it reads and changes at its start
        plain = domain.action(step.action)
        if plain is None:
            raise PlannerError(f"step {step}: no action '{step.action}' in domain {domain.name}")
        mapping = dict(zip((p for p, _ in plain.parameters), step.args, strict=True))
        happening = touches(substitute(plain.precondition, mapping), substitute(plain.effect, mapping))  # type: ignore[arg-type]
        return _Ground(happening, Touches(frozenset(), frozenset(), frozenset()), _NOTHING, 0.0)
    mapping = dict(zip((p for p, _ in action.parameters), step.args, strict=True))
    duration = action.duration
    if isinstance(duration, FluentTerm):
        term = FluentTerm(duration.function, tuple(mapping.get(a, a) for a in duration.args))
        if term not in values:
            raise PlannerError(f"step {step}: the duration {term} has no value in :init")
        duration = values[term]
    return _Ground(
        touches(substitute(action.at_start, mapping), substitute(action.start_effect, mapping)),  # type: ignore[arg-type]
        touches(substitute(action.at_end, mapping), substitute(action.end_effect, mapping)),  # type: ignore[arg-type]
        touches(substitute(action.over_all, mapping), And(())),  # type: ignore[arg-type]
        float(duration),
    )


_NOTHING = Touches(frozenset(), frozenset(), frozenset())


def _dependent(a: _Ground, b: _Ground) -> bool:
    """Whether two steps may not overlap in time (see the module docstring)."""
    for x in (a.start, a.end):
        for y in (b.start, b.end):
            if interference(x, y):
                return True
    for first, second in ((a, b), (b, a)):
        for happening in (first.start, first.end):
            if interference(happening, second.over_all):
                return True
    return False


def is_temporal(domain: Domain, problem: Problem) -> bool:
    """Whether the task is a temporal one: durative actions, or the ``(total-time)`` metric."""
    return bool(domain.durative_actions) or (
        problem.metric is not None and problem.metric.expression.function == TOTAL_TIME
    )


__all__ = ["SCALE", "Schedule", "ScheduledPlan", "is_temporal", "schedule", "sequential_task", "timed_schedule"]
