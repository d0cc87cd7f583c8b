"""A planning problem of a plan file as PDDL: the domain from its elements' signatures, the problem from World and Goal.

Each problem element (a skill plan with a ``signature``) becomes a PDDL action
of the same name: its parameters, its precondition and its effect (written in
the plan language as conjunctions of literals, ``holding(?r, ?x) and not
clear(?y)``). The robot parameter ``?r`` is the one agent of the
single-agent plan (IMPERA 7.3); task creation spreads the plan over the team
afterwards. World is the problem's ``world`` (offline use) or facts read from
the world model; Goal is the problem's ``goal``.

With ``temporal`` (the problem's ``planner: temporal``) each element becomes a PDDL 2.1 durative
action of its signature's ``duration``, and the metric is the makespan (``total-time``). The
precondition holds at the start; what the effect deletes of it is deleted at the start (the skill
holds the block, the hand, the target from its first moment on, so no other robot's step can use
them meanwhile); the rest of the effect holds at the end.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

from alica.errors import AlicaError, PlannerError
from alica.lang import literals
from alica.lang.fact import Fact
from alica.model import PlanLibrary, PlanningProblem

if TYPE_CHECKING:
    from alica.prophet.pddl import Domain, Problem


def _symbol(name: str) -> str:
    return name.lower()


def _atom(name: str, args: Iterable[object]) -> str:
    parts = [_symbol(name), *(_symbol(str(a)) for a in args)]
    return f"({' '.join(parts)})"


def _conjunction(text: str | None, what: str) -> tuple[list[str], list[tuple[bool, str, tuple[object, ...]]]]:
    if not text:
        return [], []
    try:
        found = literals(text)
    except AlicaError as exc:
        raise PlannerError(f"{what} must be a conjunction of literals to be planned with: {exc}") from None
    out = [(_atom(n, a) if p else f"(not {_atom(n, a)})") for p, n, a in found]
    return out, list(found)


def _and(parts: list[str]) -> str:
    return parts[0] if len(parts) == 1 else f"(and {' '.join(parts)})"


def _signatures(problem: PlanningProblem, library: PlanLibrary):  # type: ignore[no-untyped-def]
    """Per element: its name, typed parameters, precondition and effect (PDDL text and literals)."""
    for name in problem.elements:
        plan = library.plans.get(name)
        if plan is None or plan.signature is None:
            raise PlannerError(
                f"planning problem '{problem.name}': element '{name}' is not a skill plan with a signature"
            )
        sig = plan.signature
        typed = {v.name: (v.type if v.type != "any" else "object") for v in sig.parameters}
        pre = _conjunction(sig.precondition.text if sig.precondition else None, f"the precondition of '{name}'")
        eff = _conjunction(sig.effect.text if sig.effect else None, f"the effect of '{name}'")
        yield name, sig, typed, pre, eff


def predicate_types(problem: PlanningProblem, library: PlanLibrary) -> dict[str, tuple[str, ...]]:
    """The predicates of a planning problem's domain with their argument types (lower-case names).

    Raises:
        PlannerError: as :func:`domain_text`.
    """
    predicates: dict[str, tuple[str, ...]] = {}
    for _, _, typed, (_, pre_lits), (_, eff_lits) in _signatures(problem, library):
        for _, pred, args in pre_lits + eff_lits:
            predicates.setdefault(_symbol(pred), tuple(typed.get(str(a), "object") for a in args))
    return predicates


def domain_text(
    problem: PlanningProblem,
    library: PlanLibrary,
    *,
    temporal: bool = False,
    durations: Mapping[str, float] | None = None,
) -> str:
    """The PDDL domain of a planning problem's elements (durative ones with ``temporal``, see the module docstring).

    Args:
        problem: the planning problem.
        library: holds its elements.
        temporal: write durative actions.
        durations: element name -> seconds, over the signatures' own ``duration`` (measured ones, say).

    Raises:
        PlannerError: an element has no signature, or a signature is not a conjunction of literals; with
            ``temporal``, an element has no duration.
    """
    actions, types = [], {"object"}
    predicates = predicate_types(problem, library)
    for name, sig, typed, (pre, pre_lits), (eff, eff_lits) in _signatures(problem, library):
        types.update(typed.values())
        params = " ".join(f"{_symbol(v)} - {_symbol(t)}" for v, t in typed.items())
        if temporal:
            duration = (durations or {}).get(name, sig.duration)
            if duration is None:
                raise PlannerError(
                    f"planning problem '{problem.name}' plans with durations (planner: temporal), but element "
                    f"'{name}' declares none: give its signature a 'duration' (expected seconds)"
                )
            actions.append(_durative(name, params, duration, pre, pre_lits, eff, eff_lits))
            continue
        cost = int(sig.cost) if float(sig.cost).is_integer() else sig.cost
        effect_parts = eff + [f"(increase (total-cost) {cost})"]
        actions.append(
            f"  (:action {_symbol(name)}\n    :parameters ({params})\n"
            f"    :precondition {_and(pre) if pre else '(and)'}\n    :effect {_and(effect_parts)})"
        )
    preds = " ".join(
        f"({p} {' '.join(f'?a{i} - {_symbol(t)}' for i, t in enumerate(ts))})".replace(" )", ")")
        for p, ts in sorted(predicates.items())
    )
    type_list = " ".join(sorted(_symbol(t) for t in types if t != "object"))
    requirements = ":durative-actions" if temporal else ":action-costs"
    return (
        f"(define (domain {_symbol(problem.name)})\n  (:requirements :strips :typing :negative-preconditions {requirements})\n"
        + (f"  (:types {type_list} - object)\n" if type_list else "")
        + f"  (:predicates {preds})\n"
        + ("" if temporal else "  (:functions (total-cost) - number)\n")
        + "\n".join(actions)
        + "\n)\n"
    )


def _durative(
    name: str,
    params: str,
    duration: float,
    pre: list[str],
    pre_lits: list[tuple[bool, str, tuple[object, ...]]],
    eff: list[str],
    eff_lits: list[tuple[bool, str, tuple[object, ...]]],
) -> str:
    """One element as a durative action: what its effect deletes of its precondition goes at the start."""
    held = {(n, tuple(map(str, a))) for positive, n, a in pre_lits if positive}
    start = [
        text
        for text, (positive, n, a) in zip(eff, eff_lits, strict=True)
        if not positive and (n, tuple(map(str, a))) in held
    ]
    end = [text for text in eff if text not in start]
    conditions = [f"(at start {text})" for text in pre]
    effects = [f"(at start {text})" for text in start] + [f"(at end {text})" for text in end]
    return (
        f"  (:durative-action {_symbol(name)}\n    :parameters ({params})\n    :duration (= ?duration {duration:g})\n"
        f"    :condition {_and(conditions) if conditions else '(and)'}\n    :effect {_and(effects) if effects else '(and)'})"
    )


def problem_text(
    problem: PlanningProblem, objects: Mapping[str, str], facts: Iterable[Fact], *, temporal: bool = False
) -> str:
    """The PDDL problem: typed ``objects`` (name -> type), the initial ``facts`` and the problem's goal
    (for the makespan with ``temporal``).

    Raises:
        PlannerError: the goal is not a conjunction of literals.
    """
    goal, _ = _conjunction(problem.goal.text, f"the goal of '{problem.name}'")
    objs = " ".join(f"{_symbol(o)} - {_symbol(t)}" for o, t in sorted(objects.items()))
    init = " ".join(sorted(_atom(n, a) for n, a in facts))
    cost, metric = ("", "(total-time)") if temporal else (" (= (total-cost) 0)", "(total-cost)")
    return (
        f"(define (problem {_symbol(problem.name)}-now) (:domain {_symbol(problem.name)})\n  (:objects {objs})\n"
        f"  (:init {init}{cost})\n  (:goal {_and(goal) if goal else '(and)'})\n  (:metric minimize {metric}))\n"
    )


def offline_world(problem: PlanningProblem) -> tuple[dict[str, str], list[Fact]]:
    """The objects and facts a problem's own ``world`` and ``objects`` give (offline use).

    Raises:
        PlannerError: no world is given, or it is not a conjunction of positive literals.
    """
    if problem.world is None:
        raise PlannerError(
            f"planning problem '{problem.name}' has no 'world': it is read from the world model at run time"
        )
    _, found = _conjunction(problem.world.text, f"the world of '{problem.name}'")
    if any(not positive for positive, _, _ in found):
        raise PlannerError(
            f"the world of '{problem.name}' lists facts that hold; leave out the ones that do not (closed world)"
        )
    objects = {v.name: (v.type if v.type != "any" else "object") for v in problem.objects}
    return objects, [Fact(n, tuple(str(a) for a in args)) for _, n, args in found]


def to_pddl(
    problem: PlanningProblem,
    library: PlanLibrary,
    objects: Mapping[str, str],
    facts: Iterable[Fact],
    *,
    temporal: bool = False,
    durations: Mapping[str, float] | None = None,
) -> tuple[Domain, Problem]:
    """The parsed PDDL ``(Domain, Problem)`` of a planning problem in a world (durative with ``temporal``)."""
    from alica.prophet.pddl import parse_domain, parse_problem

    text = domain_text(problem, library, temporal=temporal, durations=durations)
    domain = parse_domain(text, file=f"<{problem.name} domain>")
    pddl_problem = parse_problem(
        problem_text(problem, objects, facts, temporal=temporal), file=f"<{problem.name} problem>"
    )
    return domain, pddl_problem
