"""Temporal plan validation: durative actions simulated happening by happening (PDDL 2.1 semantics).

Each step of a :class:`~alica.prophet.temporal_plan.TemporalPlan` is a durative action of the domain
with its arguments; its duration must be the one the domain gives (a number, or a function read
from ``:init``). The plan's happenings (each step's start and end) are taken in time order;
happenings closer than :data:`~alica.prophet.temporal_plan.EPSILON` are simultaneous, and two
simultaneous happenings of different steps must not interfere (one changes what the other reads
or changes; an atom under a quantifier stands for every atom of its predicate). At a start the
``at start`` condition must hold, at an end the ``at end`` one, both in the state before the
happening; the ``over all`` condition must hold in every state while the step runs (after its
start and each later happening, up to its end). The goal must hold after the last happening. The
result's cost is the makespan.
"""

from __future__ import annotations

from dataclasses import dataclass

from alica.prophet.pddl.model import (
    And,
    Atom,
    Domain,
    DurativeAction,
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
from alica.prophet.temporal_plan import EPSILON, TemporalPlan, TimedStep
from alica.prophet.validate import LiftedSimulation, ValidationResult

SIMULTANEOUS = EPSILON - 1e-9
"""Happenings closer than this are simultaneous (EPSILON apart, as written in a plan, are not)."""
DURATION_TOLERANCE = EPSILON / 10
"""How far a step's written duration may be from the domain's."""


@dataclass(frozen=True, slots=True)
class Touches:
    """The atoms a happening reads and changes (variables under quantifiers stay: they match any object)."""

    reads: frozenset[Atom]
    adds: frozenset[Atom]
    deletes: frozenset[Atom]


@dataclass(slots=True)
class _Step:
    number: int
    where: str
    timed: TimedStep
    action: DurativeAction
    mapping: dict[str, str]
    start: Touches
    end: Touches


def validate_temporal_plan(domain: Domain, problem: Problem, plan: TemporalPlan) -> ValidationResult:
    """Check ``plan`` against the domain's durative actions (see the module docstring).

    Returns:
        The result; its reason names the step, the time and the unmet condition (or the interfering
        pair, or the wrong duration); ``cost`` is the makespan when valid.
    """
    sim = LiftedSimulation(domain, problem)
    steps: list[_Step] = []
    for number, timed in enumerate(plan.steps, 1):
        checked = _check_step(sim, domain, number, timed)
        if isinstance(checked, ValidationResult):
            return checked
        steps.append(checked)
    # happenings: (time, 0 for an end and 1 for a start at the same time, step); a step's own start first
    events = sorted(
        [(s.timed.start, 1, s.number, "start", s) for s in steps]
        + [(s.timed.end, 0 if s.timed.duration > 0 else 2, s.number, "end", s) for s in steps]
    )
    state = set(problem.facts)
    running: dict[int, _Step] = {}
    k = 0
    while k < len(events):
        group = [events[k]]
        while k + len(group) < len(events) and events[k + len(group)][0] - events[k][0] < SIMULTANEOUS:
            group.append(events[k + len(group)])
        k += len(group)
        time = group[0][0]
        clash = _interfering(group)
        if clash:
            return ValidationResult(False, 0.0, clash[0].number, f"{clash[0].where} and {clash[1].where} {clash[2]}")
        for _t, _order, _n, kind, step in group:
            full = sim.close(state)
            condition = step.action.at_start if kind == "start" else step.action.at_end
            unmet = sim.unmet(substitute(condition, step.mapping), full)  # type: ignore[arg-type]
            if unmet is not None:
                return ValidationResult(
                    False, 0.0, step.number, f"{step.where}: at {kind} condition {unmet} does not hold at {time:.3f}"
                )
            effect = step.action.start_effect if kind == "start" else step.action.end_effect
            add: set[Atom] = set()
            delete: set[Atom] = set()
            for fired in sim.effects(substitute(effect, step.mapping), full):  # type: ignore[arg-type]
                if isinstance(fired, Not):
                    delete.add(fired.formula)  # type: ignore[arg-type]
                elif isinstance(fired, Atom):
                    add.add(fired)
            state = (state - delete) | add
            if kind == "start":
                running[step.number] = step
            else:
                running.pop(step.number, None)
        full = sim.close(state)
        for step in running.values():
            unmet = sim.unmet(substitute(step.action.over_all, step.mapping), full)  # type: ignore[arg-type]
            if unmet is not None:
                return ValidationResult(
                    False, 0.0, step.number, f"{step.where}: over all condition {unmet} does not hold at {time:.3f}"
                )
    unmet_goal = sim.unmet(problem.goal, sim.close(state))
    if unmet_goal is not None:
        return ValidationResult(False, plan.makespan, None, f"goal {unmet_goal} does not hold after the plan")
    return ValidationResult(True, plan.makespan, None, "")


def _check_step(sim: LiftedSimulation, domain: Domain, number: int, timed: TimedStep) -> _Step | ValidationResult:
    where = f"step {number} {timed.step}"
    action = domain.durative_action(timed.step.action)
    if action is None:
        return ValidationResult(False, 0.0, number, f"{where}: unknown durative action '{timed.step.action}'")
    wrong = sim.wrong_arguments(action.parameters, timed.step.args)
    if wrong:
        return ValidationResult(False, 0.0, number, f"{where}: {wrong}")
    if timed.start < 0 or timed.duration < 0:
        return ValidationResult(False, 0.0, number, f"{where}: negative start or duration")
    mapping = dict(zip((p for p, _ in action.parameters), timed.step.args, strict=True))
    duration = action.duration
    if isinstance(duration, FluentTerm):
        term = FluentTerm(duration.function, tuple(mapping.get(a, a) for a in duration.args))
        if term not in sim.values:
            return ValidationResult(False, 0.0, number, f"{where}: the duration {term} has no value in :init")
        duration = sim.values[term]
    if abs(duration - timed.duration) > DURATION_TOLERANCE:
        return ValidationResult(
            False, 0.0, number, f"{where}: duration {timed.duration:g} differs from the domain's {duration:g}"
        )
    start = touches(substitute(action.at_start, mapping), substitute(action.start_effect, mapping))  # type: ignore[arg-type]
    end = touches(substitute(action.at_end, mapping), substitute(action.end_effect, mapping))  # type: ignore[arg-type]
    return _Step(number, where, timed, action, mapping, start, end)


def touches(condition: Formula, effect: Effect) -> Touches:
    """What a happening with this condition and effect reads and changes."""
    reads: set[Atom] = set()
    adds: set[Atom] = set()
    deletes: set[Atom] = set()
    _read(condition, reads)
    _change(effect, reads, adds, deletes)
    return Touches(frozenset(reads), frozenset(adds), frozenset(deletes))


def _read(formula: Formula, out: set[Atom]) -> None:
    if isinstance(formula, Atom):
        out.add(formula)
    elif isinstance(formula, Not):
        _read(formula.formula, out)
    elif isinstance(formula, And | Or):
        for part in formula.parts:
            _read(part, out)  # type: ignore[arg-type]
    elif isinstance(formula, Imply):
        _read(formula.condition, out)
        _read(formula.consequence, out)
    elif isinstance(formula, Exists | Forall):
        _read(formula.body, out)  # type: ignore[arg-type]
    elif not isinstance(formula, Equals):
        raise TypeError(f"not a formula: {formula!r}")


def _change(effect: Effect, reads: set[Atom], adds: set[Atom], deletes: set[Atom]) -> None:
    if isinstance(effect, Atom):
        adds.add(effect)
    elif isinstance(effect, Not):
        deletes.add(effect.formula)  # type: ignore[arg-type]
    elif isinstance(effect, And):
        for part in effect.parts:
            _change(part, reads, adds, deletes)  # type: ignore[arg-type]
    elif isinstance(effect, Forall):
        _change(effect.body, reads, adds, deletes)  # type: ignore[arg-type]
    elif isinstance(effect, When):
        _read(effect.condition, reads)
        _change(effect.effect, reads, adds, deletes)
    elif not isinstance(effect, Increase):
        raise TypeError(f"not an effect: {effect!r}")


def _match(a: Atom, b: Atom) -> bool:
    """Whether two atoms may be the same ground atom (a ``?variable`` matches any object)."""
    return (
        a.predicate == b.predicate
        and len(a.args) == len(b.args)
        and all(x == y or x.startswith("?") or y.startswith("?") for x, y in zip(a.args, b.args, strict=True))
    )


def _meet(xs: frozenset[Atom], ys: frozenset[Atom]) -> Atom | None:
    return next((x for x in xs for y in ys if _match(x, y)), None)


def interference(a: Touches, b: Touches) -> str:
    """Why two simultaneous happenings interfere (empty when they do not)."""
    for first, second in ((a, b), (b, a)):
        atom = _meet(first.adds | first.deletes, second.reads)
        if atom is not None:
            return f"change {atom}, which the other reads"
        atom = _meet(first.adds, second.deletes)
        if atom is not None:
            return f"both change {atom}"
    return ""


def _interfering(group: list[tuple[float, int, int, str, _Step]]) -> tuple[_Step, _Step, str] | None:
    """The first pair of simultaneous happenings of different steps that interfere, with the reason."""
    for i, (time, _o, _n, kind, step) in enumerate(group):
        for _t, _o2, _n2, other_kind, other in group[i + 1 :]:
            if other is step:
                continue
            why = interference(
                step.start if kind == "start" else step.end, other.start if other_kind == "start" else other.end
            )
            if why:
                return step, other, f"interfere at {time:.3f} ({why}); they need {EPSILON:g} between them"
    return None


__all__ = ["DURATION_TOLERANCE", "Touches", "interference", "touches", "validate_temporal_plan"]
