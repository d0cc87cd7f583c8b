"""Turn a :class:`~alica.model.Document` into plain data, the inverse of :mod:`alica.io.build`.

Defaults are left out so written files stay short, unless the file the
document was read from wrote them: given that file's tree as ``source``, a
value written there (``default_priority: 0``, ``success_required: false``)
is written again. Reading the data back gives an equal document.
"""

from __future__ import annotations

import math
from typing import Any

from alica.io.tree import Node
from alica.model import (
    Behaviour,
    ChildRef,
    Condition,
    Constraint,
    Declaration,
    Document,
    EntryPoint,
    Plan,
    PlanningProblem,
    PlanType,
    Role,
    RoleSet,
    SkillDeclaration,
    SkillParameter,
    State,
    StateKind,
    Task,
    Transition,
    UtilityFunction,
    Variable,
)
from alica.source import SourceSpan

Data = dict[str, Any]
Keys = frozenset[str]

_NONE: Keys = frozenset()


def document_data(doc: Document, source: Node | None = None) -> Data:
    """The document as plain data in the order of the YAML format.

    Args:
        doc: the document.
        source: the tree ``doc`` was built from (as read from its file); every
            key written there is kept, even when its value is the default.
    """
    return _Dumper(source).document(doc)


def _put(out: Data, key: str, value: Any, written: Keys, default: Any = None) -> None:
    """Set ``out[key]`` unless the value is absent, or the default and not written in the source."""
    if value is None:
        return
    if key in written or (value != default and value not in ((), [], {})):
        out[key] = value


def _number(value: float) -> int | float:
    return int(value) if float(value).is_integer() else value


def _cond(cond: Condition | None) -> str | None:
    return cond.text if cond is not None else None


def _typed(variables: tuple[Variable, ...]) -> list[Any]:
    """``name``, ``name - type``, ``name - type[low, high]``, or a mapping when there are candidates."""
    return [_variable(v) for v in variables]


def _variable(v: Variable) -> Any:
    both = v.low is not None and v.high is not None
    if v.candidates is None and (both or (v.low is None and v.high is None)):
        text = v.name if v.type == "any" and not both else f"{v.name} - {v.type}"
        return f"{text}[{_bound_text(v.low)}, {_bound_text(v.high)}]" if both else text
    out: Data = {"name": v.name}
    if v.type != "any":
        out["type"] = v.type
    if both:
        out["range"] = [_bound_number(v.low), _bound_number(v.high)]
    else:
        _put(out, "min", _bound_number(v.low), _NONE)
        _put(out, "max", _bound_number(v.high), _NONE)
    _put(out, "candidates", v.candidates, _NONE)
    return out


def _bound_number(value: float | None) -> int | float | None:
    """A bound as a whole number when it is one (and small enough to stay exact)."""
    if value is None:
        return None
    return int(value) if math.isfinite(value) and value.is_integer() and abs(value) < 1e15 else value


def _bound_text(value: float | None) -> str:
    number = _bound_number(value)
    if isinstance(number, float) and math.isinf(number):
        return "inf" if number > 0 else "-inf"
    return repr(number)


def _declaration(d: Declaration) -> Any:
    """``name/arity``, or a mapping when there is a doc line."""
    if not d.doc:
        return str(d)
    return {"name": d.name, "arity": d.arity, "doc": d.doc}


def _param(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_param(v) for v in value]
    return value


class _Dumper:
    """Writes the elements of one document; knows which keys the source wrote for each element."""

    def __init__(self, source: Node | None) -> None:
        self.source = source
        self.mappings: dict[tuple[int, int], Node] = {}
        if source is not None:
            self._index(source)

    def _index(self, node: Node) -> None:
        if isinstance(node.value, dict):
            self.mappings.setdefault((node.span.line, node.span.column), node)
            for child in node.value.values():
                self._index(child)
        elif isinstance(node.value, list):
            for child in node.value:
                self._index(child)

    def node(self, span: SourceSpan | None) -> Node | None:
        """The source mapping an element was built from (found by its place in the file)."""
        if span is None:
            return None
        return self.mappings.get((span.line, span.column))

    def written(self, span: SourceSpan | None, *path: str) -> Keys:
        """The keys the source wrote for the element at ``span`` (or for its sub-mapping at ``path``)."""
        node = self.node(span)
        for key in path:
            if node is None or not isinstance(node.value, dict):
                return _NONE
            node = node.value.get(key)
        if node is None or not isinstance(node.value, dict):
            return _NONE
        return frozenset(node.value)

    def document(self, doc: Document) -> Data:
        top = self.source.value if self.source is not None else None
        written = frozenset(top) if isinstance(top, dict) else _NONE
        out: Data = {}
        _put(out, "imports", list(doc.imports), written)
        _put(out, "predicates", [_declaration(d) for d in doc.predicates], written)
        _put(out, "functions", [_declaration(d) for d in doc.functions], written)
        _put(out, "skills", [self.skill(s) for s in doc.skills], written)
        _put(out, "tasks", [self.task(t) for t in doc.tasks], written)
        _put(out, "rolesets", [self.roleset(r) for r in doc.rolesets], written)
        _put(out, "behaviours", [self.behaviour(b) for b in doc.behaviours], written)
        _put(out, "plans", [self.plan(p) for p in doc.plans], written)
        _put(out, "plantypes", [self.plantype(p) for p in doc.plantypes], written)
        _put(out, "problems", [self.problem(p) for p in doc.problems], written)
        return out

    def skill(self, skill: SkillDeclaration) -> Data:
        written = self.written(skill.span)
        out: Data = {"name": skill.name}
        _put(out, "doc", skill.doc, written, "")
        _put(out, "capabilities", sorted(skill.capabilities), written)
        _put(out, "params", [self.skill_parameter(p) for p in skill.params], written)
        return out

    def skill_parameter(self, p: SkillParameter) -> Data:
        written = self.written(p.span)
        out: Data = {"name": p.name}
        _put(out, "type", p.type, written, "any")
        _put(out, "required", p.required, written, p.default is None)
        if p.default is not None:  # an empty list is a default too
            out["default"] = _param(p.default)
        _put(out, "doc", p.doc, written, "")
        return out

    def task(self, task: Task) -> Any:
        written = self.written(task.span)
        if not task.description and "description" not in written:
            return task.name
        return {"name": task.name, "description": task.description}

    def roleset(self, rs: RoleSet) -> Data:
        written = self.written(rs.span)
        out: Data = {"name": rs.name}
        _put(out, "description", rs.description, written, "")
        _put(out, "default_priority", _number(rs.default_priority), written, 0)
        out["roles"] = [self.role(r) for r in rs.roles]
        return out

    def role(self, role: Role) -> Data:
        written = self.written(role.span)
        out: Data = {"name": role.name}
        _put(out, "description", role.description, written, "")
        _put(out, "requires", sorted(role.requires), written)
        _put(out, "priorities", {p.task: _number(p.value) for p in role.priorities}, written)
        return out

    def behaviour(self, b: Behaviour) -> Data:
        written = self.written(b.span)
        out: Data = {"name": b.name}
        _put(out, "description", b.description, written, "")
        out["skill"] = b.skill
        _put(out, "variables", _typed(b.variables), written)
        _put(out, "params", {p.name: _param(p.value) for p in b.params}, written)
        _put(out, "pre", _cond(b.pre), written)
        _put(out, "run", _cond(b.run), written)
        _put(out, "post", _cond(b.post), written)
        _put(out, "frequency", _number(b.frequency), written, 0)
        return out

    def plan(self, plan: Plan) -> Data:
        written = self.written(plan.span)
        out: Data = {"name": plan.name}
        _put(out, "description", plan.description, written, "")
        _put(out, "variables", _typed(plan.variables), written)
        _put(out, "pre", _cond(plan.pre), written)
        _put(out, "run", _cond(plan.run), written)
        _put(out, "frequency", _number(plan.frequency), written, 0)
        _put(out, "utility", self.utility(plan.utility, self.written(plan.span, "utility")), written)
        _put(out, "constraints", [self.constraint(c) for c in plan.constraints], written)
        if plan.signature is not None:
            sig_written = self.written(plan.span, "signature")
            sig: Data = {}
            _put(sig, "parameters", _typed(plan.signature.parameters), sig_written)
            _put(sig, "precondition", _cond(plan.signature.precondition), sig_written)
            _put(sig, "effect", _cond(plan.signature.effect), sig_written)
            _put(sig, "cost", _number(plan.signature.cost), sig_written, 1)
            if plan.signature.duration is not None:
                _put(sig, "duration", _number(plan.signature.duration), sig_written)
            out["signature"] = sig
        out["entry_points"] = [self.entry_point(ep) for ep in plan.entry_points]
        out["states"] = [self.state(s, plan.out_transitions(s.name)) for s in plan.states]
        _put(out, "synchronisations", [self.sync(s) for s in plan.synchronisations], written)
        return out

    def utility(self, u: UtilityFunction, written: Keys) -> Data:
        out: Data = {}
        default_priority = 1.0 if not u.summands else 0.0
        _put(out, "priority_weight", _number(u.priority_weight), written, default_priority)
        _put(out, "similarity_weight", _number(u.similarity_weight), written, 0)
        _put(out, "threshold", _number(u.threshold), written, _number(0.1))
        summands = [{"name": s.name, "weight": _number(s.weight), "expression": s.expression} for s in u.summands]
        _put(out, "summands", summands, written)
        return out

    def constraint(self, c: Constraint) -> Data:
        out: Data = {"name": c.name}
        if c.text or not c.utility:
            out["formula"] = c.text
        _put(out, "utility", c.utility, _NONE, "")
        _put(out, "variables", list(c.variables), _NONE)
        return out

    def entry_point(self, ep: EntryPoint) -> Data:
        written = self.written(ep.span)
        out: Data = {}
        if ep.name != ep.task or "name" in written:
            out["name"] = ep.name
        out["task"] = ep.task
        _put(out, "state", ep.state, written)
        _put(out, "min", ep.min, written, 0)
        if not math.isinf(ep.max):
            out["max"] = int(ep.max)
        elif "max" in written:
            out["max"] = "*"
        _put(out, "success_required", ep.success_required, written, False)
        return out

    def state(self, state: State, transitions: tuple[Transition, ...]) -> Data:
        written = self.written(state.span)
        out: Data = {"name": state.name}
        _put(out, "kind", state.kind.value, written, StateKind.NORMAL.value)
        _put(out, "description", state.description, written, "")
        _put(out, "children", [self.child(c) for c in state.children], written)
        _put(out, "post", _cond(state.post), written)
        _put(out, "transitions", [self.transition(t) for t in transitions], written)
        return out

    def child(self, child: ChildRef) -> Any:
        if not child.bindings:
            return child.name
        return {"ref": child.name, "bind": {b.variable: b.value for b in child.bindings}}

    def transition(self, t: Transition) -> Data:
        written = self.written(t.span)
        out: Data = {}
        if t.name != f"{t.source}->{t.target}" or "name" in written:
            out["name"] = t.name
        out["to"] = t.target
        _put(out, "condition", _cond(t.condition), written)
        _put(out, "sync", t.synchronisation, written)
        return out

    def sync(self, s: Any) -> Data:
        written = self.written(s.span)
        out: Data = {"name": s.name, "transitions": list(s.transitions)}
        _put(out, "talk_timeout", _number(s.talk_timeout), written, _number(0.03))
        _put(out, "sync_timeout", _number(s.sync_timeout), written, 10)
        _put(out, "fail_on_timeout", s.fail_on_timeout, written, False)
        return out

    def plantype(self, pt: PlanType) -> Data:
        written = self.written(pt.span)
        out: Data = {"name": pt.name}
        _put(out, "description", pt.description, written, "")
        out["plans"] = list(pt.plans)
        return out

    def problem(self, p: PlanningProblem) -> Data:
        written = self.written(p.span)
        out: Data = {"name": p.name}
        _put(out, "description", p.description, written, "")
        out["elements"] = list(p.elements)
        _put(out, "wait_plan", p.wait_plan, written)
        _put(out, "alternative_plan", p.alternative_plan, written)
        _put(out, "update_time", _number(p.update_time), written, 1)
        _put(out, "timeout", _number(p.timeout), written, 60)
        _put(out, "planner", p.planner, written, "builtin")
        _put(out, "objects", _typed(p.objects), written)
        _put(out, "world", _cond(p.world), written)
        out["goal"] = p.goal.text
        return out
