"""Reading RDDL ``domain``, ``non-fluents`` and ``instance`` blocks (recursive descent).

The expressions are read by :class:`~alica.prophet.rddl.expressions.Cursor`;
this module reads the blocks and their sections. Names are checked against
the declarations afterwards, by :mod:`alica.prophet.rddl.check`.
"""

from __future__ import annotations

from typing import Any

from alica.prophet.rddl.ast import (
    Assignment,
    BoolConst,
    Cpf,
    Domain,
    Instance,
    IntConst,
    Name,
    NonFluents,
    ObjectsDecl,
    Param,
    PVariable,
    RddlFile,
    RealConst,
    TypeDecl,
)
from alica.prophet.rddl.expressions import Cursor, suggestion
from alica.prophet.rddl.lexer import ENUM, EOF, INT, NAME, PRIMED, VAR, Token, tokenize

PVARIABLE_KINDS = (
    "non-fluent",
    "state-fluent",
    "action-fluent",
    "interm-fluent",
    "observ-fluent",
    "derived-fluent",
)
"""The kinds of pvariable a declaration may name."""
_BLOCKS = ("domain", "non-fluents", "instance")
_DOMAIN_SECTIONS = (
    "requirements",
    "types",
    "pvariables",
    "cpfs",
    "cdfs",
    "reward",
    "action-preconditions",
    "state-invariants",
    "state-action-constraints",
    "constraints",
)
_CONSTRAINTS = {
    "action-preconditions": "action_preconditions",
    "state-invariants": "state_invariants",
    "state-action-constraints": "state_action_constraints",
    "constraints": "state_action_constraints",
}
_NON_FLUENTS_SECTIONS = ("domain", "objects", "non-fluents")
_INSTANCE_SECTIONS = ("domain", "non-fluents", "objects", "init-state", "max-nondef-actions", "horizon", "discount")


def parse_blocks(text: str, file: str = "<string>") -> RddlFile:
    """The blocks of ``text``, unchecked (see :func:`alica.prophet.rddl.parse_rddl`).

    Raises:
        RddlError: the text is no valid RDDL.
    """
    reader = _BlockReader(tokenize(text, file), file)
    found: dict[str, Any] = {}
    while reader.peek().kind != EOF:
        token = reader.advance()
        if token.kind != NAME or token.text not in _BLOCKS:
            hint = suggestion(token.text, _BLOCKS) or "a file holds 'domain', 'non-fluents' and 'instance' blocks"
            raise reader.error(token, f"unknown keyword {token.shown()} at the top level", hint)
        if token.text in found:
            raise reader.error(token, f"a second '{token.text}' block", "put each block in a file of its own")
        try:
            found[token.text] = reader.block(token)
        except RecursionError:
            raise reader.too_deep() from None
    return RddlFile(found.get("domain"), found.get("non-fluents"), found.get("instance"))


class _BlockReader(Cursor):
    def block(self, keyword: Token) -> Domain | NonFluents | Instance:
        what = {"domain": "a domain", "non-fluents": "a non-fluents block", "instance": "an instance"}[keyword.text]
        name = self.new_name(what)
        self.expect("{", f"after the name '{name.text}'")
        sections = {"domain": _DOMAIN_SECTIONS, "non-fluents": _NON_FLUENTS_SECTIONS, "instance": _INSTANCE_SECTIONS}
        fields: dict[str, Any] = {}
        while not self.accept("}"):
            word = self.advance()
            allowed = sections[keyword.text]
            if word.kind != NAME or word.text not in allowed:
                hint = suggestion(word.text, allowed) or "expected one of: " + ", ".join(allowed)
                raise self.error(word, f"unknown keyword {word.shown()} in {what}", hint)
            parse_section = {
                "domain": self._domain_section,
                "non-fluents": self._non_fluents_section,
                "instance": self._instance_section,
            }[keyword.text]
            parse_section(word, fields)
        if keyword.text == "domain":
            return Domain(name.text, **fields, line=keyword.line, column=keyword.column)
        if "domain" not in fields:
            raise self.error(name, f"{what} '{name.text}' names no domain", "add 'domain = NAME;'")
        if keyword.text == "non-fluents":
            return NonFluents(name.text, **fields, line=keyword.line, column=keyword.column)
        return Instance(name.text, **fields, line=keyword.line, column=keyword.column)

    def _once(self, word: Token, fields: dict[str, Any], key: str, value: object) -> None:
        if key in fields:
            raise self.error(word, f"a second '{word.text}' section", "merge the two")
        fields[key] = value

    def _domain_section(self, word: Token, fields: dict[str, Any]) -> None:
        key = word.text
        if key == "requirements":
            self.accept("=")
            self.expect("{", "after 'requirements'")
            names = [self.name("a requirement").text]
            while self.accept(","):
                names.append(self.name("a requirement").text)
            self.expect("}", "to close the requirements")
            self._once(word, fields, "requirements", tuple(names))
        elif key == "reward":
            self.expect("=", "after 'reward'")
            self._once(word, fields, "reward", self.expr())
        else:
            self.expect("{", f"after '{key}'")
            items: list[Any] = []
            read = {"types": self._type, "pvariables": self._pvariable, "cpfs": self._cpf, "cdfs": self._cpf}
            while not self.accept("}"):
                if key in read:
                    items.append(read[key]())
                else:
                    items.append(self.expr())
                    self.expect(";", "the constraint")
            self._once(word, fields, _CONSTRAINTS.get(key, "cpfs" if key == "cdfs" else key), tuple(items))
        self.expect(";", f"the '{key}' section")

    def _type(self) -> TypeDecl:
        name = self.new_name("a type")
        self.expect(":", f"after the type '{name.text}'")
        if self.accept("{"):
            values = [self._enum_value()]
            while self.accept(","):
                values.append(self._enum_value())
            self.expect("}", "to close the enum values")
            decl = TypeDecl(name.text, None, tuple(values), line=name.line, column=name.column)
        else:
            parent = self.name("a super type ('object' or a type)")
            decl = TypeDecl(name.text, _name(parent), line=name.line, column=name.column)
        self.expect(";", f"the type '{name.text}'")
        return decl

    def _enum_value(self) -> str:
        token = self.advance()
        if token.kind != ENUM:
            raise self.error(token, f"expected an enum value '@name', found {token.shown()}", "write enum values as @v")
        return token.text

    def _pvariable(self) -> PVariable:
        name = self.new_name("a pvariable")
        params: list[Name] = []
        if self.accept("("):
            params.append(_name(self.name("a parameter type")))
            while self.accept(","):
                params.append(_name(self.name("a parameter type")))
            self.expect(")", "to close the parameter types")
        self.expect(":", f"after the pvariable '{name.text}'")
        self.expect("{", f"to open the declaration of '{name.text}'")
        kind = self.name("a pvariable kind")
        if kind.text not in PVARIABLE_KINDS:
            hint = suggestion(kind.text, PVARIABLE_KINDS) or "one of " + ", ".join(PVARIABLE_KINDS)
            raise self.error(kind, f"unknown pvariable kind {kind.shown()}", hint)
        self.expect(",", "after the kind")
        range_ = _name(self.name("a range (bool, int, real or a type)"))
        extra: dict[str, Any] = {}
        while self.accept(","):
            key = self.name("'default' or 'level'")
            self.expect("=", f"after '{key.text}'")
            if key.text == "default":
                extra["default"] = self.constant()
            elif key.text == "level":
                level = self.advance()
                if level.kind != INT:
                    raise self.error(level, f"expected a whole number for 'level', found {level.shown()}")
                extra["level"] = int(level.text)
            else:
                hint = suggestion(key.text, ("default", "level")) or "write 'default = v' or 'level = n'"
                raise self.error(key, f"unknown keyword {key.shown()} in a pvariable declaration", hint)
        self.expect("}", f"to close the declaration of '{name.text}'")
        self.expect(";", f"the declaration of '{name.text}'")
        return PVariable(name.text, tuple(params), kind.text, range_, **extra, line=name.line, column=name.column)

    def _cpf(self) -> Cpf:
        head = self.advance()
        if head.kind not in {NAME, PRIMED}:
            raise self.error(head, f"expected a fluent name, found {head.shown()}")
        params: list[Param] = []
        if self.accept("("):
            while True:
                var = self.advance()
                if var.kind != VAR:
                    raise self.error(var, f"expected a parameter '?name', found {var.shown()}")
                params.append(Param(var.text, line=var.line, column=var.column))
                if not self.accept(","):
                    break
            self.expect(")", "to close the parameters")
        self.expect("=", f"after the head of the cpf of '{head.text}'")
        expr = self.expr()
        self.expect(";", f"the cpf of '{head.text}'")
        return Cpf(head.text, head.kind == PRIMED, tuple(params), expr, line=head.line, column=head.column)

    def _objects(self) -> tuple[ObjectsDecl, ...]:
        self.expect("{", "after 'objects'")
        decls: list[ObjectsDecl] = []
        while not self.accept("}"):
            type_ = self.name("a type")
            self.expect(":", f"after the type '{type_.text}'")
            self.expect("{", f"to open the objects of '{type_.text}'")
            names = [_name(self.new_name("an object"))]
            while self.accept(","):
                names.append(_name(self.new_name("an object")))
            self.expect("}", f"to close the objects of '{type_.text}'")
            self.expect(";", f"the objects of '{type_.text}'")
            decls.append(ObjectsDecl(_name(type_), tuple(names), line=type_.line, column=type_.column))
        return tuple(decls)

    def _assignments(self, what: str) -> tuple[Assignment, ...]:
        self.expect("{", f"after '{what}'")
        items: list[Assignment] = []
        while not self.accept("}"):
            negated = self.accept("~")
            name = self.name("a pvariable")
            args: list[Name] = []
            if self.accept("("):
                while True:
                    arg = self.advance()
                    if arg.kind not in {NAME, ENUM}:
                        raise self.error(arg, f"expected an object, found {arg.shown()}")
                    args.append(_name(arg))
                    if not self.accept(","):
                        break
                self.expect(")", "to close the arguments")
            first = negated or name
            value: Any = BoolConst(negated is None, line=first.line, column=first.column)
            if negated is None and self.accept("="):
                value = self.constant()
            self.expect(";", f"the value of '{name.text}'")
            items.append(Assignment(name.text, tuple(args), value, line=first.line, column=first.column))
        return tuple(items)

    def _non_fluents_section(self, word: Token, fields: dict[str, Any]) -> None:
        if word.text == "domain":
            self.expect("=", "after 'domain'")
            self._once(word, fields, "domain", _name(self.name("a domain name")))
        elif word.text == "objects":
            self._once(word, fields, "objects", self._objects())
        else:
            self._once(word, fields, "values", self._assignments("non-fluents"))
        self.expect(";", f"the '{word.text}' section")

    def _instance_section(self, word: Token, fields: dict[str, Any]) -> None:
        key = word.text
        if key in {"objects", "domain"}:
            self._non_fluents_section(word, fields)
            return
        if key == "init-state":
            self._once(word, fields, "init_state", self._assignments("init-state"))
        else:
            self.expect("=", f"after '{key}'")
            if key == "non-fluents":
                self._once(word, fields, "non_fluents", _name(self.name("a non-fluents block")))
            elif key == "max-nondef-actions" and self.peek().is_name("pos-inf"):
                self.advance()
                self._once(word, fields, "max_nondef_actions", None)
            else:
                self._once(word, fields, key.replace("-", "_"), self._number(key))
        self.expect(";", f"the '{key}' section")

    def _number(self, key: str) -> int | float:
        token = self.peek()
        value = self.constant()
        if key == "discount" and isinstance(value, IntConst | RealConst) and 0 <= value.value <= 1:
            return float(value.value)
        if key != "discount" and isinstance(value, IntConst) and value.value >= 1:
            return value.value
        need = "a number from 0 to 1" if key == "discount" else "a whole number of at least 1"
        if key == "max-nondef-actions":
            need += " or pos-inf"
        raise self.error(token, f"expected {need} for '{key}', found {token.shown()}")


def _name(token: Token) -> Name:
    return Name(token.text, line=token.line, column=token.column)
