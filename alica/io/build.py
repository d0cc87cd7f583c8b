"""Turn a located tree (from YAML or XML) into a :class:`~alica.model.Document`.

Structural problems (wrong types, missing or unknown keys, bad numbers) are
collected, not raised, so a file shows every problem at once.
Cross-element checks live in :mod:`alica.io.validate`.
"""

from __future__ import annotations

import math
import re

from alica.io.fields import Fields, Problems, kind_of, to_number
from alica.io.skill_declarations import build_skills
from alica.io.tree import Node
from alica.lang.ast import KEYWORDS
from alica.model import (
    ANY_TYPE,
    UNBOUNDED,
    Behaviour,
    Binding,
    ChildRef,
    Condition,
    ConditionKind,
    Constraint,
    Declaration,
    Document,
    EntryPoint,
    Param,
    ParamValue,
    Plan,
    PlanningProblem,
    PlanningSignature,
    PlanType,
    Priority,
    Role,
    RoleSet,
    State,
    StateKind,
    Summand,
    Synchronisation,
    Task,
    Transition,
    UtilityFunction,
    Variable,
)
from alica.source import SourceSpan

#: Keys of the top level of a plan file.
TOP_KEYS = (
    "alica",
    "imports",
    "predicates",
    "functions",
    "skills",
    "tasks",
    "rolesets",
    "behaviours",
    "plans",
    "plantypes",
    "problems",
)
#: ``name`` or ``name - type``, the way typed names are written in both formats.
TYPED_NAME = re.compile(r"^\s*(\??[A-Za-z_][\w-]*)\s*(?:-\s*([A-Za-z_][\w-]*))?\s*$")
#: ``name/arity``, the short form of a predicate or function declaration.
DECLARED_NAME = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*/\s*([0-9]+)\s*$")
_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
#: ``name - type[low, high]``: a variable with a range (real, int and point variables).
RANGED_NAME = re.compile(r"^\s*(\??[A-Za-z_][\w-]*)\s*-\s*([A-Za-z_][\w-]*)\s*\[([^\[\]]*)\]\s*$")
#: ``type`` or ``type[low, high]``, a type in the ``name: type`` form of a variable list.
TYPE_RANGE = re.compile(r"^\s*([A-Za-z_][\w-]*)\s*(?:\[([^\[\]]*)\])?\s*$")


def build_document(tree: Node, path: str, problems: Problems) -> Document:
    """Build the document of one file.

    Args:
        tree: the file's located tree.
        path: the file's name, kept on the document.
        problems: where problems go.
    """
    if not tree.is_mapping:
        problems.add(
            tree.span,
            f"a plan file must be a mapping of sections, not {kind_of(tree)}",
            "start the file with 'plans:', 'tasks:' or another section",
        )
        return Document(path=path)
    top = Fields(tree, "the plan file", problems, TOP_KEYS)
    version = top.get("alica")
    if version is not None and str(version.value) not in ("1", "1.0"):
        problems.add(version.span, f"unknown format version '{version.value}'", "write 'alica: 1' or leave it out")
    return Document(
        imports=tuple(n for n, _ in top.names("imports")),
        predicates=_declarations(top, "predicates", problems),
        functions=_declarations(top, "functions", problems),
        skills=build_skills(top, problems),
        tasks=tuple(_task(n, problems) for n in top.items("tasks")),
        rolesets=tuple(_roleset(n, problems) for n in top.items("rolesets")),
        behaviours=tuple(_behaviour(n, problems) for n in top.items("behaviours")),
        plans=tuple(_plan(n, problems) for n in top.items("plans")),
        plantypes=tuple(_plantype(n, problems) for n in top.items("plantypes")),
        problems=tuple(_problem(n, problems) for n in top.items("problems")),
        path=path,
    )


def _element(node: Node, what: str, problems: Problems, keys: tuple[str, ...]) -> Fields | None:
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each entry of '{what}' must be a mapping with a 'name', not {kind_of(node)}",
            "write '- name: ...' and the element's keys",
        )
        return None
    label = node.value.get("name")  # type: ignore[union-attr]
    shown = f"{what.removesuffix('s')} '{label.value}'" if label is not None else what
    return Fields(node, shown, problems, keys)


def _condition(f: Fields, key: str, kind: ConditionKind) -> Condition | None:
    node = f.get(key)
    if node is None or node.value is None:
        return None
    if isinstance(node.value, bool):
        return Condition(kind, "true" if node.value else "false", span=node.span)
    if not isinstance(node.value, str):
        f.problems.add(
            node.span,
            f"'{key}' of {f.what} must be a formula written as text, not {kind_of(node)}",
            "quote the formula",
        )
        return None
    return Condition(kind, node.value.strip(), span=node.text_span(1 + len(node.value) - len(node.value.lstrip())))


def _typed(node: Node, f: Fields, key: str) -> Variable | None:
    """``name``, ``name - type``, ``name - type[low, high]`` or ``{name, type, range, min, max, candidates}``."""
    if node.is_mapping:
        return _typed_mapping(node, f, key)
    if isinstance(node.value, str):
        match = TYPED_NAME.match(node.value)
        if match:
            return Variable(match.group(1), match.group(2) or ANY_TYPE, span=node.span)
        match = RANGED_NAME.match(node.value)
        if match:
            low, high = _range_text(node, match.group(3), match.start(3) + 1, f, match.group(1))
            return Variable(match.group(1), match.group(2), low, high, span=node.span)
    f.problems.add(
        node.span,
        f"'{node.value}' in '{key}' of {f.what} is not 'name', 'name - type' or 'name - type[low, high]'",
        "write e.g. '?r - robot' or 'x - real[-10, 10]'",
    )
    return None


def _typed_mapping(node: Node, f: Fields, key: str) -> Variable:
    keys = ("name", "type", "range", "min", "max", "candidates")
    g = Fields(node, f"an entry of '{key}' in {f.what}", f.problems, keys)
    name = g.name()
    what = f"variable '{name}' in {f.what}"
    low = _bound(g, "min", what)
    high = _bound(g, "max", what)
    table = g.get("range")
    if table is not None and table.value is not None:
        if g.has("min") or g.has("max"):
            f.problems.add(table.span, f"{what} gives both 'range' and 'min'/'max'", "keep one of them")
        items = table.value if isinstance(table.value, list) else None
        if items is None or len(items) != 2:
            f.problems.add(
                table.span,
                f"'range' of {what} must be a list of two numbers [low, high]",
                "write e.g. range: [-10, 10]",
            )
        else:
            low, high = (_number_of(item, what, f.problems) for item in items)
    for given, missing in (("min", "max"), ("max", "min")):
        if g.has(given) and not g.has(missing) and table is None:
            f.problems.add(g.span_of(given), f"{what} gives '{given}' but no '{missing}'", f"add '{missing}:'")
    candidates = g.text("candidates").strip() or None
    return Variable(name, g.text("type", default=ANY_TYPE), low, high, candidates, span=node.span)


def _bound_number(value: object) -> float | None:
    """A bound as a number; YAML's ``.inf`` and ``.nan`` are read in text too (the validator rejects them)."""
    if isinstance(value, str) and value.strip().lower().lstrip("+-") in (".inf", ".nan"):
        value = value.strip().replace(".", "", 1)
    return to_number(value)


def _number_of(node: Node, what: str, problems: Problems) -> float | None:
    value = _bound_number(node.value)
    if value is None:
        problems.add(node.span, f"bound '{node.value}' of {what} is not a number", "write the range as numbers")
    return value


def _bound(g: Fields, key: str, what: str) -> float | None:
    node = g.get(key)
    if node is None or node.value is None:
        return None
    return _number_of(node, what, g.problems)


def _range_text(node: Node, text: str, column: int, f: Fields, name: str) -> tuple[float | None, float | None]:
    """``low, high`` written inside the brackets of a short form, starting at 1-based ``column`` of ``node``."""
    parts = text.split(",")
    what = f"variable '{name}' in {f.what}"
    if len(parts) != 2:
        f.problems.add(
            node.text_span(column), f"the range of {what} must be two numbers [low, high]", "write e.g. real[-10, 10]"
        )
        return None, None
    out: list[float | None] = []
    offset = column
    for part in parts:
        value = _bound_number(part)
        if value is None:
            lead = len(part) - len(part.lstrip())
            f.problems.add(
                node.text_span(offset + lead),
                f"bound '{part.strip()}' of {what} is not a number",
                "write the range as numbers, e.g. real[-10, 10]",
            )
        out.append(value)
        offset += len(part) + 1
    return out[0], out[1]


def _typed_list(f: Fields, key: str) -> tuple[Variable, ...]:
    node = f.get(key)
    if node is not None and node.is_mapping:  # name: type
        out = []
        for name, value in node.value.items():  # type: ignore[union-attr]
            span = node.key_span(name)
            if value.value is None:
                out.append(Variable(name, ANY_TYPE, span=span))
                continue
            match = TYPE_RANGE.match(str(value.value)) if isinstance(value.value, str) else None
            if match is None or match.group(2) is None:
                out.append(Variable(name, str(value.value), span=span))
                continue
            low, high = _range_text(value, match.group(2), match.start(2) + 1, f, name)
            out.append(Variable(name, match.group(1), low, high, span=span))
        return tuple(out)
    return tuple(v for v in (_typed(n, f, key) for n in f.items(key)) if v is not None)


def _declarations(top: Fields, key: str, problems: Problems) -> tuple[Declaration, ...]:
    """``name/arity`` or ``{name, arity, doc}`` entries of ``predicates`` or ``functions``."""
    out = []
    for node in top.items(key):
        declaration = _declaration(node, key, problems)
        if declaration is not None:
            out.append(declaration)
    return tuple(out)


def _declaration(node: Node, key: str, problems: Problems) -> Declaration | None:
    example = "found/1" if key == "predicates" else "pos/1"
    if isinstance(node.value, str):
        match = DECLARED_NAME.match(node.value)
        if match is None:
            problems.add(
                node.span,
                f"'{node.value}' in '{key}' is not 'name/arity'",
                f"write the name and its number of arguments, e.g. '{example}'",
            )
            return None
        return Declaration(match.group(1), int(match.group(2)), span=node.span)
    f = _element(node, key, problems, ("name", "arity", "doc"))
    if f is None:
        return None
    name = f.name()
    if not name:
        return None
    if not _IDENTIFIER.match(name) or name in KEYWORDS:
        problems.add(
            f.get("name").span,  # type: ignore[union-attr]
            f"'{name}' in '{key}' is not a name formulas can use",
            "use letters, digits and '_', starting with a letter, and no keyword",
        )
        return None
    if f.get("arity") is None:
        problems.add(node.span, f"{f.what} has no 'arity'", f"give its number of arguments, e.g. '{example}'")
        return None
    return Declaration(name, f.integer("arity", 0), f.text("doc"), span=node.span)


def _task(node: Node, problems: Problems) -> Task:
    if isinstance(node.value, str):
        return Task(node.value.strip(), span=node.span)
    f = _element(node, "tasks", problems, ("name", "description"))
    if f is None:
        return Task("", span=node.span)
    return Task(f.name(), f.text("description"), span=node.span)


def _roleset(node: Node, problems: Problems) -> RoleSet:
    f = _element(node, "rolesets", problems, ("name", "default_priority", "roles", "description"))
    if f is None:
        return RoleSet("", (), span=node.span)
    return RoleSet(
        f.name(),
        tuple(_role(n, problems) for n in f.items("roles", required=True, hint="list the team's roles under 'roles:'")),
        f.number("default_priority", 0.0),
        f.text("description"),
        span=node.span,
    )


def _role(node: Node, problems: Problems) -> Role:
    f = _element(node, "roles", problems, ("name", "priorities", "requires", "description"))
    if f is None:
        return Role("", span=node.span)
    priorities = []
    table = f.mapping("priorities")
    if table is not None:
        for task, value in table.value.items():  # type: ignore[union-attr]
            number = to_number(value.value)
            if number is None:
                problems.add(
                    value.span,
                    f"priority of role '{f.values.get('name', node).value}' for task '{task}' must be a number, not {kind_of(value)}",
                    "write a number in [-1, 1]; negative means the role cannot take the task",
                )
                continue
            priorities.append(Priority(task, number, span=table.key_span(task)))
    return Role(
        f.name(),
        tuple(priorities),
        frozenset(n for n, _ in f.names("requires")),
        f.text("description"),
        span=node.span,
    )


def _param_value(node: Node, problems: Problems, where: str) -> ParamValue:
    if isinstance(node.value, list):
        return tuple(_param_value(n, problems, where) for n in node.value)
    if isinstance(node.value, dict):
        problems.add(
            node.span,
            f"parameter value in {where} must be a value or a list, not a mapping",
            "flatten it into separate parameters",
        )
        return None
    return node.value


def _behaviour(node: Node, problems: Problems) -> Behaviour:
    keys = ("name", "skill", "params", "variables", "pre", "run", "post", "frequency", "description")
    f = _element(node, "behaviours", problems, keys)
    if f is None:
        return Behaviour("", "", span=node.span)
    params = []
    table = f.mapping("params")
    if table is not None:
        for key, value in table.value.items():  # type: ignore[union-attr]
            params.append(Param(key, _param_value(value, problems, f.what), span=table.key_span(key)))
    return Behaviour(
        f.name(),
        f.text("skill", required=True, hint="name the skill the behaviour runs, e.g. 'skill: MoveToPosition'").strip(),
        tuple(params),
        _typed_list(f, "variables"),
        _condition(f, "pre", ConditionKind.PRE),
        _condition(f, "run", ConditionKind.RUN),
        _condition(f, "post", ConditionKind.POST),
        f.number("frequency", 0.0, low=0.0),
        f.text("description"),
        span=node.span,
    )


def _plan(node: Node, problems: Problems) -> Plan:
    keys = (
        "name",
        "description",
        "entry_points",
        "states",
        "synchronisations",
        "variables",
        "pre",
        "run",
        "utility",
        "constraints",
        "signature",
        "frequency",
    )
    f = _element(node, "plans", problems, keys)
    if f is None:
        return Plan("", (), (), span=node.span)
    name = f.name()
    states: list[State] = []
    transitions: list[Transition] = []
    for state_node in f.items("states", required=True, hint="a plan needs at least one state under 'states:'"):
        state, outgoing = _state(state_node, name, problems)
        states.append(state)
        transitions.extend(outgoing)
    return Plan(
        name,
        tuple(
            _entry_point(n, name, problems)
            for n in f.items(
                "entry_points", required=True, hint="add 'entry_points:' with a task and its initial state"
            )
        ),
        tuple(states),
        tuple(transitions),
        tuple(_synchronisation(n, name, problems) for n in f.items("synchronisations")),
        _typed_list(f, "variables"),
        _condition(f, "pre", ConditionKind.PRE),
        _condition(f, "run", ConditionKind.RUN),
        _utility(f, problems),
        tuple(_constraint(n, name, problems) for n in f.items("constraints")),
        _signature(f, problems),
        f.number("frequency", 0.0, low=0.0),
        f.text("description"),
        span=node.span,
    )


def _entry_point(node: Node, plan: str, problems: Problems) -> EntryPoint:
    keys = ("name", "task", "state", "min", "max", "success_required")
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each entry point of plan '{plan}' must be a mapping with 'task' and 'state'",
            "write '- {task: T, state: S}'",
        )
        return EntryPoint("", "", None, span=node.span)
    f = Fields(node, f"an entry point of plan '{plan}'", problems, keys)
    task = f.text("task", required=True, hint="name the task agents take by entering here").strip()
    state = f.text("state").strip() or None
    return EntryPoint(
        f.text("name").strip() or task,
        task,
        state,
        f.integer("min", 0),
        f.cardinality("max", UNBOUNDED),
        f.flag("success_required", False),
        span=node.span,
    )


def _state(node: Node, plan: str, problems: Problems) -> tuple[State, list[Transition]]:
    keys = ("name", "kind", "children", "transitions", "post", "description")
    if not node.is_mapping:
        problems.add(node.span, f"each state of plan '{plan}' must be a mapping with a 'name'", "write '- name: S'")
        return State("", span=node.span), []
    label = node.value.get("name")  # type: ignore[union-attr]
    f = Fields(node, f"state '{label.value if label else '?'}' of plan '{plan}'", problems, keys)
    name = f.name()
    kind_text = f.text("kind", default="normal").strip().lower()
    try:
        kind = StateKind(kind_text)
    except ValueError:
        problems.add(f.span_of("kind"), f"unknown state kind '{kind_text}'", "use normal, success or failure")
        kind = StateKind.NORMAL
    children = tuple(_child(n, f, problems) for n in f.items("children"))
    transitions = [_transition(n, plan, name, problems) for n in f.items("transitions")]
    return (
        State(name, kind, children, _condition(f, "post", ConditionKind.POST), f.text("description"), span=node.span),
        transitions,
    )


def _child(node: Node, owner: Fields, problems: Problems) -> ChildRef:
    if isinstance(node.value, str):
        return ChildRef(node.value.strip(), span=node.span)
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each child of {owner.what} must be a name or a mapping with 'ref'",
            "write the name of a behaviour, plan, plan type or problem",
        )
        return ChildRef("", span=node.span)
    f = Fields(node, f"a child of {owner.what}", problems, ("ref", "bind"))
    bindings = []
    table = f.mapping("bind")
    if table is not None:
        for var, value in table.value.items():  # type: ignore[union-attr]
            if isinstance(value.value, (dict, list)) or value.value is None:
                problems.add(
                    value.span, f"binding of '{var}' must be a term written as text", "write e.g. 'goal: pos(a)'"
                )
                continue
            text = str(value.value).lower() if isinstance(value.value, bool) else str(value.value)
            bindings.append(Binding(var, text, span=value.text_span(1)))
    return ChildRef(
        f.text("ref", required=True, hint="name the behaviour, plan, plan type or problem").strip(),
        tuple(bindings),
        span=node.span,
    )


def _transition(node: Node, plan: str, source: str, problems: Problems) -> Transition:
    keys = ("name", "to", "condition", "sync")
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each transition of state '{source}' in plan '{plan}' must be a mapping with 'to'",
            "write '- {to: S, condition: ...}'",
        )
        return Transition("", source, "", span=node.span)
    f = Fields(node, f"a transition of state '{source}' in plan '{plan}'", problems, keys)
    target = f.text("to", required=True, hint="name the state the transition enters").strip()
    return Transition(
        f.text("name").strip() or f"{source}->{target}",
        source,
        target,
        _condition(f, "condition", ConditionKind.TRANSITION),
        f.text("sync").strip() or None,
        span=node.span,
    )


def _synchronisation(node: Node, plan: str, problems: Problems) -> Synchronisation:
    keys = ("name", "transitions", "talk_timeout", "sync_timeout", "fail_on_timeout")
    f = _element(node, "synchronisations", problems, keys)
    if f is None:
        return Synchronisation("", (), span=node.span)
    return Synchronisation(
        f.name(),
        tuple(
            n for n, _ in f.names("transitions", required=True, hint="list the names of the synchronised transitions")
        ),
        f.number("talk_timeout", 0.03, low=0.0),
        f.number("sync_timeout", 10.0, low=0.0),
        f.flag("fail_on_timeout", False),
        span=node.span,
    )


def _utility(plan: Fields, problems: Problems) -> UtilityFunction:
    node = plan.mapping("utility")
    if node is None:
        return UtilityFunction()
    f = Fields(
        node, f"the utility of {plan.what}", problems, ("priority_weight", "similarity_weight", "threshold", "summands")
    )
    summands = []
    for item in f.items("summands"):
        if not item.is_mapping:
            problems.add(
                item.span,
                f"each summand of {f.what} must be a mapping",
                "write '- {name: N, weight: W, expression: ...}'",
            )
            continue
        g = Fields(item, f"a summand of {f.what}", problems, ("name", "weight", "expression"))
        expr = g.get("expression")
        summands.append(
            Summand(
                g.name(),
                g.number("weight", 0.0, low=0.0, high=1.0),
                g.text("expression", required=True, hint="write a numeric formula with values in [0, 1]").strip(),
                span=expr.text_span(1) if expr is not None else item.span,
            )
        )
    return UtilityFunction(
        f.number("priority_weight", 1.0 if not summands else 0.0, low=0.0, high=1.0),
        tuple(summands),
        f.number("similarity_weight", 0.0, low=0.0, high=1.0),
        f.number("threshold", 0.1, low=0.0),
        span=node.span,
    )


def _constraint(node: Node, plan: str, problems: Problems) -> Constraint:
    f = _element(node, "constraints", problems, ("name", "formula", "utility", "variables"))
    if f is None:
        return Constraint("", "", span=node.span)
    formula = f.get("formula")
    utility = f.get("utility")
    if not f.has("formula") and not f.has("utility"):
        problems.add(
            f.span,
            f"{f.what} of plan '{plan}' has neither 'formula' nor 'utility'",
            "write the hard constraint as 'formula:' (a truth value), the value to maximise as 'utility:', or both",
        )
    return Constraint(
        f.name(),
        f.text("formula").strip(),
        tuple(n for n, _ in f.names("variables")),
        f.text("utility").strip(),
        span=_text_start(formula) if formula is not None else node.span,
        utility_span=_text_start(utility) if utility is not None else None,
    )


def _text_start(node: Node) -> SourceSpan:
    """Where the text of a formula starts once its leading blanks are stripped."""
    text = node.value if isinstance(node.value, str) else ""
    return node.text_span(1 + len(text) - len(text.lstrip()))


def _signature(plan: Fields, problems: Problems) -> PlanningSignature | None:
    node = plan.mapping("signature")
    if node is None:
        return None
    keys = ("parameters", "precondition", "effect", "cost", "duration")
    f = Fields(node, f"the signature of {plan.what}", problems, keys)
    duration = f.number("duration", -1.0, low=0.001) if "duration" in f.values else -1.0
    return PlanningSignature(
        _typed_list(f, "parameters"),
        _condition(f, "precondition", ConditionKind.PRE),
        _condition(f, "effect", ConditionKind.POST),
        f.number("cost", 1.0, low=0.0),
        duration if duration >= 0.0 else None,
        span=node.span,
    )


def _plantype(node: Node, problems: Problems) -> PlanType:
    f = _element(node, "plantypes", problems, ("name", "plans", "description"))
    if f is None:
        return PlanType("", (), span=node.span)
    return PlanType(
        f.name(),
        tuple(n for n, _ in f.names("plans", required=True, hint="list the alternative plans")),
        f.text("description"),
        span=node.span,
    )


def _problem(node: Node, problems: Problems) -> PlanningProblem:
    keys = (
        "name",
        "elements",
        "goal",
        "wait_plan",
        "alternative_plan",
        "update_time",
        "timeout",
        "world",
        "objects",
        "planner",
        "description",
    )
    f = _element(node, "problems", problems, keys)
    if f is None:
        return PlanningProblem("", (), Condition(ConditionKind.POST, "true"), span=node.span)
    goal = _condition(f, "goal", ConditionKind.POST)
    if goal is None:
        problems.add(f.span, f"{f.what} has no 'goal'", "write the goal as a formula, e.g. 'goal: On(a, g)'")
        goal = Condition(ConditionKind.POST, "true", span=f.span)
    update_time = f.number("update_time", 1.0)
    if not math.isfinite(update_time) or update_time <= 0:
        problems.add(
            f.span_of("update_time"), f"'update_time' of {f.what} must be a positive number of seconds", "use e.g. 1.0"
        )
    timeout = f.number("timeout", 60.0)
    if not math.isfinite(timeout) or timeout <= 0:
        problems.add(f.span_of("timeout"), f"'timeout' of {f.what} must be a positive number of seconds", "use e.g. 60")
    return PlanningProblem(
        f.name(),
        tuple(n for n, _ in f.names("elements", required=True, hint="list the skill plans the planner may use")),
        goal,
        f.text("wait_plan").strip() or None,
        f.text("alternative_plan").strip() or None,
        update_time,
        timeout,
        _condition(f, "world", ConditionKind.PRE),
        _typed_list(f, "objects"),
        f.text("planner", default="builtin").strip(),
        f.text("description"),
        span=node.span,
    )
