"""Checking the names of RDDL blocks against their declarations.

Each error points at the offending token: an undeclared pvariable or one
applied to the wrong number of arguments, a parameter that neither the cpf's
head nor a quantifier binds, an unknown type or object, a block that names
another domain or non-fluents block than the one given.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from alica.prophet.rddl.ast import (
    Aggregate,
    Apply,
    Assignment,
    Binary,
    Distribution,
    Domain,
    EnumValue,
    Expr,
    If,
    Instance,
    Name,
    Neg,
    NonFluents,
    Not,
    ObjectsDecl,
    Param,
    PVariable,
)
from alica.prophet.rddl.errors import RddlError
from alica.prophet.rddl.expressions import suggestion
from alica.source import SourceSpan

_BUILTIN_RANGES = ("bool", "int", "real")


@dataclass(slots=True)
class _Scope:
    file: str
    domain: Domain | None
    types: dict[str, Name | None] = field(default_factory=dict)
    enums: dict[str, tuple[str, ...]] = field(default_factory=dict)
    pvariables: dict[str, PVariable] = field(default_factory=dict)
    objects: dict[str, str] | None = None

    def error(self, node: Name | Expr | Assignment | ObjectsDecl, message: str, hint: str = "") -> RddlError:
        return RddlError(message, SourceSpan(self.file, node.line, node.column), hint)

    def known_type(self, name: Name, *, builtin: bool = False) -> None:
        names = [*self.types, *self.enums, "object", *(_BUILTIN_RANGES if builtin else ())]
        if name.text not in names:
            hint = suggestion(name.text, names) or "declare it in the domain's 'types' section"
            raise self.error(name, f"unknown type '{name.text}'", hint)

    def is_a(self, type_: str, wanted: str) -> bool:
        seen: set[str] = set()
        while type_ != wanted and type_ in self.types and type_ not in seen:
            seen.add(type_)
            parent = self.types[type_]
            type_ = "object" if parent is None else parent.text
        return type_ == wanted or wanted == "object"

    def argument(self, arg: Name, wanted: str, pvariable: str) -> None:
        if arg.text.startswith("@"):
            if arg.text not in self.enums.get(wanted, ()):
                raise self.error(arg, f"'{arg.text}' is no value of '{wanted}' ({pvariable})")
            return
        if self.objects is None:
            return
        if arg.text not in self.objects:
            hint = suggestion(arg.text, list(self.objects)) or "declare it in an 'objects' section"
            raise self.error(arg, f"unknown object '{arg.text}'", hint)
        if self.domain is not None and not self.is_a(self.objects[arg.text], wanted):
            raise self.error(
                arg, f"object '{arg.text}' is a {self.objects[arg.text]}, {pvariable} wants a {wanted} there"
            )


def _count(number: int) -> str:
    return f"{number} argument" + ("" if number == 1 else "s")


def _scope(file: str, domain: Domain | None) -> _Scope:
    scope = _Scope(file, domain)
    if domain is None:
        return scope
    for decl in domain.types:
        if decl.name in scope.types or decl.name in scope.enums:
            raise scope.error(Name(decl.name, line=decl.line, column=decl.column), f"type '{decl.name}' declared twice")
        if decl.parent is None:
            scope.enums[decl.name] = decl.values
        else:
            scope.types[decl.name] = decl.parent
    for pvariable in domain.pvariables:
        if pvariable.name in scope.pvariables:
            place = Name(pvariable.name, line=pvariable.line, column=pvariable.column)
            raise scope.error(place, f"pvariable '{pvariable.name}' declared twice")
        scope.pvariables[pvariable.name] = pvariable
    return scope


def check_domain(domain: Domain, file: str = "<string>") -> None:
    """Check a domain's types, pvariables, cpfs, reward and constraints.

    Args:
        domain: the domain.
        file: the file name messages show.

    Raises:
        RddlError: at the first offending name.
    """
    scope = _scope(file, domain)
    for parent in scope.types.values():
        if parent is not None and parent.text != "object":
            if parent.text in scope.enums:
                raise scope.error(parent, f"the enum type '{parent.text}' cannot be a super type")
            scope.known_type(parent)
    for decl in domain.pvariables:
        for type_ in decl.params:
            scope.known_type(type_)
        scope.known_type(decl.range, builtin=True)
        if isinstance(decl.default, EnumValue) and decl.default.name not in scope.enums.get(decl.range.text, ()):
            raise scope.error(decl.default, f"'{decl.default.name}' is no value of '{decl.range.text}'")
    for cpf in domain.cpfs:
        target = scope.pvariables.get(cpf.name)
        head = Name(cpf.name, line=cpf.line, column=cpf.column)
        if target is None:
            hint = suggestion(cpf.name, list(scope.pvariables)) or "declare it in 'pvariables'"
            raise scope.error(head, f"cpf of the undeclared pvariable '{cpf.name}'", hint)
        if target.kind in {"non-fluent", "action-fluent"}:
            raise scope.error(head, f"the {target.kind} '{cpf.name}' takes no cpf", "remove the cpf")
        if cpf.primed != (target.kind == "state-fluent"):
            if cpf.primed:
                raise scope.error(head, f"'{cpf.name}' is a {target.kind}, only state fluents are primed", "drop the '")
            raise scope.error(head, f"the cpf of the state fluent '{cpf.name}' needs a prime", f"write {cpf.name}'")
        if len(cpf.params) != len(target.params):
            raise scope.error(head, f"'{cpf.name}' takes {_count(len(target.params))}, the cpf has {len(cpf.params)}")
        bound: dict[str, str] = {}
        for param, type_ in zip(cpf.params, target.params):
            if param.name in bound:
                raise scope.error(param, f"parameter '{param.name}' appears twice in the head of '{cpf.name}'")
            bound[param.name] = type_.text
        _expr(scope, cpf.expr, bound, f"the cpf of '{cpf.name}'")
    if domain.reward is not None:
        _expr(scope, domain.reward, {}, "the reward")
    for constraint in (*domain.action_preconditions, *domain.state_invariants, *domain.state_action_constraints):
        _expr(scope, constraint, {}, "a constraint")


def _expr(scope: _Scope, expr: Expr, bound: dict[str, str], where: str, *, argument: bool = False) -> None:
    match expr:
        case Param(name=name):
            if name not in bound:
                raise scope.error(
                    expr,
                    f"parameter '{name}' is not bound in {where}",
                    "bind it in the pvariable's parameters or with a quantifier such as sum_{" + name + " : type}",
                )
        case Apply(name=name, args=args, primed=primed):
            target = scope.pvariables.get(name)
            if primed and (target is None or target.kind != "state-fluent"):
                raise scope.error(expr, f"'{name}' is no state fluent and has no next value in {where}", "drop the '")
            if target is None:
                if argument and not args and (scope.objects is None or name in scope.objects):
                    return
                what = "object or pvariable" if argument and not args else "pvariable"
                hint = suggestion(name, [*scope.pvariables, *(scope.objects or ())]) or "declare it in 'pvariables'"
                raise scope.error(expr, f"undeclared {what} '{name}' in {where}", hint)
            if len(args) != len(target.params):
                raise scope.error(expr, f"'{name}' takes {_count(len(target.params))}, {len(args)} given in {where}")
            for arg in args:
                _expr(scope, arg, bound, where, argument=True)
        case EnumValue(name=name):
            values = [v for vs in scope.enums.values() for v in vs]
            if name not in values:
                hint = suggestion(name, values) or "declare it in an enum type: 'name : {@a, @b};'"
                raise scope.error(expr, f"unknown enum value '{name}' in {where}", hint)
        case Aggregate(params=params, body=body):
            inner = dict(bound)
            for param in params:
                scope.known_type(param.type)
                inner[param.name] = param.type.text
            _expr(scope, body, inner, where)
        case Neg(operand=operand) | Not(operand=operand):
            _expr(scope, operand, bound, where)
        case Binary(left=left, right=right):
            _expr(scope, left, bound, where)
            _expr(scope, right, bound, where)
        case If(cond=cond, then=then, else_=else_):
            for part in (cond, then, else_):
                _expr(scope, part, bound, where)
        case Distribution(args=args):
            for arg in args:
                _expr(scope, arg, bound, where)


def _objects(scope: _Scope, decls: tuple[ObjectsDecl, ...]) -> None:
    if scope.objects is None:
        scope.objects = {}
    for decl in decls:
        if scope.domain is not None:
            scope.known_type(decl.type)
            if decl.type.text in scope.enums:
                raise scope.error(
                    decl.type, f"'{decl.type.text}' is an enum type; its values are declared in the domain"
                )
        for name in decl.names:
            if name.text in scope.objects:
                raise scope.error(name, f"object '{name.text}' declared twice")
            scope.objects[name.text] = decl.type.text


def _values(scope: _Scope, items: tuple[Assignment, ...], kinds: tuple[str, ...], section: str) -> None:
    if scope.domain is None:
        return
    for item in items:
        target = scope.pvariables.get(item.name)
        if target is None or target.kind not in kinds:
            wanted = " or ".join(kinds)
            candidates = [p.name for p in scope.pvariables.values() if p.kind in kinds]
            found = "undeclared pvariable" if target is None else f"{target.kind}"
            hint = suggestion(item.name, candidates) or f"'{section}' sets {wanted}s only"
            raise scope.error(item, f"'{item.name}' in '{section}': {found}, expected a {wanted}", hint)
        if len(item.args) != len(target.params):
            raise scope.error(item, f"'{item.name}' takes {_count(len(target.params))}, {len(item.args)} given")
        for arg, type_ in zip(item.args, target.params):
            scope.argument(arg, type_.text, f"'{item.name}'")


def _domain_name(scope: _Scope, name: Name) -> None:
    if scope.domain is not None and name.text != scope.domain.name:
        raise scope.error(name, f"domain '{name.text}' is not the domain given, '{scope.domain.name}'")


def check_non_fluents(block: NonFluents, domain: Domain | None = None, file: str = "<string>") -> None:
    """Check a non-fluents block: its domain's name, object types and non-fluent values.

    Args:
        block: the non-fluents block.
        domain: its domain; without it, only the objects are checked.
        file: the file name messages show.

    Raises:
        RddlError: at the first offending name.
    """
    scope = _scope(file, domain)
    _domain_name(scope, block.domain)
    _objects(scope, block.objects)
    _values(scope, block.values, ("non-fluent",), "non-fluents")


def check_instance(
    instance: Instance, domain: Domain | None = None, non_fluents: NonFluents | None = None, file: str = "<string>"
) -> None:
    """Check an instance: the names of its domain and non-fluents block, its objects and initial state.

    Args:
        instance: the instance.
        domain: its domain, if known.
        non_fluents: its non-fluents block, if known (it declares objects).
        file: the file name messages show.

    Raises:
        RddlError: at the first offending name.
    """
    scope = _scope(file, domain)
    _domain_name(scope, instance.domain)
    if non_fluents is not None and instance.non_fluents is not None and instance.non_fluents.text != non_fluents.name:
        raise scope.error(
            instance.non_fluents,
            f"non-fluents '{instance.non_fluents.text}' is not the block given, '{non_fluents.name}'",
        )
    if non_fluents is not None:
        _objects(scope, non_fluents.objects)
    if instance.objects:
        _objects(scope, instance.objects)
    _values(scope, instance.init_state, ("state-fluent",), "init-state")
