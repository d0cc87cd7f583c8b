"""Reading PDDL domains and problems (recursive descent over :mod:`alica.prophet.pddl.sexpr`).

Reading is linear in the text: duplicate checks go through sets, never list
scans. With :class:`~alica.prophet.planner.Limits`, the reader checks the
deadline every :data:`CHECK_EVERY` declarations, actions, objects or facts, and
refuses a text whose estimated parse size (:data:`BYTES_PER_CHAR`) passes the
memory bound. The garbage collector is paused while reading (many objects, no cycles).
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

from alica.prophet.pddl.errors import PddlError
from alica.prophet.pddl.formulas import FormulaReader, expect_list, expect_name, parse_number, parse_typed_list
from alica.prophet.pddl.model import (
    OBJECT,
    TOTAL_TIME,
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
    Metric,
    Not,
    Or,
    Predicate,
    Problem,
    TypedName,
    When,
)
from alica.prophet.pddl.sexpr import Node, SList, Source, Symbol, read_sexpr
from alica.prophet.planner import Feature, Limits, collector_paused
from alica.source import byte_place

CHECK_EVERY = 1024
"""Items read between two checks of the limits."""
BYTES_PER_CHAR = 48
"""The memory estimate of reading, per character of the text (tokens and nodes; measured about 35)."""

_FEATURES = {f"{f.value}": frozenset({f}) for f in Feature}
_EXTRA = {
    "disjunctive-preconditions": frozenset({"disjunctive-preconditions"}),
    "existential-preconditions": frozenset({"existential-preconditions"}),
    "universal-preconditions": frozenset({"universal-preconditions"}),
    "quantified-preconditions": frozenset({"existential-preconditions", "universal-preconditions"}),
}
_ADL = (
    frozenset(
        {Feature.STRIPS, Feature.TYPING, Feature.NEGATIVE_PRECONDITIONS, Feature.EQUALITY, Feature.CONDITIONAL_EFFECTS}
    ),
    frozenset({"disjunctive-preconditions", "existential-preconditions", "universal-preconditions"}),
)
_UNSUPPORTED = frozenset(
    {
        "numeric-fluents",
        "fluents",
        "object-fluents",
        "duration-inequalities",
        "continuous-effects",
        "timed-initial-literals",
        "preferences",
        "constraints",
    }
)
SUPPORTED_REQUIREMENTS = tuple(sorted([*_FEATURES, *_EXTRA, "adl"]))
"""The requirement names the reader accepts."""


def _requirements(source: Source, section: SList) -> tuple[set[Feature], set[str]]:
    features: set[Feature] = set()
    extra: set[str] = set()
    for item in section.items[1:]:
        if not isinstance(item, Symbol) or not item.text.startswith(":"):
            shown = item.text if isinstance(item, Symbol) else item.describe()
            raise source.error(item.offset, f"expected a requirement ':name', found '{shown}'")
        name = item.text[1:]
        if name in _FEATURES:
            features |= _FEATURES[name]
        elif name in _EXTRA:
            extra |= _EXTRA[name]
        elif name == "adl":
            features |= _ADL[0]
            extra |= _ADL[1]
        elif name in _UNSUPPORTED:
            raise source.error(
                item.offset,
                f"unsupported requirement ':{name}'",
                "supported: " + " ".join(f":{n}" for n in SUPPORTED_REQUIREMENTS),
            )
        else:
            raise source.error(
                item.offset,
                f"unknown requirement ':{name}'",
                "supported: " + " ".join(f":{n}" for n in SUPPORTED_REQUIREMENTS),
            )
    return features, extra


def formula_features(formula: Formula | Effect, *, in_effect: bool = False) -> tuple[set[Feature], set[str]]:
    """The features and extra requirement names a formula or effect uses.

    Args:
        formula: the formula or effect tree.
        in_effect: whether ``formula`` is an effect (a ``not`` there is a delete).

    Returns:
        The features and the names such as ``disjunctive-preconditions``.
    """
    features: set[Feature] = set()
    extra: set[str] = set()
    stack: list[tuple[object, bool]] = [(formula, in_effect)]
    while stack:
        node, effect = stack.pop()
        if isinstance(node, And):
            stack.extend((p, effect) for p in node.parts)
        elif isinstance(node, Not):
            if not effect:
                features.add(Feature.NEGATIVE_PRECONDITIONS)
                stack.append((node.formula, False))
        elif isinstance(node, Or | Imply):
            extra.add("disjunctive-preconditions")
            parts = node.parts if isinstance(node, Or) else (node.condition, node.consequence)
            stack.extend((p, False) for p in parts)
        elif isinstance(node, Exists):
            extra.add("existential-preconditions")
            stack.append((node.body, False))
        elif isinstance(node, Forall):
            if not effect:
                extra.add("universal-preconditions")
            stack.append((node.body, effect))
        elif isinstance(node, When):
            features.add(Feature.CONDITIONAL_EFFECTS)
            stack.append((node.condition, False))
            stack.append((node.effect, True))
        elif isinstance(node, Equals):
            features.add(Feature.EQUALITY)
        elif isinstance(node, Increase):
            features.add(Feature.ACTION_COSTS)
    return features, extra


def _check_header(source: Source, top: SList, kind: str) -> str:
    if top.head() != "define":
        raise source.error(top.offset, f"expected '(define ({kind} NAME) ...)', found '{top.describe()}'")
    if len(top.items) < 2 or not isinstance(top.items[1], SList) or top.items[1].head() != kind:
        place = top.items[1].offset if len(top.items) > 1 else top.offset
        raise source.error(place, f"expected '({kind} NAME)' after 'define'")
    header = top.items[1]
    if len(header.items) != 2:
        raise source.error(header.offset, f"expected '({kind} NAME)' with one name")
    return expect_name(source, header.items[1], f"a {kind} name")


def _sections(source: Source, top: SList, allowed: tuple[str, ...]) -> list[SList]:
    sections = []
    for item in top.items[2:]:
        section = expect_list(source, item, "a section '(:keyword ...)'")
        head = section.head()
        if head == ":constraints":
            raise source.error(section.offset, f"unsupported construct '({head} ...)'")
        if head not in allowed:
            raise source.error(section.offset, f"expected one of {', '.join(allowed)}, found '{section.describe()}'")
        sections.append(section)
    return sections


def _typed(
    source: Source, section: SList, variables: bool, types: dict[str, tuple[str, ...]] | None, what: str
) -> list[tuple[TypedName, int]]:
    return parse_typed_list(source, section.items[1:], variables=variables, types=types, what=what)


def _check_type_cycles(
    source: Source, types: dict[str, tuple[str, ...]], declared: list[tuple[TypedName, int]]
) -> None:
    """Refuse a type that is its own ancestor (``a - b``, ``b - a``), at the first declaration on the cycle."""
    for (child, parent), offset in declared:
        seen: set[str] = set()
        stack = [parent]
        while stack:
            kind = stack.pop()
            if kind == child:
                raise source.error(offset, f"type '{child}' is its own ancestor (through '{parent}')")
            if kind not in seen:
                seen.add(kind)
                stack.extend(types.get(kind, ()))


def _declarations(
    source: Source,
    section: SList,
    types: dict[str, tuple[str, ...]],
    what: str,
    functions: bool,
    limits: Limits | None = None,
) -> list[Predicate]:
    out: list[Predicate] = []
    names: set[str] = set()
    items = section.items[1:]
    index = 0
    while index < len(items):
        decl = expect_list(source, items[index], f"a {what} declaration '(name ?x ...)'")
        name = expect_name(source, decl.items[0], f"a {what} name") if decl.items else ""
        if not name:
            raise source.error(decl.offset, f"expected a {what} name, found '()'")
        params = parse_typed_list(source, decl.items[1:], variables=True, types=types, what=f"parameters of '{name}'")
        if name in names:
            raise source.error(decl.offset, f"duplicate {what} '{name}'")
        names.add(name)
        out.append(Predicate(name, tuple(p for p, _ in params)))
        if limits is not None and len(out) % CHECK_EVERY == 0:
            limits.check("reading the domain", done=f"{len(out)} {what}s")
        index += 1
        dash = items[index] if index < len(items) else None
        if functions and isinstance(dash, Symbol) and dash.text == "-":
            kind = items[index + 1] if index + 1 < len(items) else items[index]
            if not isinstance(kind, Symbol) or kind.text != "number":
                raise source.error(kind.offset, f"unsupported construct: function '{name}' must be '- number'")
            index += 2
    return out


def _keyed(source: Source, section: SList, kind: str, keys: tuple[str, ...]) -> tuple[str, list[tuple[Symbol, Node]]]:
    """The name of ``(kind NAME :key value ...)`` and its ``(key, value)`` pairs, each key once, from ``keys``."""
    if len(section.items) < 2:
        raise source.error(section.offset, f"expected an action name after '{kind}'")
    name = expect_name(source, section.items[1], "an action name")
    items = section.items[2:]
    pairs: list[tuple[Symbol, Node]] = []
    seen: set[str] = set()
    for index in range(0, len(items), 2):
        key = items[index]
        if not isinstance(key, Symbol) or key.text not in keys:
            shown = key.text if isinstance(key, Symbol) else key.describe() + " ...)"
            expected = ", ".join(keys[:-1]) + f" or {keys[-1]}"
            raise source.error(key.offset, f"expected {expected} in '({kind} {name}', found '{shown}'")
        if key.text in seen:
            raise source.error(key.offset, f"duplicate {key.text} in '({kind} {name}'")
        seen.add(key.text)
        if index + 1 >= len(items):
            raise source.error(key.offset, f"expected a value after {key.text} in '({kind} {name}'")
        if key.text == ":parameters" and index != 0:
            raise source.error(key.offset, f"expected :parameters first in '({kind} {name}'")
        pairs.append((key, items[index + 1]))
    return name, pairs


def _parameters(source: Source, value: Node, reader: FormulaReader, kind: str, name: str) -> tuple[TypedName, ...]:
    plist = expect_list(source, value, "a parameter list '(?x - type ...)'")
    typed = parse_typed_list(source, plist.items, variables=True, types=reader.types, what=f"parameters of '{name}'")
    counts = Counter(n for (n, _), _ in typed)
    if len(counts) < len(typed):  # the first parameter written twice, at its first place
        pname, offset = next((n, o) for (n, _), o in typed if counts[n] > 1)
        raise source.error(offset, f"duplicate parameter '{pname}' in '({kind} {name}'")
    return tuple(p for p, _ in typed)


def _action(source: Source, section: SList, reader: FormulaReader) -> Action:
    name, pairs = _keyed(source, section, ":action", (":parameters", ":precondition", ":effect"))
    parameters: tuple[TypedName, ...] = ()
    precondition: Formula = And(())
    effect: Effect = And(())
    for key, value in pairs:
        if key.text == ":parameters":
            parameters = _parameters(source, value, reader, ":action", name)
        elif key.text == ":precondition":
            precondition = _empty_or(value, lambda v, scope=dict(parameters): reader.formula(v, scope))
        else:
            effect = _empty_or(value, lambda v, scope=dict(parameters): reader.effect(v, scope))
    return Action(name, parameters, precondition, effect, span=source.span(section.offset))


_TIMES = {"at start": 0, "over all": 1, "at end": 2}
"""The time specifiers of a durative action's conditions, and where each goes."""


def _durative_action(source: Source, section: SList, reader: FormulaReader) -> DurativeAction:
    """``(:durative-action NAME :parameters (...) :duration (= ?duration d) :condition C :effect E)``."""
    kind = ":durative-action"
    name, pairs = _keyed(source, section, kind, (":parameters", ":duration", ":condition", ":effect"))
    parameters: tuple[TypedName, ...] = ()
    duration: int | float | FluentTerm | None = None
    conditions: list[list[Formula]] = [[], [], []]
    effects: list[list[Effect]] = [[], []]
    for key, value in pairs:
        scope = dict(parameters)
        if key.text == ":parameters":
            parameters = _parameters(source, value, reader, kind, name)
        elif key.text == ":duration":
            duration = _duration(source, value, reader, scope, name)
        elif key.text == ":condition":
            for when, body in _timed_parts(source, value, name, "condition"):
                if when not in _TIMES:
                    raise source.error(
                        body.offset,
                        f"expected (at start ...), (over all ...) or (at end ...) in the condition of '{name}'",
                    )
                conditions[_TIMES[when]].append(reader.formula(body, scope))
        else:
            for when, body in _timed_parts(source, value, name, "effect"):
                if when not in ("at start", "at end"):
                    raise source.error(
                        body.offset,
                        f"expected (at start ...) or (at end ...) in the effect of '{name}'",
                        "continuous effects ((over all ...) in an effect) are not supported",
                    )
                effects[0 if when == "at start" else 1].append(reader.effect(body, scope))
    if duration is None:
        raise source.error(section.offset, f"expected ':duration (= ?duration d)' in '({kind} {name}'")

    def joined(parts: list[Any]) -> Any:
        return parts[0] if len(parts) == 1 else And(tuple(parts))

    at_start, over_all, at_end = (joined(c) for c in conditions)
    start_effect, end_effect = (joined(e) for e in effects)
    return DurativeAction(
        name,
        parameters,
        duration,
        at_start,
        over_all,
        at_end,
        start_effect,
        end_effect,
        span=source.span(section.offset),
    )


def _duration(
    source: Source, value: Node, reader: FormulaReader, scope: dict[str, str], name: str
) -> int | float | FluentTerm:
    """``(= ?duration d)``: d a non-negative number or a function of the parameters."""
    node = expect_list(source, value, "'(= ?duration d)'")
    head = node.head()
    if head in ("<=", ">=", "<", ">", "and"):
        raise source.error(
            node.offset, f"unsupported duration constraint '({head} ...)' in '{name}'", "write (= ?duration d)"
        )
    if (
        head != "="
        or len(node.items) != 3
        or not isinstance(node.items[1], Symbol)
        or node.items[1].text != "?duration"
    ):
        raise source.error(node.offset, f"expected '(= ?duration d)' in '{name}'")
    amount = node.items[2]
    if isinstance(amount, SList):
        if amount.head() in ("+", "-", "*", "/"):
            raise source.error(
                amount.offset,
                f"unsupported duration expression '({amount.head()} ...)' in '{name}'",
                "write a number or one function, e.g. (travel-time ?from ?to)",
            )
        return reader.fluent(amount, scope)
    number = parse_number(source, amount, f"the duration of '{name}'")
    if number < 0:
        raise source.error(amount.offset, f"negative duration {number:g} in '{name}'")
    return number


def _timed_parts(source: Source, value: Node, name: str, what: str) -> list[tuple[str, Node]]:
    """The ``(at start X)``/``(over all X)``/``(at end X)`` parts of a durative action's condition or effect."""
    if isinstance(value, SList) and not value.items:
        return []
    node = expect_list(source, value, f"a timed {what} '(and (at start ...) (at end ...))'")
    parts = node.items[1:] if node.head() == "and" else [node]
    out: list[tuple[str, Node]] = []
    for part in parts:
        item = expect_list(source, part, f"a timed {what} '(at start ...)'")
        words = [i.text if isinstance(i, Symbol) else "" for i in item.items[:2]]
        if len(item.items) != 3 or " ".join(words) not in ("at start", "over all", "at end"):
            raise source.error(
                item.offset,
                f"expected (at start ...), (over all ...) or (at end ...) in the {what} of '{name}', "
                f"found '{item.describe()}'",
            )
        out.append((" ".join(words), item.items[2]))
    return out


def _derived(source: Source, section: SList, reader: FormulaReader) -> Axiom:
    """``(:derived (predicate ?x - t ...) body)``, the predicate declared in ``:predicates``."""
    if len(section.items) != 3:
        raise source.error(section.offset, "expected '(:derived (predicate ?x ...) formula)'")
    head = expect_list(source, section.items[1], "a derived predicate '(predicate ?x ...)'")
    name = expect_name(source, head.items[0], "a predicate name") if head.items else ""
    if not name:
        raise source.error(head.offset, "expected a predicate name, found '()'")
    declared = reader.predicates.get(name)
    if declared is None:
        raise source.error(
            head.items[0].offset,
            f"undefined derived predicate '{name}'",
            "declare it in (:predicates ...) before the (:derived ...) rule",
        )
    typed = parse_typed_list(
        source, head.items[1:], variables=True, types=reader.types, what=f"parameters of derived '{name}'"
    )
    counts = Counter(n for (n, _), _ in typed)
    if len(counts) < len(typed):
        pname, offset = next((n, o) for (n, _), o in typed if counts[n] > 1)
        raise source.error(offset, f"duplicate parameter '{pname}' in '(:derived ({name}'")
    if len(typed) != declared.arity:
        raise source.error(
            head.offset, f"wrong number of arguments for '{name}': expected {declared.arity}, found {len(typed)}"
        )
    parameters = tuple(p for p, _ in typed)
    body = _empty_or(section.items[2], lambda v: reader.formula(v, dict(parameters)))
    return Axiom(name, parameters, body, span=source.span(section.offset))


def _derived_names(top: SList) -> set[str]:
    """The predicate names that ``(:derived (name ...) ...)`` sections define (read before the sections)."""
    names = set()
    for item in top.items[2:]:
        if isinstance(item, SList) and item.head() == ":derived" and len(item.items) > 1:
            head = item.items[1]
            if isinstance(head, SList) and head.items and isinstance(head.items[0], Symbol):
                names.add(head.items[0].text)
    return names


def _empty_or(node: Node, read):  # type: ignore[no-untyped-def]
    """``()`` is the empty conjunction, anything else is read by ``read``."""
    if isinstance(node, SList) and not node.items:
        return And(())
    return read(node)


def parse_domain(text: str, file: str = "<string>", limits: Limits | None = None) -> Domain:
    """Read a PDDL domain.

    Args:
        text: the domain text.
        file: the file name for error messages.
        limits: a deadline and memory bound to check while reading.

    Returns:
        The domain.

    Raises:
        PddlError: the text is no valid domain (the message has ``FILE:LINE:COL``).
        LimitReached: a limit was reached while reading.
    """
    with collector_paused():
        return _parse_domain(text, file, limits)


def _parse_domain(text: str, file: str, limits: Limits | None) -> Domain:
    stage = "reading the domain"
    source = Source(text, file)
    if limits is not None:
        limits.check(stage, len(text) * BYTES_PER_CHAR, f"{len(text)} characters")
    top = read_sexpr(source)
    if limits is not None:
        limits.check(stage)
    name = _check_header(source, top, "domain")
    allowed = (
        ":requirements",
        ":types",
        ":constants",
        ":predicates",
        ":functions",
        ":action",
        ":durative-action",
        ":derived",
    )
    features: set[Feature] = {Feature.STRIPS}
    extra: set[str] = set()
    types: dict[str, tuple[str, ...]] = {}
    constants: list[TypedName] = []
    predicates: list[Predicate] = []
    functions: list[Predicate] = []
    reader = FormulaReader(source, {}, {}, {}, types, derived=_derived_names(top))
    actions: list[Action] = []
    axioms: list[Axiom] = []
    durative_actions: list[DurativeAction] = []
    action_names: set[str] = set()
    for section in _sections(source, top, allowed):
        head = section.head()
        if head == ":requirements":
            more, more_extra = _requirements(source, section)
            features |= more
            extra |= more_extra
        elif head == ":types":
            declared = _typed(source, section, False, None, "type list")
            for (child, parent), offset in declared:
                if child == OBJECT:
                    continue
                parents = types.get(child, ())
                if parent in parents:
                    raise source.error(offset, f"duplicate type '{child}'")
                # a type declared under several parents (area - object, area - surface) has them all;
                # object is implicit beside another parent
                if parent == OBJECT:
                    types[child] = parents or (OBJECT,)
                else:
                    types[child] = tuple(sorted({*(p for p in parents if p != OBJECT), parent}))
            for (child, parent), offset in declared:
                if parent != OBJECT and parent not in types:
                    raise source.error(
                        offset, f"unknown type '{parent}' (parent of '{child}')", "declare it in (:types ...)"
                    )
            _check_type_cycles(source, types, declared)
            features.add(Feature.TYPING)
        elif head == ":constants":
            for (const, kind), offset in _typed(source, section, False, types, "constant list"):
                if const in reader.objects:
                    raise source.error(offset, f"duplicate constant '{const}'")
                reader.objects[const] = kind
                constants.append((const, kind))
        elif head == ":predicates":
            predicates.extend(_declarations(source, section, types, "predicate", False, limits))
            reader.predicates.update((p.name, p) for p in predicates)
        elif head == ":functions":
            functions.extend(_declarations(source, section, types, "function", True, limits))
            reader.functions.update((f.name, f) for f in functions)
        elif head == ":derived":
            axioms.append(_derived(source, section, reader))
        elif head == ":durative-action":
            durative = _durative_action(source, section, reader)
            if durative.name in action_names:
                raise source.error(section.offset, f"duplicate action '{durative.name}'")
            action_names.add(durative.name)
            durative_actions.append(durative)
        else:
            action = _action(source, section, reader)
            if action.name in action_names:
                raise source.error(section.offset, f"duplicate action '{action.name}'")
            action_names.add(action.name)
            actions.append(action)
            if limits is not None and len(actions) % CHECK_EVERY == 0:
                limits.check(stage, done=f"{len(actions)} actions")
    for action in actions:
        for part, in_effect in ((action.precondition, False), (action.effect, True)):
            more, more_extra = formula_features(part, in_effect=in_effect)
            features |= more
            extra |= more_extra
        if any(t != OBJECT for _, t in action.parameters):
            features.add(Feature.TYPING)
    for durative in durative_actions:
        features.add(Feature.DURATIVE_ACTIONS)
        for part in (durative.at_start, durative.over_all, durative.at_end):
            more, more_extra = formula_features(part)
            features |= more
            extra |= more_extra
        for part in (durative.start_effect, durative.end_effect):
            more, more_extra = formula_features(part, in_effect=True)
            features |= more
            extra |= more_extra
        if any(t != OBJECT for _, t in durative.parameters):
            features.add(Feature.TYPING)
    for axiom in axioms:
        more, more_extra = formula_features(axiom.body)
        features |= more
        extra |= more_extra
        features.add(Feature.DERIVED_PREDICATES)
        if any(t != OBJECT for _, t in axiom.parameters):
            features.add(Feature.TYPING)
    if any(t != OBJECT for p in (*predicates, *functions) for _, t in p.parameters):
        features.add(Feature.TYPING)
    return Domain(
        name,
        frozenset(features),
        types,
        tuple(constants),
        tuple(predicates),
        tuple(functions),
        tuple(actions),
        frozenset(extra),
        tuple(axioms),
        tuple(durative_actions),
    )


def parse_problem(
    text: str, file: str = "<string>", domain: Domain | None = None, limits: Limits | None = None
) -> Problem:
    """Read a PDDL problem, checked against ``domain`` when given.

    Args:
        text: the problem text.
        file: the file name for error messages.
        domain: the domain; with it, predicates, arities, objects, types and the domain name are checked.
        limits: a deadline and memory bound to check while reading.

    Returns:
        The problem.

    Raises:
        PddlError: the text is no valid problem (the message has ``FILE:LINE:COL``).
        LimitReached: a limit was reached while reading.
    """
    with collector_paused():
        return _parse_problem(text, file, domain, limits)


def _parse_problem(text: str, file: str, domain: Domain | None, limits: Limits | None) -> Problem:
    stage = "reading the problem"
    source = Source(text, file)
    if limits is not None:
        limits.check(stage, len(text) * BYTES_PER_CHAR, f"{len(text)} characters")
    top = read_sexpr(source)
    if limits is not None:
        limits.check(stage)
    name = _check_header(source, top, "problem")
    sections = _sections(source, top, (":domain", ":requirements", ":objects", ":init", ":goal", ":metric"))
    if not sections or sections[0].head() != ":domain":
        raise source.error(
            sections[0].offset if sections else top.offset, "expected '(:domain NAME)' first in the problem"
        )
    dom = sections[0]
    if len(dom.items) != 2:
        raise source.error(dom.offset, "expected '(:domain NAME)' with one name")
    domain_name = expect_name(source, dom.items[1], "a domain name")
    if domain is not None and domain_name != domain.name:
        raise source.error(dom.items[1].offset, f"problem is for domain '{domain_name}', not '{domain.name}'")
    strict = domain is not None
    types = domain.types if domain is not None else None
    reader = FormulaReader(
        source,
        {p.name: p for p in domain.predicates} if domain else {},
        {f.name: f for f in domain.functions} if domain else {},
        dict(domain.constants) if domain else {},
        types,
        strict,
        derived=set(domain.derived) if domain else set(),
    )
    features: set[Feature] = set()
    extra: set[str] = set()
    objects: list[TypedName] = []
    init: list[Atom | FluentValue] = []
    goal: Formula | None = None
    metric: Metric | None = None
    seen: set[str] = set()
    for section in sections[1:]:
        head = section.head()
        if head in seen:
            raise source.error(section.offset, f"duplicate section '({head}'")
        seen.add(head)
        if head == ":requirements":
            features, extra = _requirements(source, section)
        elif head == ":objects":
            for (obj, kind), offset in _typed(source, section, False, types, "object list"):
                if obj in reader.objects:
                    raise source.error(offset, f"duplicate object '{obj}'")
                objects.append((obj, kind))
                reader.objects[obj] = kind
                if limits is not None and len(objects) % CHECK_EVERY == 0:
                    limits.check(stage, done=f"{len(objects)} objects")
        elif head == ":init":
            for item in section.items[1:]:
                init.append(_init_item(source, item, reader))
                if limits is not None and len(init) % CHECK_EVERY == 0:
                    limits.check(stage, done=f"{len(init)} initial facts")
        elif head == ":goal":
            if len(section.items) != 2:
                raise source.error(section.offset, "expected '(:goal formula)' with one formula")
            goal = _empty_or(section.items[1], lambda v: reader.formula(v, {}))
        else:
            metric = _metric(source, section, reader)
    if goal is None:
        raise source.error(top.offset, "expected a '(:goal ...)' section in the problem")
    more, more_extra = formula_features(goal)
    return Problem(
        name,
        domain_name,
        tuple(objects),
        tuple(init),
        goal,
        metric,
        frozenset(features | more),
        frozenset(extra | more_extra),
    )


def _init_item(source: Source, node: Node, reader: FormulaReader) -> Atom | FluentValue:
    item = expect_list(source, node, "an initial fact '(predicate ...)'")
    head = item.head()
    if head == "=":
        if len(item.items) != 3:
            raise source.error(item.offset, "expected '(= (fluent ...) number)'")
        target = expect_list(source, item.items[1], "a fluent '(function ...)' after '='")
        fluent = reader.fluent(target, {})
        return FluentValue(fluent, parse_number(source, item.items[2], f"the value of {fluent}"))
    if head in ("not", "and", "or", "forall", "exists", "when"):
        raise source.error(item.offset, f"unsupported construct '({head} ...)' in :init", "list the true facts only")
    return reader.changed_atom(item, {}, ":init")


def _metric(source: Source, section: SList, reader: FormulaReader) -> Metric:
    if (
        len(section.items) != 3
        or not isinstance(section.items[1], Symbol)
        or section.items[1].text not in ("minimize", "maximize")
    ):
        raise source.error(section.offset, "expected '(:metric minimize (total-cost))'")
    expression = expect_list(source, section.items[2], "a fluent '(total-cost)' in the metric")
    if expression.head() in ("+", "-", "*", "/"):
        raise source.error(expression.offset, "unsupported construct: metric expressions other than one fluent")
    if expression.head() == TOTAL_TIME and len(expression.items) == 1:  # the makespan: no declaration
        return Metric(section.items[1].text, FluentTerm(TOTAL_TIME))
    return Metric(section.items[1].text, reader.fluent(expression, {}))


def read_domain(path: str | Path, limits: Limits | None = None) -> Domain:
    """Read a domain file (see :func:`parse_domain`).

    Raises:
        PddlError: the file cannot be read or is no valid domain.
        LimitReached: a limit was reached while reading.
    """
    return parse_domain(_read(path), str(path), limits)


def read_problem(path: str | Path, domain: Domain | None = None, limits: Limits | None = None) -> Problem:
    """Read a problem file (see :func:`parse_problem`).

    Raises:
        PddlError: the file cannot be read or is no valid problem.
        LimitReached: a limit was reached while reading.
    """
    return parse_problem(_read(path), str(path), domain, limits)


def _read(path: str | Path) -> str:
    try:
        data = Path(path).read_bytes()
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        raise PddlError(f"cannot read {path}: {error}") from error
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        place = byte_place(data, error.start, str(path))
        raise PddlError(
            f"the file is not UTF-8 text (byte 0x{data[error.start]:02x})", place, "save it as UTF-8"
        ) from error
