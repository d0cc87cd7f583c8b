"""``alica solve``: solve a plan's constraints offline for a team, as the engine would at run time.

The team is allocated to the plan's entry points as the engine's initial
allocation does; ``agents(E)`` then lists the agents of entry point, task or
state ``E``. The world the formulas read comes from ``--fact`` literals and a
``--world`` YAML file::

    objects: {Frontier: [f1, f2, f3]}        # objects by type
    values:                                  # function values: name -> argument -> value
      Pos: {f1: [1.0, 2.0], f2: [6.0, 0.5], scout: [0.0, 0.0]}
      gain: {f1: 3.5, f2: 1.0}
    facts: ["found(a)"]                      # literals, as --fact takes them

It prints each agent's values and whether each hard constraint holds.
JSON (``--json``): ``status`` (``solved``, ``infeasible``, ``timeout``),
``values`` (agent -> variable -> value; static variables under ``""``),
``utility``, ``time_s``, ``satisfied`` (constraint -> bool), ``assignment``
(agent -> entry point) and ``reason``.

Exit codes: 0 solved, 1 bad input, 2 wrong usage, 3 infeasible, 4 no
solution within the time limit.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.allocation import AgentSpec
    from alica.lang import FactBase
    from alica.model import Document, Plan, PlanLibrary
    from alica.solver.query import Place

EXIT_OK, EXIT_ERROR, EXIT_INFEASIBLE, EXIT_TIMEOUT = 0, 1, 3, 4


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``solve`` subcommand to the ``alica`` parser."""
    from alica.app.cli_plan import _positive
    from alica.app.skill_options import add_skills_option

    p = sub.add_parser(
        "solve",
        help="solve a plan's constraints offline for a team and print every agent's values",
        description="Allocate the team to a plan's entry points, solve the plan's constraints (its variables: "
        "real, int, point or objects of a type) and print every agent's values and which constraints hold. "
        "Exit 0 solved, 1 bad input, 3 infeasible, 4 no solution within the time limit.",
    )
    p.add_argument("plan", metavar="PLANFILE", help="a plan file")
    p.add_argument(
        "--plan", dest="name", metavar="NAME", help="the plan (default: the file's first plan with constraints)"
    )
    p.add_argument("--agents", required=True, metavar="NAME[:ROLE],...", help="the team, e.g. r1:Robot,r2:Robot")
    p.add_argument("--roleset", help="the role set (default: the one holding the agents' roles)")
    p.add_argument(
        "--fact",
        action="append",
        default=[],
        metavar="LITERALS",
        help="facts of the world, e.g. 'found(a)' (repeatable)",
    )
    p.add_argument("--world", metavar="FILE", help="a YAML file with objects, function values and facts")
    p.add_argument(
        "--at",
        action="append",
        default=[],
        metavar="AGENT=STATE,...",
        help="put agents in states of the plan instead of their entry point's initial state (and under the entry "
        "point the state belongs to), for constraints over agents(STATE) (repeatable)",
    )
    p.add_argument("--time-limit", type=_positive, default=1.0, metavar="S", help="seconds of search (default 1)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    add_skills_option(p)
    p.set_defaults(run=cmd_solve)


def cmd_solve(args: argparse.Namespace) -> int:
    """Run the ``solve`` subcommand; returns the exit code."""
    from alica.app.options import parse_roster
    from alica.app.plan_entry import agent_roles, load_entry
    from alica.app.skill_options import skill_registry
    from alica.io import Loader
    from alica.solver import solve
    from alica.solver.query import Level, collect

    library, entry = load_entry(args.plan, Loader(skills=skill_registry(args)))
    plan = _pick_plan(library, entry, args.name, args.plan)
    roles = agent_roles(library, parse_roster(args.agents), args.roleset)
    places = _allocate(library, plan, roles, args.roleset)
    _place(plan, places, args.at)
    belief = _world(args.world, args.fact)
    query = collect([Level(plan.name, plan, places)], belief)
    if not query.problem.variables:
        raise AlicaError(f"plan '{plan.name}' has no variable its constraints read; nothing to solve")
    solution = solve(query.problem, time_limit=args.time_limit)
    values: dict[str, dict[str, object]] = {}
    for var, value in sorted(solution.values.items(), key=lambda item: (item[0].agent or "", item[0].name)):
        values.setdefault(var.agent or "", {})[var.name] = _plain(value)
    result = {
        "status": solution.status,
        "plan": plan.name,
        "values": values,
        "utility": None if math.isnan(solution.utility) else solution.utility,
        "time_s": round(solution.time_s, 6),
        "optimal": solution.optimal,
        "satisfied": dict(solution.satisfied),
        "assignment": {agent: place[0] for agent, place in sorted(places.items())},
        "states": {agent: place[1] for agent, place in sorted(places.items())},
        "reason": solution.reason,
    }
    if args.json:
        print(json.dumps(result, indent=2, sort_keys=True))
    else:
        _print(result)
    return {"solved": EXIT_OK, "infeasible": EXIT_INFEASIBLE}.get(solution.status, EXIT_TIMEOUT)


def _pick_plan(library: PlanLibrary, entry: Document, name: str | None, path: str) -> Plan:
    if name is not None:
        if name not in library.plans:
            raise AlicaError(f"{path} has no plan named '{name}'; plans: {', '.join(sorted(library.plans))}")
        return library.plans[name]
    for plan in entry.plans:
        if plan.constraints:
            return plan
    raise AlicaError(f"{path} defines no plan with constraints; name one with --plan")


def _allocate(
    library: PlanLibrary, plan: Plan, roles: dict[str, str | AgentSpec], roleset_name: str | None
) -> dict[str, Place]:
    """Agent -> (entry point, its initial state), as the engine's initial allocation gives them."""
    from alica.allocation import AgentSpec, AllocationProblem, allocate, assign_roles
    from alica.engine import pick_roleset

    specs = {n: s if isinstance(s, AgentSpec) else AgentSpec(role=s) for n, s in sorted(roles.items())}
    roleset = pick_roleset(library, (s.role for s in specs.values()), roleset_name)
    role_of = assign_roles(specs, roleset)
    result = allocate(AllocationProblem(tuple(sorted(specs)), role_of, roleset, (plan,)))
    if result.assignment is None:
        raise AlicaError(f"the team cannot run plan '{plan.name}': {result.why}")
    places: dict[str, Place] = {}
    for agent, ep in result.assignment.entries:
        places[agent] = (ep, plan.entry_point(ep).state if ep is not None else None)
    return places


def _place(plan: Plan, places: dict[str, Place], texts: list[str]) -> None:
    """Move agents to the states ``--at`` names (and to the entry point a state lies under, if it is another)."""
    for text in texts:
        for part in (p.strip() for p in text.split(",") if p.strip()):
            agent, _, state = part.partition("=")
            agent, state = agent.strip(), state.strip()
            if not state:
                raise AlicaError(f"--at: '{part}' is not AGENT=STATE")
            if agent not in places:
                raise AlicaError(f"--at: '{agent}' is not one of the agents ({', '.join(sorted(places))})")
            entry = places[agent][0]
            under = [ep.name for ep in plan.entry_points if state in plan.reachable_states(ep.name)]
            if not under:
                raise AlicaError(
                    f"--at: plan '{plan.name}' has no state '{state}' (states: "
                    f"{', '.join(sorted(s.name for s in plan.states))})"
                )
            if entry not in under:
                entry = under[0]  # the state lies under another entry point: the agent takes that one
            places[agent] = (entry, state)


def _world(path: str | None, facts: list[str]) -> FactBase:
    """The belief the formulas read: ``--world`` objects, values and facts, then ``--fact`` literals."""
    from alica.lang import FactBase, literals

    base = FactBase()
    texts = list(facts)
    if path is not None:
        data = _read_world(path)
        for type_name, objects in (data.get("objects") or {}).items():
            for obj in _listed(objects, f"{path}: objects.{type_name}"):
                base.add_object(_value(obj), str(type_name))
        for func, table in (data.get("values") or {}).items():
            if not isinstance(table, dict):
                raise AlicaError(f"{path}: values.{func} must map arguments to values, e.g. {{f1: 3.5}}")
            for arg, value in table.items():
                args = tuple(_value(a) for a in arg) if isinstance(arg, (list, tuple)) else (_value(arg),)
                base.set(str(func), *args, value=_value(value))
        texts.extend(str(f) for f in _listed(data.get("facts") or [], f"{path}: facts"))
    for text in texts:
        for positive, pred, args in literals(text):
            if positive:
                base.add(pred, *args)
            else:
                base.remove(pred, *args)
    return base


def _read_world(path: str) -> dict[str, Any]:
    import yaml

    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise AlicaError(f"{path}: cannot read the world file: {exc}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        marked = exc if isinstance(exc, yaml.MarkedYAMLError) else None
        mark = marked.problem_mark if marked is not None else None
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark is not None else path
        raise AlicaError(f"{where}: error: not valid YAML: {marked.problem if marked is not None else exc}") from None
    if data is None:
        return {}
    if not isinstance(data, dict) or not set(data) <= {"objects", "values", "facts"}:
        raise AlicaError(f"{path}: a world file is a mapping with the keys objects, values and facts")
    return data


def _listed(value: object, where: str) -> list[object]:
    if not isinstance(value, list):
        raise AlicaError(f"{where} must be a list")
    return value


def _value(value: object) -> object:
    if isinstance(value, list):
        return tuple(_value(v) for v in value)
    if isinstance(value, float) and not math.isfinite(value):
        raise AlicaError(f"world values must be finite numbers, got {value}")
    if isinstance(value, (str, int, float, bool, tuple)) or value is None:
        return value
    raise AlicaError(f"world values are names, numbers or lists of them, not {value!r}")


def _plain(value: object) -> object:
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item"):
        return value.item()
    return value


def _print(result: dict[str, Any]) -> None:
    status = result["status"]
    print(f"plan {result['plan']}: {status}" + (f" ({result['reason']})" if result["reason"] else ""))
    if result["utility"] is not None:
        print(
            f"utility {result['utility']:.6g}, {result['time_s'] * 1000:.1f} ms"
            + (", optimal" if result["optimal"] else "")
        )
    for agent, values in sorted(result["values"].items()):
        shown = ", ".join(f"{k} = {_show(v)}" for k, v in sorted(values.items()))
        entry = result["assignment"].get(agent)
        where = f" [{entry}/{result['states'][agent]}]" if entry else ""
        print(f"  {agent or '(team)'}{where}: {shown}")
    for name, holds in sorted(result["satisfied"].items()):
        print(f"  {'holds' if holds else 'VIOLATED'}: {name}")


def _show(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        return "(" + ", ".join(_show(v) for v in value) + ")"
    return str(value)
