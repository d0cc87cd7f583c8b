"""Ground durative actions over bit masks, for the makespan search (:mod:`alica.prophet.temporal_search`).

The ground actions are those the grounding of the sequential task keeps
(:func:`~alica.prophet.temporal.sequential_task`: reachable under the delete relaxation).
Each one is substituted from its lifted :class:`~alica.prophet.pddl.model.DurativeAction`:
its conditions and effects must be conjunctions of literals (equalities are decided here).
Atoms that no action changes are *static*: a condition on one is decided here too (an action
whose static condition fails is dropped), so the masks hold only the atoms that change.

Times are integers in :data:`TICKS` per time unit, so that sums of durations stay exact; two
happenings are simultaneous when they are fewer than :data:`EPSILON_TICKS` apart
(:data:`~alica.prophet.temporal_plan.EPSILON`, the validator's rule).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from alica.errors import PlannerError
from alica.prophet.pddl.model import (
    Atom,
    Domain,
    Effect,
    Equals,
    FluentTerm,
    Formula,
    Increase,
    Not,
    Problem,
    top_level_parts,
)
from alica.prophet.pddl.normal import substitute
from alica.prophet.planner import PlanStep
from alica.prophet.temporal_plan import EPSILON

TICKS = 1_000_000
"""Ticks per time unit (microseconds when the unit is the second)."""
EPSILON_TICKS = round(EPSILON * TICKS)
"""Happenings of different actions fewer ticks apart than this are simultaneous."""


@dataclass(frozen=True, slots=True)
class Happening:
    """A start or an end of a ground durative action: what it needs, reads and changes (fact masks)."""

    pos: int
    neg: int
    add: int
    delete: int

    @property
    def reads(self) -> int:
        """The facts its condition reads."""
        return self.pos | self.neg

    def interferes(self, other: Happening) -> bool:
        """Whether the two may not happen at once: one changes what the other reads, or both change a
        fact one way and the other (the validator's :func:`~alica.prophet.validate_temporal.interference`)."""
        mine, theirs = self.add | self.delete, other.add | other.delete
        return bool(mine & other.reads or theirs & self.reads or self.add & other.delete or other.add & self.delete)


@dataclass(frozen=True, slots=True)
class DurativeOp:
    """A ground durative action.

    Attributes:
        step: the action and its arguments.
        duration: its duration in time units.
        ticks: its duration in :data:`TICKS`.
        start: its start happening (``at start`` condition and effects).
        end: its end happening (``at end`` condition and effects).
        over_pos: the facts its ``over all`` condition needs.
        over_neg: the facts its ``over all`` condition needs false.
        relaxed_pre: the facts the delete relaxation needs before it starts: its positive conditions
            (the ``over all`` and ``at end`` ones its own start does not add).
    """

    step: PlanStep
    duration: float
    ticks: int
    start: Happening
    end: Happening
    over_pos: int
    over_neg: int
    relaxed_pre: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class TemporalTask:
    """The ground durative actions, the initial facts and the goal over the changing atoms.

    Attributes:
        facts: the changing atoms (``(at r p)``); a fact's id is its index, its mask bit ``1 << id``.
        init: the initial facts (a mask).
        goal_pos: the goal's facts that must hold (a mask).
        goal_neg: the goal's facts that must not hold (a mask).
        ops: the ground durative actions, in the grounding's order.
        unsolvable: why no plan exists, when a static goal literal already shows it (else empty).
    """

    facts: tuple[str, ...]
    init: int
    goal_pos: int
    goal_neg: int
    ops: tuple[DurativeOp, ...]
    unsolvable: str = ""


_Literals = tuple[set[Atom], set[Atom]]


def temporal_task(domain: Domain, problem: Problem, steps: Iterable[PlanStep]) -> TemporalTask:
    """The ground task of ``steps`` (the ground actions, in order; repeats are dropped).

    Raises:
        PlannerError: instantaneous actions in the domain, a condition, goal or effect that is no
            conjunction of literals, or a duration missing from ``:init``.
    """
    if domain.actions:
        raise PlannerError(
            f"the makespan search takes durative actions only; domain {domain.name} has instantaneous ones "
            f"({domain.actions[0].name})"
        )
    values = problem.fluent_values
    init_atoms = {(a.predicate, a.args) for a in problem.facts}
    raw: list[tuple[PlanStep, float, tuple[_Literals, ...], tuple[_Literals, _Literals]]] = []
    seen: set[PlanStep] = set()
    for step in steps:
        if step in seen:
            continue
        seen.add(step)
        action = domain.durative_action(step.action)
        if action is None:
            raise PlannerError(f"the makespan search takes durative actions only, not '{step.action}'")
        mapping = dict(zip((p for p, _ in action.parameters), step.args, strict=True))
        duration = action.duration
        if isinstance(duration, FluentTerm):
            term = FluentTerm(duration.function, tuple(mapping.get(a, a) for a in duration.args))
            if term not in values:
                raise PlannerError(f"step {step}: the duration {term} has no value in :init")
            duration = values[term]
        conditions = [
            _condition(substitute(c, mapping), step)  # type: ignore[arg-type]
            for c in (action.at_start, action.over_all, action.at_end)
        ]
        if any(c is None for c in conditions):
            continue  # an equality that fails: the action never applies
        effects = (
            _effect(substitute(action.start_effect, mapping), step),  # type: ignore[arg-type]
            _effect(substitute(action.end_effect, mapping), step),  # type: ignore[arg-type]
        )
        raw.append((step, float(duration), tuple(c for c in conditions if c is not None), effects))
    changing: set[Atom] = set()
    for *_, effects in raw:
        for adds, deletes in effects:
            changing |= adds | deletes
    facts = sorted(changing, key=str)
    ids = {atom: i for i, atom in enumerate(facts)}

    def static_fails(literals: _Literals) -> bool:
        pos, neg = literals
        return any(a not in ids and (a.predicate, a.args) not in init_atoms for a in pos) or any(
            a not in ids and (a.predicate, a.args) in init_atoms for a in neg
        )

    def bits(atoms: Iterable[Atom]) -> int:
        out = 0
        for atom in atoms:
            if atom in ids:
                out |= 1 << ids[atom]
        return out

    ops: list[DurativeOp] = []
    for step, duration, (at_start, over_all, at_end), ((sadd, sdel), (eadd, edel)) in raw:
        if any(static_fails(c) for c in (at_start, over_all, at_end)):
            continue
        start_add = bits(sadd)
        relaxed = (bits(at_start[0]) | bits(over_all[0]) | bits(at_end[0])) & ~start_add
        ops.append(
            DurativeOp(
                step,
                duration,
                round(duration * TICKS),
                Happening(bits(at_start[0]), bits(at_start[1]), start_add, bits(sdel) & ~start_add),
                Happening(bits(at_end[0]), bits(at_end[1]), bits(eadd), bits(edel) & ~bits(eadd)),
                bits(over_all[0]),
                bits(over_all[1]),
                tuple(i for i in range(relaxed.bit_length()) if relaxed >> i & 1),
            )
        )
    goal = _condition(problem.goal, None)
    unsolvable = ""
    if goal is None or static_fails(goal):
        unsolvable = "a goal literal on an atom no action changes is false"
        goal = (set(), set())
    goal_pos, goal_neg = bits(goal[0]), bits(goal[1])
    return TemporalTask(
        tuple(str(a) for a in facts),
        bits(a for a in facts if (a.predicate, a.args) in init_atoms),
        goal_pos,
        goal_neg,
        _useful(ops, goal_pos, goal_neg),
        unsolvable,
    )


def _useful(ops: list[DurativeOp], goal_pos: int, goal_neg: int) -> tuple[DurativeOp, ...]:
    """The actions that may help: one that adds no fact any condition or the goal needs, and deletes no fact
    one needs false, is left out (a plan without it stays valid: it only loses happenings, and facts nothing
    reads as true)"""
    wanted, unwanted = goal_pos, goal_neg
    for op in ops:
        wanted |= op.start.pos | op.end.pos | op.over_pos
        unwanted |= op.start.neg | op.end.neg | op.over_neg
    return tuple(
        op for op in ops if (op.start.add | op.end.add) & wanted or (op.start.delete | op.end.delete) & unwanted
    )


def _condition(formula: Formula, step: PlanStep | None) -> _Literals | None:
    """The positive and negative atoms of a conjunction of literals; None when an equality in it fails."""
    pos: set[Atom] = set()
    neg: set[Atom] = set()
    for part in top_level_parts(formula):  # type: ignore[arg-type]
        if isinstance(part, Atom):
            pos.add(part)
        elif isinstance(part, Not) and isinstance(part.formula, Atom):
            neg.add(part.formula)
        elif isinstance(part, Equals) or (isinstance(part, Not) and isinstance(part.formula, Equals)):
            equals = part if isinstance(part, Equals) else part.formula
            assert isinstance(equals, Equals)
            if (equals.left == equals.right) != isinstance(part, Equals):
                return None
        else:
            raise _not_literals("condition" if step is not None else "goal", step, part)
    return pos, neg


def split_effect(effect: Effect) -> tuple[set[Atom], set[Atom], list[object]]:
    """An effect's added atoms, its deleted atoms, and its parts that are neither (numeric increases aside)."""
    adds: set[Atom] = set()
    deletes: set[Atom] = set()
    others: list[object] = []
    for part in top_level_parts(effect):
        if isinstance(part, Atom):
            adds.add(part)
        elif isinstance(part, Not) and isinstance(part.formula, Atom):
            deletes.add(part.formula)
        elif not isinstance(part, Increase):
            others.append(part)
    return adds, deletes, others


def _effect(effect: Effect, step: PlanStep) -> _Literals:
    adds, deletes, others = split_effect(effect)
    if others:
        raise _not_literals("effect", step, others[0])
    return adds, deletes


def _not_literals(what: str, step: PlanStep | None, part: object) -> PlannerError:
    where = f"step {step}" if step is not None else "the problem"
    return PlannerError(
        f"{where}: the makespan search takes a {what} that is a conjunction of literals, not {type(part).__name__.lower()}"
    )


__all__ = ["EPSILON_TICKS", "TICKS", "DurativeOp", "Happening", "TemporalTask", "temporal_task"]
