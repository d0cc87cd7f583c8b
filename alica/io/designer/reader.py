"""Read a designer file's JSON into the records of :mod:`alica.io.designer.records`.

Every value is read through :class:`~alica.io.designer.json_view.View`, so a
value of the wrong type is an error at its key and never a guess; a file that
is not JSON is an error at its line and column.
"""

from __future__ import annotations

import json
from collections.abc import Callable

from alica.io.designer.json_view import Sink, View, parse_ref
from alica.io.designer.records import (
    UNBOUNDED_CARDINALITY,
    AnnotatedPlan,
    BehaviourRec,
    Cond,
    ConditionRepoRec,
    EntryRec,
    FileRec,
    KeyMap,
    PlaceholderRec,
    PlanRec,
    PlanTypeRec,
    Priority,
    RepoCondition,
    RoleRec,
    RoleSetRec,
    StateRec,
    SyncRec,
    TaskRec,
    TaskRepoRec,
    TransitionRec,
    Var,
    VarBinding,
    Wrapper,
)
from alica.io.designer.report import FileError


def read_file(text: str, file: str) -> tuple[FileRec | None, list[FileError]]:
    """Read one designer file.

    Args:
        text: the file's contents.
        file: its path relative to the source folder; its extension says what it holds.

    Returns:
        The record (``None`` when the file cannot be read at all) and every problem found.
    """
    try:
        data: object = json.loads(text)
    except json.JSONDecodeError as exc:
        return None, [FileError(file, "", f"bad JSON: {exc.msg}", exc.lineno, exc.colno)]
    except RecursionError:
        return None, [FileError(file, "", "bad JSON: nested too deep")]
    sink = Sink(file)
    if not isinstance(data, dict):
        return None, [FileError(file, "", "a designer file must hold a JSON object")]
    top = View(data, "", sink)
    ext = file.rsplit(".", 1)[-1].lower()
    readers: dict[str, Callable[[View, str], FileRec]] = {
        "pml": _plan,
        "beh": _behaviour,
        "pty": _plantype,
        "rst": _roleset,
        "tsk": _taskrepo,
        "cnd": _condrepo,
        "plh": _placeholder,
    }
    record = readers[ext](top, file)
    return record, sink.errors


def _id(view: View) -> int:
    value = view.ident("id")
    if value is None:
        if not view.has("id"):  # a value of the wrong type is reported by ident()
            view.sink.add(view.path("id"), "missing id")
        return 0
    return value


def _cond(view: View, name: str) -> Cond | None:
    c = view.obj(name)
    if c is None:
        return None
    return Cond(
        _id(c),
        c.text("name"),
        c.text("comment"),
        c.text("conditionString"),
        c.flag("enabled", True),
        len(c.items("quantifiers")),
        len(c.items("variables")),
        c.key,
    )


def _variables(view: View) -> tuple[Var, ...]:
    return tuple(Var(_id(v), v.text("name"), v.text("variableType"), v.key) for v in view.objects("variables"))


def _keymap(view: View) -> tuple[tuple[KeyMap, ...], tuple[KeyMap, ...]]:
    mapping = view.obj("keyMapping")
    if mapping is None:
        return (), ()
    sides = []
    for side in ("input", "output"):
        sides.append(
            tuple(
                KeyMap(m.text("parentKey") if m.has("parentKey") else None, m.text("childKey"), m.scalar("value"))
                for m in mapping.objects(side)
            )
        )
    return sides[0], sides[1]


def _plan(top: View, file: str) -> PlanRec:
    states = []
    for s in top.objects("states"):
        wrappers = []
        for w in s.objects("confAbstractPlanWrappers"):
            inputs, outputs = _keymap(w)
            target = w.ref("abstractPlan")
            if not w.has("abstractPlan"):
                w.sink.add(w.path("abstractPlan"), "the child names no plan, behaviour or plan type")
            wrappers.append(Wrapper(_id(w), target, w.has("configuration"), inputs, outputs, w.key))
        bindings = tuple(
            VarBinding(b.ident("variable"), b.ref("subPlan"), b.ref("subVariable"), b.key)
            for b in s.objects("variableBindings")
        )
        kind = s.text("type", "State")
        if kind not in ("State", "TerminalState"):
            s.sink.add(s.path("type"), f"unknown state type '{kind}' (State or TerminalState)")
        terminal = kind == "TerminalState"
        states.append(
            StateRec(
                _id(s),
                s.text("name"),
                s.text("comment"),
                terminal,
                s.flag("success", True),
                _cond(s, "postCondition"),
                tuple(wrappers),
                bindings,
                s.key,
            )
        )
    entries = [
        EntryRec(
            _id(e),
            e.text("name"),
            e.ref("task"),
            e.ident("state"),
            e.integer("minCardinality", 0),
            e.integer("maxCardinality", UNBOUNDED_CARDINALITY),
            e.flag("successRequired"),
            e.flag("isDynamic"),
            e.key,
        )
        for e in top.objects("entryPoints")
    ]
    transitions = []
    for t in top.objects("transitions"):
        inputs, outputs = _keymap(t)
        transitions.append(
            TransitionRec(
                _id(t),
                t.text("name"),
                t.ident("inState"),
                t.ident("outState"),
                t.ref("condition"),
                inputs,
                outputs,
                _cond(t, "preCondition"),
                t.ident("synchronisation"),
                t.key,
            )
        )
    syncs = [
        SyncRec(
            _id(s),
            s.text("name"),
            s.ids("syncedTransitions"),
            s.number("talkTimeout", 30.0),
            s.number("syncTimeout", 10000.0),
            s.flag("failOnSyncTimeout"),
            s.key,
        )
        for s in top.objects("synchronisations")
    ]
    return PlanRec(
        file,
        _id(top),
        top.text("name"),
        top.text("comment"),
        top.flag("masterPlan"),
        top.number("frequency"),
        top.number("utilityThreshold", 0.1),
        top.flag("isInterface"),
        top.flag("inheritBlackboard"),
        len(top.items("blackboard")),
        top.text("implementationName"),
        _variables(top),
        _cond(top, "preCondition"),
        _cond(top, "runtimeCondition"),
        tuple(entries),
        tuple(states),
        tuple(transitions),
        tuple(syncs),
    )


def _behaviour(top: View, file: str) -> BehaviourRec:
    return BehaviourRec(
        file,
        _id(top),
        top.text("name"),
        top.text("comment"),
        top.number("frequency"),
        top.truthy("deferring"),
        top.flag("eventDriven"),
        top.flag("isInterface"),
        top.flag("inheritBlackboard"),
        len(top.items("blackboard")),
        top.text("implementationName"),
        _variables(top),
        _cond(top, "preCondition"),
        _cond(top, "runtimeCondition"),
        _cond(top, "postCondition"),
    )


def _plantype(top: View, file: str) -> PlanTypeRec:
    plans = tuple(AnnotatedPlan(p.ref("plan"), p.flag("activated", True), p.key) for p in top.objects("annotatedPlans"))
    return PlanTypeRec(
        file,
        _id(top),
        top.text("name"),
        top.text("comment"),
        plans,
        len(top.items("variableBindings")),
        _variables(top),
    )


def _roleset(top: View, file: str) -> RoleSetRec:
    roles = []
    for r in top.objects("roles"):
        priorities = []
        for task, value in r.entries("taskPriorities"):
            number = value.value
            if isinstance(number, (int, float)) and not isinstance(number, bool):
                priority = float(number)
            else:
                r.sink.add(value.key, "a task priority must be a number")
                continue
            ref = parse_ref(task, value.key, r.sink)
            priorities.append(Priority(ref, priority, value.key))
        roles.append(
            RoleRec(
                _id(r), r.text("name"), r.text("comment"), tuple(priorities), len(r.items("characteristics")), r.key
            )
        )
    return RoleSetRec(
        file,
        _id(top),
        top.text("name"),
        top.text("comment"),
        top.number("defaultPriority", 0.0),
        top.flag("defaultRoleSet"),
        tuple(roles),
    )


def _taskrepo(top: View, file: str) -> TaskRepoRec:
    tasks = tuple(TaskRec(_id(t), t.text("name"), t.text("comment"), t.key) for t in top.objects("tasks"))
    return TaskRepoRec(file, _id(top), top.text("name"), tasks)


def _condrepo(top: View, file: str) -> ConditionRepoRec:
    conditions = []
    for c in top.objects("conditions"):
        inputs = tuple(
            (b.text("key"), b.text("type")) for b in c.objects("blackboard") if b.text("access", "input") == "input"
        )
        conditions.append(
            RepoCondition(_id(c), c.text("name"), c.text("comment"), c.text("libraryName"), inputs, c.key)
        )
    return ConditionRepoRec(file, _id(top), top.text("name"), tuple(conditions))


def _placeholder(top: View, file: str) -> PlaceholderRec:
    return PlaceholderRec(file, _id(top), top.text("name"))
