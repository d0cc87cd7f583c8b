"""What the operator may do from the control center, checked before it reaches the team.

A goal is a conjunction of literals over the planning problem's predicates
(``on(a, b) and ontable(b)``), checked by the formula language as it is typed:
a syntax error, a part that is not a literal, an unknown predicate or a wrong
number of arguments comes back with its column. Facts are literals too. A
decision on a proposed plan names the generation it answers.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from alica.errors import AlicaError, FormulaError, PlannerError
from alica.lang.ast import Call, Name
from alica.lang.parser import parse
from alica.lang.walk import atoms, literal_text, literals
from alica.model import PlanLibrary

DECISIONS = ("accept", "decline", "modify")


def problems(library: PlanLibrary) -> dict[str, dict[str, Any]]:
    """Each planning problem of the library: its default goal, planner and the predicates a goal may use."""
    from alica.prophet.problem import predicate_types

    out: dict[str, dict[str, Any]] = {}
    for name, problem in sorted(library.problems.items()):
        try:
            predicates = {p: len(types) for p, types in predicate_types(problem, library).items()}
        except PlannerError:
            predicates = {}
        out[name] = {"goal": problem.goal.text, "planner": problem.planner, "predicates": predicates}
    return out


def _error(exc: FormulaError) -> dict[str, Any]:
    return {"ok": False, "error": exc.message, "column": exc.column, "hint": exc.hint}


def check_goal(known: Mapping[str, dict[str, Any]], problem: str, text: str) -> dict[str, Any]:
    """Check a goal for ``problem`` as the operator types it.

    Returns:
        ``{"ok": True, "literals": [...]}``, or ``{"ok": False, "error", "column", "hint"}``
        (column 1-based in ``text``).
    """
    if problem not in known:
        names = ", ".join(known) or "none"
        return {"ok": False, "error": f"no planning problem named '{problem}'", "column": 1, "hint": names}
    if not text.strip():
        return {"ok": False, "error": "the goal is empty", "column": 1, "hint": "write literals such as on(a, b)"}
    try:
        found = literals(text)
        nodes = atoms(parse(text), text=text)
    except FormulaError as exc:
        return _error(exc)
    predicates: dict[str, int] = known[problem]["predicates"]
    for node, (_, name, args) in zip(nodes, found, strict=True):
        column = node.column if isinstance(node, (Call, Name)) else 1
        if predicates and name.lower() not in predicates:
            return {
                "ok": False,
                "error": f"'{name}' is no predicate of {problem}'s domain",
                "column": column,
                "hint": "predicates: " + ", ".join(f"{p}/{n}" for p, n in sorted(predicates.items())),
            }
        wanted = predicates.get(name.lower())
        if wanted is not None and wanted != len(args):
            return {
                "ok": False,
                "error": f"'{name}' takes {wanted} argument{'s' * (wanted != 1)}, not {len(args)}",
                "column": column,
                "hint": "",
            }
    return {"ok": True, "literals": [literal_text(p, n, a) for p, n, a in found]}


def check_facts(text: str) -> dict[str, Any]:
    """Check facts the operator sets by hand (literals, ``not`` retracts one)."""
    if not text.strip():
        return {"ok": False, "error": "no facts given", "column": 1, "hint": "write literals such as found(s1)"}
    try:
        found = literals(text)
    except FormulaError as exc:
        return _error(exc)
    return {"ok": True, "literals": [literal_text(p, n, a) for p, n, a in found]}


def decision(body: Mapping[str, Any]) -> tuple[str, int, str, tuple[int, ...] | None, dict[str, str]]:
    """The problem, generation, action, step order and pins of a decision sent by the page.

    Raises:
        AlicaError: a field is missing or has the wrong type.
    """
    problem, generation, action = body.get("problem"), body.get("generation"), body.get("action")
    if not isinstance(problem, str) or not problem:
        raise AlicaError("a decision names its planning problem ('problem')")
    if not isinstance(generation, int) or isinstance(generation, bool):
        raise AlicaError("a decision names the generation of the plan it answers ('generation', a number)")
    if action not in DECISIONS:
        raise AlicaError(f"'action' must be one of {', '.join(DECISIONS)}, not {action!r}")
    order = body.get("order")
    if order is not None and (
        not isinstance(order, list) or not all(isinstance(i, int) and not isinstance(i, bool) for i in order)
    ):
        raise AlicaError("'order' lists the indices of the kept steps in their new order")
    pins = body.get("pins") or {}
    if not isinstance(pins, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in pins.items()):
        raise AlicaError("'pins' maps a task to the robot that must take it")
    return problem, generation, str(action), tuple(order) if order is not None else None, dict(pins)
