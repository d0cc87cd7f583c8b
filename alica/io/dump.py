"""Turn a :class:`~alica.model.Document` into plain data, the inverse of :mod:`alica.io.build`.

Defaults are left out so written files stay short; reading the data back
gives an equal document.
"""

from __future__ import annotations

import math
from typing import Any

from alica.model import (
    Behaviour,
    ChildRef,
    Condition,
    Declaration,
    Document,
    EntryPoint,
    Plan,
    PlanningProblem,
    PlanType,
    Role,
    RoleSet,
    State,
    StateKind,
    Task,
    Transition,
    UtilityFunction,
    Variable,
)

Data = dict[str, Any]


def document_data(doc: Document) -> Data:
    """The document as plain data in the order of the YAML format."""
    out: Data = {}
    if doc.imports:
        out["imports"] = list(doc.imports)
    if doc.predicates:
        out["predicates"] = [_declaration(d) for d in doc.predicates]
    if doc.functions:
        out["functions"] = [_declaration(d) for d in doc.functions]
    if doc.tasks:
        out["tasks"] = [_task(t) for t in doc.tasks]
    if doc.rolesets:
        out["rolesets"] = [_roleset(r) for r in doc.rolesets]
    if doc.behaviours:
        out["behaviours"] = [_behaviour(b) for b in doc.behaviours]
    if doc.plans:
        out["plans"] = [_plan(p) for p in doc.plans]
    if doc.plantypes:
        out["plantypes"] = [_plantype(p) for p in doc.plantypes]
    if doc.problems:
        out["problems"] = [_problem(p) for p in doc.problems]
    return out


def _put(out: Data, key: str, value: Any, default: Any = None) -> None:
    if value != default and value not in ((), [], {}):
        out[key] = value


def _number(value: float) -> int | float:
    return int(value) if float(value).is_integer() else value


def _cond(cond: Condition | None) -> str | None:
    return cond.text if cond is not None else None


def _typed(variables: tuple[Variable, ...]) -> list[str]:
    return [v.name if v.type == "any" else f"{v.name} - {v.type}" for v in variables]


def _declaration(d: Declaration) -> Any:
    """``name/arity``, or a mapping when there is a doc line."""
    if not d.doc:
        return str(d)
    return {"name": d.name, "arity": d.arity, "doc": d.doc}


def _task(task: Task) -> Any:
    if not task.description:
        return task.name
    return {"name": task.name, "description": task.description}


def _roleset(rs: RoleSet) -> Data:
    out: Data = {"name": rs.name}
    _put(out, "description", rs.description, "")
    _put(out, "default_priority", _number(rs.default_priority), 0)
    out["roles"] = [_role(r) for r in rs.roles]
    return out


def _role(role: Role) -> Data:
    out: Data = {"name": role.name}
    _put(out, "description", role.description, "")
    _put(out, "requires", sorted(role.requires))
    _put(out, "priorities", {p.task: _number(p.value) for p in role.priorities})
    return out


def _behaviour(b: Behaviour) -> Data:
    out: Data = {"name": b.name}
    _put(out, "description", b.description, "")
    out["skill"] = b.skill
    _put(out, "variables", _typed(b.variables))
    _put(out, "params", {p.name: _param(p.value) for p in b.params})
    _put(out, "pre", _cond(b.pre))
    _put(out, "run", _cond(b.run))
    _put(out, "post", _cond(b.post))
    _put(out, "frequency", _number(b.frequency), 0)
    return out


def _param(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_param(v) for v in value]
    return value


def _plan(plan: Plan) -> Data:
    out: Data = {"name": plan.name}
    _put(out, "description", plan.description, "")
    _put(out, "variables", _typed(plan.variables))
    _put(out, "pre", _cond(plan.pre))
    _put(out, "run", _cond(plan.run))
    _put(out, "frequency", _number(plan.frequency), 0)
    utility = _utility(plan.utility)
    _put(out, "utility", utility)
    _put(out, "constraints", [_constraint(c) for c in plan.constraints])
    if plan.signature is not None:
        sig: Data = {}
        _put(sig, "parameters", _typed(plan.signature.parameters))
        _put(sig, "precondition", _cond(plan.signature.precondition))
        _put(sig, "effect", _cond(plan.signature.effect))
        _put(sig, "cost", _number(plan.signature.cost), 1)
        out["signature"] = sig
    out["entry_points"] = [_entry_point(ep) for ep in plan.entry_points]
    out["states"] = [_state(s, plan.out_transitions(s.name)) for s in plan.states]
    _put(out, "synchronisations", [_sync(s) for s in plan.synchronisations])
    return out


def _utility(u: UtilityFunction) -> Data:
    out: Data = {}
    default_priority = 1.0 if not u.summands else 0.0
    _put(out, "priority_weight", _number(u.priority_weight), default_priority)
    _put(out, "similarity_weight", _number(u.similarity_weight), 0)
    _put(out, "threshold", _number(u.threshold), _number(0.1))
    _put(
        out, "summands", [{"name": s.name, "weight": _number(s.weight), "expression": s.expression} for s in u.summands]
    )
    return out


def _constraint(c: Any) -> Data:
    out: Data = {"name": c.name, "formula": c.text}
    _put(out, "variables", list(c.variables))
    return out


def _entry_point(ep: EntryPoint) -> Data:
    out: Data = {}
    if ep.name != ep.task:
        out["name"] = ep.name
    out["task"] = ep.task
    _put(out, "state", ep.state)
    _put(out, "min", ep.min, 0)
    if not math.isinf(ep.max):
        out["max"] = int(ep.max)
    _put(out, "success_required", ep.success_required, False)
    return out


def _state(state: State, transitions: tuple[Transition, ...]) -> Data:
    out: Data = {"name": state.name}
    _put(out, "kind", state.kind.value, StateKind.NORMAL.value)
    _put(out, "description", state.description, "")
    _put(out, "children", [_child(c) for c in state.children])
    _put(out, "post", _cond(state.post))
    _put(out, "transitions", [_transition(t) for t in transitions])
    return out


def _child(child: ChildRef) -> Any:
    if not child.bindings:
        return child.name
    return {"ref": child.name, "bind": {b.variable: b.value for b in child.bindings}}


def _transition(t: Transition) -> Data:
    out: Data = {}
    if t.name != f"{t.source}->{t.target}":
        out["name"] = t.name
    out["to"] = t.target
    _put(out, "condition", _cond(t.condition))
    _put(out, "sync", t.synchronisation)
    return out


def _sync(s: Any) -> Data:
    out: Data = {"name": s.name, "transitions": list(s.transitions)}
    _put(out, "talk_timeout", _number(s.talk_timeout), _number(0.03))
    _put(out, "sync_timeout", _number(s.sync_timeout), 10)
    _put(out, "fail_on_timeout", s.fail_on_timeout, False)
    return out


def _plantype(pt: PlanType) -> Data:
    out: Data = {"name": pt.name}
    _put(out, "description", pt.description, "")
    out["plans"] = list(pt.plans)
    return out


def _problem(p: PlanningProblem) -> Data:
    out: Data = {"name": p.name}
    _put(out, "description", p.description, "")
    out["elements"] = list(p.elements)
    _put(out, "wait_plan", p.wait_plan)
    _put(out, "alternative_plan", p.alternative_plan)
    _put(out, "update_time", _number(p.update_time), 1)
    _put(out, "timeout", _number(p.timeout), 60)
    _put(out, "planner", p.planner, "builtin")
    _put(out, "objects", _typed(p.objects))
    _put(out, "world", _cond(p.world))
    out["goal"] = p.goal.text
    return out
