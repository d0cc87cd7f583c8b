"""The XML vocabulary of plan files: which element maps to which key, and how.

The table is shared by the reader (:mod:`alica.io.xml_format`) and the writer
(:mod:`alica.io.xml_write`); see the former's docstring for the mapping.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import yaml

# --------------------------------------------------------------------------- vocabulary

LIST = "list"
NAMES = "names"
ENTRIES = "entries"
ONE = "one"
TEXT = "text"
VALUE = "value"


@dataclass(frozen=True)
class _Child:
    """A child element of a mapping element.

    Args:
        tag: the element's tag.
        key: the key it gives in the tree.
        shape: ``list``, ``names``, ``entries``, ``one``, ``text`` or ``value``.
        spec: for ``list``/``one`` the spec of the element, for ``entries`` the entry kind.
        attribute: for ``names``, an attribute that may hold the text instead (``href``).
        formula: whether the text is a formula (written as CDATA when it holds ``<>&``).
    """

    tag: str
    key: str
    shape: str
    spec: str = ""
    attribute: str = ""
    formula: bool = False


@dataclass(frozen=True)
class _Spec:
    """How one mapping element maps to keys.

    Args:
        attributes: keys written as attributes, in writing order.
        children: child elements, in the canonical (schema) order.
        content: the key the element's own text gives, if any.
        renamed: attribute -> key where the two differ.
        item_text: a list entry given as plain text in the data means ``{item_text: text}``.
        typed: a list entry given as text is ``name`` or ``name - type``.
        declared: a list entry given as text is ``name/arity``.
    """

    attributes: tuple[str, ...] = ()
    children: tuple[_Child, ...] = ()
    content: str = ""
    renamed: tuple[tuple[str, str], ...] = ()
    item_text: str = ""
    typed: bool = False
    declared: bool = False

    def key_of(self, attribute: str) -> str:
        """The key an attribute gives."""
        return dict(self.renamed).get(attribute, attribute)

    def child(self, tag: str) -> _Child | None:
        """The known child element ``tag``, if any."""
        for child in self.children:
            if child.tag == tag:
                return child
        return None


@dataclass(frozen=True)
class _Entry:
    """Elements collected into one mapping (priorities, params, bindings).

    Args:
        key: the attribute that names the entry.
        typed: values resolved as YAML scalars, lists as ``<item>`` (params).
        as_text: the writer puts the value in the element's text, not ``value=``.
    """

    key: str
    typed: bool = False
    as_text: bool = False


def _text(tag: str, formula: bool = True) -> _Child:
    return _Child(tag, tag, TEXT, formula=formula)


_DESCRIPTION = _text("description", formula=False)

_SPECS: dict[str, _Spec] = {
    "alica": _Spec(
        ("version",),
        (
            _Child("import", "imports", NAMES, attribute="href"),
            _Child("predicate", "predicates", LIST, "declaration"),
            _Child("function", "functions", LIST, "declaration"),
            _Child("skill", "skills", LIST, "skill"),
            _Child("task", "tasks", LIST, "task"),
            _Child("roleset", "rolesets", LIST, "roleset"),
            _Child("behaviour", "behaviours", LIST, "behaviour"),
            _Child("plan", "plans", LIST, "plan"),
            _Child("plantype", "plantypes", LIST, "plantype"),
            _Child("problem", "problems", LIST, "problem"),
        ),
        renamed=(("version", "alica"),),
    ),
    "declaration": _Spec(("name", "arity", "doc"), declared=True),
    "skill": _Spec(
        ("name", "doc"),
        (_Child("capability", "capabilities", NAMES), _Child("parameter", "params", LIST, "skillparameter")),
    ),
    # 'default' is an attribute when its text reads back by the parameter's type, else a <default> element
    "skillparameter": _Spec(("name", "type", "required", "doc"), (_Child("default", "default", VALUE),)),
    "task": _Spec(("name", "description"), (_DESCRIPTION,), item_text="name"),
    "roleset": _Spec(
        ("name", "default_priority", "description"),
        (_DESCRIPTION, _Child("role", "roles", LIST, "role")),
    ),
    "role": _Spec(
        ("name", "description"),
        (
            _DESCRIPTION,
            _Child("requires", "requires", NAMES),
            _Child("priority", "priorities", ENTRIES, "priority"),
        ),
    ),
    "behaviour": _Spec(
        ("name", "skill", "frequency", "description"),
        (
            _DESCRIPTION,
            _Child("variable", "variables", LIST, "variable"),
            _Child("param", "params", ENTRIES, "param"),
            _text("pre"),
            _text("run"),
            _text("post"),
        ),
    ),
    "variable": _Spec(("name", "type", "min", "max", "candidates"), typed=True),
    "plan": _Spec(
        ("name", "frequency", "description"),
        (
            _DESCRIPTION,
            _Child("variable", "variables", LIST, "variable"),
            _text("pre"),
            _text("run"),
            _Child("utility", "utility", ONE, "utility"),
            _Child("constraint", "constraints", LIST, "constraint"),
            _Child("signature", "signature", ONE, "signature"),
            _Child("entrypoint", "entry_points", LIST, "entrypoint"),
            _Child("state", "states", LIST, "state"),
            _Child("synchronisation", "synchronisations", LIST, "synchronisation"),
        ),
    ),
    "utility": _Spec(
        ("priority_weight", "similarity_weight", "threshold"),
        (_Child("summand", "summands", LIST, "summand"),),
    ),
    "summand": _Spec(("name", "weight"), content="expression"),
    "constraint": _Spec(("name",), (_Child("variable", "variables", NAMES), _text("formula"), _text("utility"))),
    "signature": _Spec(
        ("cost", "duration"),
        (_Child("parameter", "parameters", LIST, "variable"), _text("precondition"), _text("effect")),
    ),
    "entrypoint": _Spec(("name", "task", "state", "min", "max", "success_required")),
    "state": _Spec(
        ("name", "kind", "description"),
        (
            _DESCRIPTION,
            _Child("child", "children", LIST, "child"),
            _text("post"),
            _Child("transition", "transitions", LIST, "transition"),
        ),
    ),
    "child": _Spec(("ref",), (_Child("bind", "bind", ENTRIES, "bind"),), item_text="ref"),
    "transition": _Spec(("name", "to", "sync"), (_text("condition"),)),
    "synchronisation": _Spec(
        ("name", "talk_timeout", "sync_timeout", "fail_on_timeout"),
        (_Child("transition", "transitions", NAMES),),
    ),
    "plantype": _Spec(("name", "description"), (_DESCRIPTION, _Child("plan", "plans", NAMES))),
    "problem": _Spec(
        ("name", "wait_plan", "alternative_plan", "update_time", "timeout", "planner", "description"),
        (
            _DESCRIPTION,
            _Child("element", "elements", NAMES),
            _Child("object", "objects", LIST, "variable"),
            _text("world"),
            _text("goal"),
        ),
    ),
}

_ENTRIES: dict[str, _Entry] = {
    "priority": _Entry("task"),
    "param": _Entry("name", typed=True),
    "bind": _Entry("variable", as_text=True),
}

_XSI = "http://www.w3.org/2001/XMLSchema-instance"
_XML_NS = "http://www.w3.org/XML/1998/namespace"
_NEWLINE = re.compile(r"\r\n?|\n")

# --------------------------------------------------------------------------- YAML scalar rules

_RESOLVER = yaml.resolver.Resolver()
_CONSTRUCTOR = yaml.constructor.SafeConstructor()
_SCALAR_TAGS = {f"tag:yaml.org,2002:{t}" for t in ("null", "bool", "int", "float")}


def resolve_scalar(text: str) -> str | int | float | bool | None:
    """``text`` as a YAML 1.1 plain scalar would read: int, float, bool, null, else the text.

    Dates and other tagged forms stay text, as the YAML reader keeps them.
    """
    tag = _RESOLVER.resolve(yaml.ScalarNode, text, (True, False))
    if tag not in _SCALAR_TAGS:
        return text
    try:
        value = _CONSTRUCTOR.yaml_constructors[tag](_CONSTRUCTOR, yaml.ScalarNode(tag, text))
    except (ValueError, ArithmeticError, yaml.YAMLError):
        return text
    if isinstance(value, (bool, int, float)) or value is None:
        return value
    return text


def _yaml_float(value: float) -> str:
    """A float as text that YAML 1.1 reads back as the same float."""
    if math.isnan(value):
        return ".nan"
    if math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    text = repr(value)
    if "." not in text and "e" in text:
        mantissa, exponent = text.split("e", 1)
        text = f"{mantissa}.0e{exponent}"
    return text
