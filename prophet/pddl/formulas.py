"""Reading formulas, effects and typed lists from S-expressions, with checks against declarations."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from alica.prophet.pddl.model import (
    OBJECT,
    And,
    Atom,
    Effect,
    Equals,
    Exists,
    FluentTerm,
    Forall,
    Formula,
    Imply,
    Increase,
    Not,
    Or,
    Predicate,
    TypedName,
    When,
    either,
)
from alica.prophet.pddl.sexpr import Node, SList, Source, Symbol
from alica.prophet.planner import Feature

#: Largest magnitude of a number in PDDL text: sums of such costs stay exact as floats.
MAX_NUMBER = 1e15

_NUMBER = re.compile(r"-?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?")
_NAME = re.compile(r"[a-z][a-z0-9_\-]*", re.IGNORECASE)
_NUMERIC_COMPARISONS = frozenset({"<", ">", "<=", ">="})
_NUMERIC_EFFECTS = frozenset({"assign", "decrease", "scale-up", "scale-down"})


def parse_number(source: Source, node: Node, what: str) -> int | float:
    """A number literal (an int when it has no fraction or exponent).

    Raises:
        PddlError: the node is no number, or its magnitude exceeds :data:`MAX_NUMBER`.
    """
    if not isinstance(node, Symbol) or not _NUMBER.fullmatch(node.text):
        shown = node.text if isinstance(node, Symbol) else node.describe() + " ...)"
        raise source.error(node.offset, f"bad number '{shown}' for {what}")
    text = node.text
    if re.fullmatch(r"-?\d+", text) and len(text.lstrip("-").lstrip("0")) <= 16:
        value: int | float = int(text)
    else:
        value = float(text)  # the pattern admits only what float() reads; huge values give inf
    if not abs(value) <= MAX_NUMBER:
        shown = text if len(text) <= 30 else text[:27] + "..."
        raise source.error(
            node.offset, f"number '{shown}' for {what} is too large", f"use a number of at most {MAX_NUMBER:.0e}"
        )
    return value


def expect_name(source: Source, node: Node, what: str) -> str:
    """A plain name (no variable, keyword or list).

    Raises:
        PddlError: the node is no name.
    """
    if not isinstance(node, Symbol) or not _NAME.fullmatch(node.text):
        shown = node.text if isinstance(node, Symbol) else node.describe() + " ...)"
        raise source.error(node.offset, f"expected {what}, found '{shown}'")
    return node.text


def expect_list(source: Source, node: Node, what: str) -> SList:
    """``node`` as a list.

    Raises:
        PddlError: the node is a symbol.
    """
    if not isinstance(node, SList):
        raise source.error(node.offset, f"expected {what}, found '{node.text}'")
    return node


def parse_typed_list(
    source: Source, items: tuple[Node, ...], *, variables: bool, types: dict[str, tuple[str, ...]] | None, what: str
) -> list[tuple[TypedName, int]]:
    """``a b - t c`` as ``[((a, t), offset), ((b, t), ...), ((c, object), ...)]``.

    Args:
        source: the text, for error places.
        items: the list's items.
        variables: whether the names are variables (``?x``).
        types: known types (child -> parents), or None to accept any type (the ``:types`` list itself).
        what: what the names are, for messages.

    Raises:
        PddlError: a bad name, a missing or unknown type, or ``(either ...)`` where it has no meaning
            (the type list itself, objects and constants).
    """
    out: list[tuple[TypedName, int]] = []
    pending: list[tuple[str, int]] = []
    index = 0
    while index < len(items):
        item = items[index]
        if isinstance(item, Symbol) and item.text == "-":
            if index + 1 >= len(items):
                raise source.error(item.offset, f"expected a type after '-' in the {what}")
            type_node = items[index + 1]
            if isinstance(type_node, SList):
                type_name = _either(source, type_node, variables=variables, types=types, what=what)
            else:
                type_name = _known_type(source, type_node, types)
            if not pending:
                raise source.error(item.offset, f"expected names before '- {type_name}' in the {what}")
            out.extend(((name, type_name), offset) for name, offset in pending)
            pending = []
            index += 2
            continue
        if variables:
            if not isinstance(item, Symbol) or not item.text.startswith("?") or not _NAME.fullmatch(item.text[1:]):
                shown = item.text if isinstance(item, Symbol) else item.describe() + " ...)"
                raise source.error(item.offset, f"expected a variable '?name' in the {what}, found '{shown}'")
            pending.append((item.text, item.offset))
        else:
            pending.append((expect_name(source, item, f"a name in the {what}"), item.offset))
        index += 1
    out.extend(((name, OBJECT), offset) for name, offset in pending)
    return out


def _known_type(source: Source, node: Node, types: dict[str, tuple[str, ...]] | None) -> str:
    """A type name, checked against the declared ``types`` (unless None)."""
    name = expect_name(source, node, "a type name")
    if types is not None and name != OBJECT and name not in types:
        raise source.error(node.offset, f"unknown type '{name}'", "declare it in (:types ...)")
    return name


def _either(
    source: Source, node: SList, *, variables: bool, types: dict[str, tuple[str, ...]] | None, what: str
) -> str:
    """``(either t1 t2 ...)`` after ``-``: the :func:`~alica.prophet.pddl.model.either` type name."""
    if not node.items or not isinstance(node.items[0], Symbol) or node.items[0].text.lower() != "either":
        raise source.error(node.offset, f"expected a type name or '(either type ...)' in the {what}")
    if types is None:
        raise source.error(
            node.offset,
            "'(either ...)' in the type list",
            "declare the type once under each parent instead, as 'area - object' and 'area - surface'",
        )
    if not variables:
        raise source.error(
            node.offset,
            f"'(either ...)' in the {what}: an object or constant has one type",
            "give it one type, or declare a type below each of the types and use that",
        )
    if len(node.items) < 2:
        raise source.error(node.offset, "expected at least one type in '(either ...)'")
    members = []
    for item in node.items[1:]:
        if isinstance(item, SList):
            raise source.error(item.offset, "expected a type name in '(either ...)', found a list")
        members.append(_known_type(source, item, types))
    return either(members)


@dataclass(slots=True)
class FormulaReader:
    """Reads formulas and effects, checking names, arities and variables.

    Attributes:
        source: the text.
        predicates: known predicates by name.
        functions: known functions by name.
        objects: known constants and objects (name -> type).
        types: known types (None: any).
        strict: whether unknown predicates, functions and objects are errors (False without a domain).
        used: features found while reading.
        derived: the derived predicates (an effect or ``:init`` naming one is an error).
    """

    source: Source
    predicates: dict[str, Predicate]
    functions: dict[str, Predicate]
    objects: dict[str, str]
    types: dict[str, tuple[str, ...]] | None
    strict: bool = True
    used: set[Feature] = field(default_factory=set)
    derived: set[str] = field(default_factory=set)

    def term(self, node: Node, scope: dict[str, str]) -> str:
        """A variable in scope or a known object."""
        if isinstance(node, SList):
            raise self.source.error(node.offset, f"expected a variable or object, found '{node.describe()} ...)'")
        text = node.text
        if text.startswith("?"):
            if text not in scope:
                raise self.source.error(
                    node.offset, f"undefined variable '{text}'", "declare it in :parameters or a quantifier"
                )
            return text
        if self.strict and text not in self.objects:
            raise self.source.error(node.offset, f"undefined object or constant '{text}'")
        return text

    def atom(self, node: SList, scope: dict[str, str]) -> Atom:
        """``(pred term ...)``, checked against the predicate's declaration."""
        name = expect_name(self.source, node.items[0], "a predicate name") if node.items else ""
        if not node.items:
            raise self.source.error(node.offset, "expected a predicate name, found '()'")
        declared = self.predicates.get(name)
        args = tuple(self.term(item, scope) for item in node.items[1:])
        if declared is None:
            if not self.strict:
                return Atom(name, args)
            raise self.source.error(
                node.items[0].offset, f"undefined predicate '{name}'", "declare it in (:predicates ...)"
            )
        if len(args) != declared.arity:
            raise self.source.error(
                node.offset, f"wrong number of arguments for '{name}': expected {declared.arity}, found {len(args)}"
            )
        return Atom(name, args)

    def fluent(self, node: SList, scope: dict[str, str]) -> FluentTerm:
        """``(function term ...)``, checked against the function's declaration."""
        if not node.items:
            raise self.source.error(node.offset, "expected a function name, found '()'")
        name = expect_name(self.source, node.items[0], "a function name")
        declared = self.functions.get(name)
        args = tuple(self.term(item, scope) for item in node.items[1:])
        if declared is None:
            if not self.strict:
                return FluentTerm(name, args)
            raise self.source.error(
                node.items[0].offset, f"undefined function '{name}'", "declare it in (:functions ...)"
            )
        if len(args) != declared.arity:
            raise self.source.error(
                node.offset, f"wrong number of arguments for '{name}': expected {declared.arity}, found {len(args)}"
            )
        return FluentTerm(name, args)

    def _scoped(self, node: SList, scope: dict[str, str]) -> tuple[tuple[TypedName, ...], dict[str, str]]:
        if len(node.items) != 3:
            raise self.source.error(node.offset, f"expected '({node.head()} (?v - type ...) body)'")
        variables = expect_list(self.source, node.items[1], f"a variable list after '{node.head()}'")
        typed = parse_typed_list(self.source, variables.items, variables=True, types=self.types, what="variable list")
        if any(t != OBJECT for (_, t), _ in typed):
            self.used.add(Feature.TYPING)
        names = tuple(name for name, _ in typed)
        return names, {**scope, **dict(names)}

    def formula(self, node: Node, scope: dict[str, str]) -> Formula:
        """A precondition or goal formula.

        Raises:
            PddlError: unknown names, wrong arities, numeric comparisons or bad structure.
        """
        if not isinstance(node, SList):
            raise self.source.error(node.offset, f"expected a formula '(...)', found '{node.text}'")
        head = node.head()
        if head == "and":
            return And(tuple(self.formula(item, scope) for item in node.items[1:]))
        if head == "or":
            return Or(tuple(self.formula(item, scope) for item in node.items[1:]))
        if head == "not":
            if len(node.items) != 2:
                raise self.source.error(node.offset, "expected '(not formula)' with one formula")
            return Not(self.formula(node.items[1], scope))
        if head == "imply":
            if len(node.items) != 3:
                raise self.source.error(node.offset, "expected '(imply condition consequence)'")
            return Imply(self.formula(node.items[1], scope), self.formula(node.items[2], scope))
        if head in ("exists", "forall"):
            names, inner = self._scoped(node, scope)
            body = self.formula(node.items[2], inner)
            return Exists(names, body) if head == "exists" else Forall(names, body)
        if head == "=":
            if len(node.items) != 3:
                raise self.source.error(node.offset, "expected '(= term term)'")
            if any(isinstance(item, SList) for item in node.items[1:]):
                raise self.source.error(node.offset, "unsupported construct: numeric comparison '(= (fluent) ...)'")
            self.used.add(Feature.EQUALITY)
            return Equals(self.term(node.items[1], scope), self.term(node.items[2], scope))
        if head in _NUMERIC_COMPARISONS:
            raise self.source.error(node.offset, f"unsupported construct: numeric comparison '({head} ...)'")
        return self.atom(node, scope)

    def effect(self, node: Node, scope: dict[str, str]) -> Effect:
        """An action effect.

        Raises:
            PddlError: unknown names, numeric effects other than increasing total-cost, or bad structure.
        """
        if not isinstance(node, SList):
            raise self.source.error(node.offset, f"expected an effect '(...)', found '{node.text}'")
        head = node.head()
        if head == "and":
            return And(tuple(self.effect(item, scope) for item in node.items[1:]))
        if head == "not":
            if len(node.items) != 2 or not isinstance(node.items[1], SList):
                raise self.source.error(node.offset, "expected '(not (predicate ...))' in an effect")
            return Not(self.changed_atom(node.items[1], scope))
        if head == "forall":
            names, inner = self._scoped(node, scope)
            return Forall(names, self.effect(node.items[2], inner))
        if head == "when":
            if len(node.items) != 3:
                raise self.source.error(node.offset, "expected '(when condition effect)'")
            self.used.add(Feature.CONDITIONAL_EFFECTS)
            return When(self.formula(node.items[1], scope), self.effect(node.items[2], scope))
        if head == "increase":
            return self._increase(node, scope)
        if head in _NUMERIC_EFFECTS:
            raise self.source.error(
                node.offset, f"unsupported construct: numeric effect '({head} ...)'", "only (increase (total-cost) x)"
            )
        return self.changed_atom(node, scope)

    def changed_atom(self, node: SList, scope: dict[str, str], where: str = "an action effect") -> Atom:
        """An atom an effect (or ``:init``) sets: never one of a derived predicate."""
        atom = self.atom(node, scope)
        if atom.predicate in self.derived:
            raise self.source.error(
                node.offset,
                f"derived predicate '{atom.predicate}' in {where}",
                "derived predicates follow from the (:derived ...) rules; effects and :init name basic predicates only",
            )
        return atom

    def _increase(self, node: SList, scope: dict[str, str]) -> Increase:
        if len(node.items) != 3:
            raise self.source.error(node.offset, "expected '(increase (total-cost) value)'")
        target = expect_list(self.source, node.items[1], "'(total-cost)' after 'increase'")
        fluent = self.fluent(target, scope)
        if fluent != FluentTerm("total-cost"):
            raise self.source.error(
                target.offset, f"unsupported construct: increase of '{fluent}'", "only (total-cost) may be increased"
            )
        value_node = node.items[2]
        value: int | float | FluentTerm
        if isinstance(value_node, SList):
            value = self.fluent(value_node, scope)
        else:
            value = parse_number(self.source, value_node, "the cost")
            if value < 0:
                raise self.source.error(
                    value_node.offset, f"bad number '{value_node.text}' for the cost: costs must not be negative"
                )
        self.used.add(Feature.ACTION_COSTS)
        return Increase(fluent, value)
