"""Write plan data as XML: the inverse of :func:`alica.io.xml_format.read_xml`."""

from __future__ import annotations

import datetime
import math
import re
from typing import Any

from lxml import etree

from alica.io.build import DECLARED_NAME, RANGED_NAME, TYPE_RANGE, TYPED_NAME
from alica.io.fields import to_number
from alica.io.skill_declarations import coerce_default
from alica.io.tree import Node
from alica.io.xml_vocabulary import (
    _ENTRIES,
    _SPECS,
    LIST,
    NAMES,
    ONE,
    TEXT,
    VALUE,
    _Child,
    _yaml_float,
    resolve_scalar,
)
from alica.source import Diagnostic, SourceSpan

# --------------------------------------------------------------------------- writing

#: Characters XML 1.0 cannot hold, not even as character references.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def unwritable_text(tree: Node) -> list[Diagnostic]:
    """Every key or text of a located tree that XML 1.0 cannot hold, at its place.

    ``alica convert`` checks the tree before writing XML, so a control character
    in a description is reported where it was written, not as a failed write.
    """
    problems: list[Diagnostic] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        if isinstance(node.value, dict):
            for key, child in node.value.items():
                bad = _NOT_XML.search(key)
                if bad is not None:
                    problems.append(_unwritable(node.key_span(key), bad.group(), "key"))
                todo.append(child)
        elif isinstance(node.value, list):
            todo.extend(node.value)
        elif isinstance(node.value, str):
            bad = _NOT_XML.search(node.value)
            if bad is not None:
                problems.append(_unwritable(node.text_span(bad.start() + 1), bad.group(), "text"))
    return problems


def _unwritable(span: SourceSpan, char: str, what: str) -> Diagnostic:
    return Diagnostic(
        span,
        f"the {what} holds the character U+{ord(char):04X}, which XML cannot hold",
        "remove it, or keep this file in YAML",
    )


def write_xml(data: dict[str, Any]) -> str:
    """Plain data (as from :func:`alica.io.dump.document_data`) as an XML plan file.

    Returns:
        UTF-8 XML text with an ``<?xml ...?>`` header, indented by two spaces.

    Raises:
        ValueError: a key the XML form does not know, or text XML cannot hold
            (control characters other than tab, newline and carriage return).
    """
    if not isinstance(data, dict):
        raise ValueError(f"write_xml needs a mapping of sections, not {type(data).__name__}")
    root = etree.Element("alica")
    rest = dict(data)
    rest.setdefault("alica", 1)
    _fill(root, "alica", rest, "the document")
    body = etree.tostring(root, encoding="unicode", pretty_print=True)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + body


def _scalar_text(value: Any, where: str) -> str:
    """A scalar as attribute or element text (numbers as xs:double allows)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "INF" if value > 0 else "-INF"
        return repr(value)
    if isinstance(value, str):
        return value
    if isinstance(value, (datetime.date, datetime.datetime)):
        return value.isoformat()
    raise ValueError(f"cannot write {value!r} ({type(value).__name__}) as text in {where}")


def _set(el: Any, attribute: str, value: Any, where: str) -> None:
    try:
        el.set(attribute, _scalar_text(value, where))
    except ValueError as exc:
        raise ValueError(f"cannot write '{attribute}' of {where} as XML: {exc}") from exc


def _set_text(el: Any, value: Any, where: str, formula: bool = False) -> None:
    text = _scalar_text(value, where)
    try:
        if formula and any(c in text for c in "<>&") and "]]>" not in text and "\r" not in text:
            el.text = etree.CDATA(text)
        else:
            el.text = text
    except ValueError as exc:
        raise ValueError(f"cannot write <{el.tag}> of {where} as XML: {exc}") from exc


def _as_element(key: str, value: Any) -> bool:
    """Descriptions of more than one line are written as elements, not attributes."""
    return key == "description" and isinstance(value, str) and "\n" in value


def _listed(value: Any) -> list[Any]:
    if isinstance(value, (list, tuple)):
        return list(value)
    return [value]


def _typed_entry(item: Any) -> dict[str, Any]:
    """``name``, ``name - type`` or ``name - type[low, high]`` as ``{name, type, min, max}``.

    A mapping's ``range: [low, high]`` becomes ``min`` and ``max``, the XML attributes.
    """
    if isinstance(item, dict):
        if "range" not in item:
            return item
        out = {k: v for k, v in item.items() if k != "range"}
        bounds = item["range"]
        if not isinstance(bounds, (list, tuple)) or len(bounds) != 2:
            raise ValueError(f"'range' of variable '{item.get('name')}' must be [low, high] to write it as XML")
        out["min"], out["max"] = bounds
        return out
    text = _scalar_text(item, "a typed name")
    match = TYPED_NAME.match(text)
    if match:
        return {"name": match.group(1), **({"type": match.group(2)} if match.group(2) else {})}
    match = RANGED_NAME.match(text)
    if match:
        bounds = match.group(3).split(",")
        if len(bounds) == 2:
            low, high = (_bound_value(b) for b in bounds)
            return {"name": match.group(1), "type": match.group(2), "min": low, "max": high}
    if " - " in text:
        name, kind = text.split(" - ", 1)
        return {"name": name.strip(), "type": kind.strip()}
    return {"name": text}


def _bound_value(text: str) -> Any:
    """A bound of a short-form range as a number (text when it is none: reading it back reports it)."""
    value = to_number(text)
    if value is None:
        return text.strip()
    return int(value) if math.isfinite(value) and value.is_integer() and abs(value) < 1e15 else value


def _named_type(name: str, kind: Any) -> dict[str, Any]:
    """One entry of the ``name: type`` form (the type perhaps with a range, ``point[-5, 5]``)."""
    if kind is None:
        return {"name": name}
    match = TYPE_RANGE.match(kind) if isinstance(kind, str) else None
    if match is not None and match.group(2) is not None:
        bounds = match.group(2).split(",")
        if len(bounds) == 2:
            low, high = (_bound_value(b) for b in bounds)
            return {"name": name, "type": match.group(1), "min": low, "max": high}
    return {"name": name, "type": kind}


def _declared_entry(item: Any) -> dict[str, Any]:
    """``name/arity`` as ``{name, arity}``."""
    text = _scalar_text(item, "a declaration")
    match = DECLARED_NAME.match(text)
    if match is None:
        raise ValueError(f"'{text}' is not 'name/arity': cannot write it as XML")
    return {"name": match.group(1), "arity": int(match.group(2))}


def _fill(el: Any, spec_name: str, data: dict[str, Any], where: str) -> None:
    spec = _SPECS[spec_name]
    label = data.get("name") if isinstance(data.get("name"), str) else None
    where = f"{spec_name} '{label}'" if label else where
    known: set[str] = set()
    for attribute in spec.attributes:
        key = spec.key_of(attribute)
        known.add(key)
        value = data.get(key)
        if value is None or _as_element(key, value):
            continue
        _set(el, attribute, value, where)
    for child in spec.children:
        known.add(child.key)
        value = data.get(child.key)
        if value is None:
            continue
        if child.shape == TEXT:
            if child.key in spec.attributes and not _as_element(child.key, value):
                continue  # written as an attribute above
            _set_text(etree.SubElement(el, child.tag), value, where, child.formula)
        elif child.shape == VALUE:
            text = _attribute_text(value, data.get("type"))
            if text is not None:
                _set(el, child.key, value, where)
            else:
                _write_value(etree.SubElement(el, child.tag), value, where, as_text=True)
        elif child.shape == ONE:
            if not isinstance(value, dict):
                raise ValueError(f"'{child.key}' of {where} must be a mapping to write it as XML")
            _fill(etree.SubElement(el, child.tag), child.spec, value, where)
        elif child.shape == LIST:
            item_spec = _SPECS[child.spec]
            if isinstance(value, dict) and item_spec.typed:  # {name: type}
                value = [_named_type(k, v) for k, v in value.items()]
            for item in _listed(value):
                if item_spec.typed:
                    item = _typed_entry(item)
                elif item_spec.declared and not isinstance(item, dict):
                    item = _declared_entry(item)
                elif not isinstance(item, dict) and item_spec.item_text:
                    item = {item_spec.item_text: item}
                if not isinstance(item, dict):
                    raise ValueError(f"each entry of '{child.key}' in {where} must be a mapping to write it as XML")
                _fill(etree.SubElement(el, child.tag), child.spec, item, where)
        elif child.shape == NAMES:
            for item in _listed(value):
                sub = etree.SubElement(el, child.tag)
                if child.attribute:
                    _set(sub, child.attribute, item, where)
                else:
                    _set_text(sub, item, where)
        else:
            _write_entries(el, child, value, where)
    if spec.content:
        known.add(spec.content)
        value = data.get(spec.content)
        if value is not None:
            _set_text(el, value, where, formula=True)
    unknown = [k for k in data if k not in known]
    if unknown:
        raise ValueError(f"cannot write key '{unknown[0]}' of {where} as XML: the XML form has no such key")


def _attribute_text(value: Any, kind: Any) -> str | None:
    """A skill parameter's default as attribute text that reads back as the same value, or ``None``.

    The reader reads a ``default="..."`` attribute by the parameter's type
    (:func:`alica.io.skill_declarations.coerce_default`); a value that would
    read back otherwise (a list, a number of an ``any`` parameter) needs the
    ``<default>`` element.
    """
    if isinstance(value, (list, tuple)) or value is None:
        return None
    try:
        text = _scalar_text(value, "a default")
    except ValueError:
        return None
    back = coerce_default(text, kind if isinstance(kind, str) else "any")
    return text if type(back) is type(value) and back == value else None


def _write_entries(el: Any, child: _Child, value: Any, where: str) -> None:
    if not isinstance(value, dict):
        raise ValueError(f"'{child.key}' of {where} must be a mapping to write it as XML")
    entry = _ENTRIES[child.spec]
    for key, item in value.items():
        sub = etree.SubElement(el, child.tag)
        _set(sub, entry.key, str(key), where)
        if entry.typed:
            _write_value(sub, item, where, as_text=False)
        elif entry.as_text:
            if item is not None:
                _set_text(sub, item, where, formula=True)
        elif item is not None:
            _set(sub, "value", item, where)


def _write_value(el: Any, value: Any, where: str, as_text: bool) -> None:
    """A parameter value on ``<param>`` (``value=``) or ``<item>`` (text)."""
    if isinstance(value, (list, tuple)):
        if not value:
            el.set("type", "list")
        for item in value:
            _write_value(etree.SubElement(el, "item"), item, where, as_text=True)
        return
    if value is None:
        return
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, int):
        text = str(value)
    elif isinstance(value, float):
        text = _yaml_float(value)
    elif isinstance(value, str):
        text = value
    else:
        raise ValueError(f"cannot write parameter value {value!r} ({type(value).__name__}) of {where} as XML")
    if as_text and text:
        _set_text(el, text, where)
    else:
        _set(el, "value", text, where)
    if isinstance(value, str):
        resolved = resolve_scalar(value)
        if not isinstance(resolved, str) or resolved != value:
            el.set("type", "str")
