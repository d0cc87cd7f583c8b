"""Writing domains and problems as readable PDDL that reads back to an equal model."""

from __future__ import annotations

from alica.prophet.pddl.model import (
    OBJECT,
    Action,
    And,
    Atom,
    Axiom,
    Domain,
    DurativeAction,
    Effect,
    Equals,
    Exists,
    FluentTerm,
    FluentValue,
    Forall,
    Formula,
    Imply,
    Increase,
    Not,
    Or,
    Problem,
    TypedName,
    When,
)
from alica.prophet.planner import Feature


def _number(value: float) -> str:
    return str(value) if isinstance(value, int) else repr(float(value))


def _typed(names: tuple[TypedName, ...] | list[TypedName]) -> str:
    """``?x ?y - t ?z``: consecutive names of one type share it; ``object`` is left out at the end."""
    groups: list[tuple[list[str], str]] = []
    for name, kind in names:
        if groups and groups[-1][1] == kind:
            groups[-1][0].append(name)
        else:
            groups.append(([name], kind))
    words: list[str] = []
    for index, (members, kind) in enumerate(groups):
        words.extend(members)
        if kind != OBJECT or index < len(groups) - 1:
            words.extend(("-", kind))
    return " ".join(words)


def write_formula(formula: Formula | Effect, indent: int = 0) -> str:
    """A formula or effect as PDDL text; long conjunctions take one line per part.

    Args:
        formula: the formula or effect.
        indent: the column the text starts at (for line breaks).
    """
    if isinstance(formula, Atom):
        return str(formula)
    if isinstance(formula, FluentTerm):
        return str(formula)
    if isinstance(formula, Equals):
        return str(formula)
    if isinstance(formula, Not):
        return f"(not {write_formula(formula.formula, indent + 5)})"
    if isinstance(formula, And | Or):
        word = "and" if isinstance(formula, And) else "or"
        parts = [write_formula(p, indent + 2) for p in formula.parts]
        if not parts:
            return f"({word})"
        flat = f"({word} {' '.join(parts)})"
        if len(flat) + indent <= 100 and "\n" not in flat:
            return flat
        pad = "\n" + " " * (indent + 2)
        return f"({word}{pad}{pad.join(parts)})"
    if isinstance(formula, Imply):
        return (
            f"(imply {write_formula(formula.condition, indent + 7)} {write_formula(formula.consequence, indent + 7)})"
        )
    if isinstance(formula, Exists | Forall):
        word = "exists" if isinstance(formula, Exists) else "forall"
        body = write_formula(formula.body, indent + 2)
        return f"({word} ({_typed(formula.variables)})\n{' ' * (indent + 2)}{body})"
    if isinstance(formula, When):
        return f"(when {write_formula(formula.condition, indent + 6)}\n{' ' * (indent + 2)}{write_formula(formula.effect, indent + 2)})"
    if isinstance(formula, Increase):
        value = formula.value if isinstance(formula.value, FluentTerm) else _number(formula.value)
        return f"(increase {formula.fluent} {value})"
    raise TypeError(f"not a formula or effect: {formula!r}")


def _requirements(features: frozenset[Feature], extra: frozenset[str]) -> str:
    names = sorted(f":{f.value}" for f in features) + sorted(f":{e}" for e in extra)
    return f"(:requirements {' '.join(names)})"


def _action(action: Action) -> str:
    lines = [f"  (:action {action.name}", f"    :parameters ({_typed(action.parameters)})"]
    lines.append(f"    :precondition {write_formula(action.precondition, 18)}")
    lines.append(f"    :effect {write_formula(action.effect, 12)})")
    return "\n".join(lines)


def _durative(action: DurativeAction) -> str:
    duration = action.duration if isinstance(action.duration, FluentTerm) else _number(action.duration)
    lines = [
        f"  (:durative-action {action.name}",
        f"    :parameters ({_typed(action.parameters)})",
        f"    :duration (= ?duration {duration})",
    ]
    for key, parts in (
        (":condition", (("at start", action.at_start), ("over all", action.over_all), ("at end", action.at_end))),
        (":effect", (("at start", action.start_effect), ("at end", action.end_effect))),
    ):
        timed = [f"({when} {write_formula(part, 8)})" for when, part in parts if part != And(())]
        lines.append(f"    {key} (and" + "".join(f"\n      {t}" for t in timed) + ")")
    lines[-1] += ")"
    return "\n".join(lines)


def _axiom(axiom: Axiom) -> str:
    head = f"({' '.join((axiom.predicate, _typed(axiom.parameters)))})".replace(" )", ")")
    return f"  (:derived {head}\n    {write_formula(axiom.body, 4)})"


def _types(types: dict[str, tuple[str, ...]]) -> str:
    by_parent: dict[str, list[str]] = {}
    for child in sorted(types):
        for parent in types[child] or (OBJECT,):
            by_parent.setdefault(parent, []).append(child)
    groups = [f"{' '.join(children)} - {parent}" for parent, children in sorted(by_parent.items())]
    return "(:types\n    " + "\n    ".join(groups) + ")"


def write_domain(domain: Domain) -> str:
    """The domain as PDDL text.

    Args:
        domain: the domain.

    Returns:
        Text that :func:`alica.prophet.pddl.parse_domain` reads back to an equal domain.
    """
    parts = [f"(define (domain {domain.name})", f"  {_requirements(domain.requirements, domain.extra_requirements)}"]
    if domain.types:
        parts.append(f"  {_types(domain.types)}")
    if domain.constants:
        parts.append(f"  (:constants {_typed(domain.constants)})")
    if domain.predicates:
        decls = "\n    ".join(
            f"({' '.join((p.name, _typed(p.parameters)))})".replace(" )", ")") for p in domain.predicates
        )
        parts.append(f"  (:predicates\n    {decls})")
    if domain.functions:
        decls = "\n    ".join(
            f"({' '.join((f.name, _typed(f.parameters)))}) - number".replace(" )", ")") for f in domain.functions
        )
        parts.append(f"  (:functions\n    {decls})")
    parts.extend(_axiom(a) for a in domain.axioms)
    parts.extend(_action(a) for a in domain.actions)
    parts.extend(_durative(a) for a in domain.durative_actions)
    return "\n".join(parts) + ")\n"


def write_problem(problem: Problem) -> str:
    """The problem as PDDL text.

    Args:
        problem: the problem.

    Returns:
        Text that :func:`alica.prophet.pddl.parse_problem` reads back to an equal problem.
    """
    parts = [f"(define (problem {problem.name})", f"  (:domain {problem.domain_name})"]
    if problem.requirements or problem.extra_requirements:
        parts.append(f"  {_requirements(problem.requirements, problem.extra_requirements)}")
    if problem.objects:
        parts.append(f"  (:objects {_typed(problem.objects)})")
    init = []
    for item in problem.init:
        init.append(str(item) if isinstance(item, Atom) else f"(= {item.fluent} {_number(item.value)})")
    parts.append("  (:init" + "".join(f"\n    {fact}" for fact in init) + ")")
    parts.append(f"  (:goal {write_formula(problem.goal, 9)})")
    if problem.metric is not None:
        parts.append(f"  (:metric {problem.metric.direction} {problem.metric.expression})")
    return "\n".join(parts) + ")\n"


__all__ = ["FluentValue", "write_domain", "write_formula", "write_problem"]
