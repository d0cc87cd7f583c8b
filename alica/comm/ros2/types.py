"""ROS 2 message types: the ``.msg`` parser, the type registry and type identity.

:func:`lookup` gives a parsed :class:`MsgType` (fields and constants) for a
type name and distro; :func:`dds_name`, :func:`type_hash` (REP-2016 RIHS01) and
:func:`schema_text` (the ``ros2msg`` schema rosbag2 writes into MCAP) give the
names and texts ROS 2 tools use to recognise a type. The definitions come from
:mod:`alica.comm.ros2.messages`.
"""

from __future__ import annotations

import functools
import hashlib
import json
import re
from dataclasses import dataclass

from alica.comm.ros2.messages import check_distro, definitions
from alica.errors import AlicaError

#: primitive name -> (little-endian numpy dtype, size in bytes, REP-2016 field type id)
PRIMITIVES: dict[str, tuple[str, int, int]] = {
    "bool": ("?", 1, 15),
    "byte": ("u1", 1, 16),
    "char": ("u1", 1, 3),  # rosidl maps msg char to uint8
    "int8": ("i1", 1, 2),
    "uint8": ("u1", 1, 3),
    "int16": ("<i2", 2, 4),
    "uint16": ("<u2", 2, 5),
    "int32": ("<i4", 4, 6),
    "uint32": ("<u4", 4, 7),
    "int64": ("<i8", 8, 8),
    "uint64": ("<u8", 8, 9),
    "float32": ("<f4", 4, 10),
    "float64": ("<f8", 8, 11),
}
_STRING_ID = 17
_BOUNDED_STRING_ID = 21
_NESTED_ID = 1
_KIND_OFFSET = {"single": 0, "array": 48, "bounded": 96, "sequence": 144}
_SEPARATOR = "=" * 80
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*$")
_TYPE = re.compile(r"(?P<base>[A-Za-z][\w/]*)(?:<=(?P<sbound>\d+))?(?:\[(?P<le><=)?(?P<size>\d*)\])?$")


@dataclass(frozen=True)
class FieldType:
    """The type of one field.

    Attributes:
        base: a primitive name, ``string``, or the full name of a nested type.
        kind: ``single``, ``array`` (fixed size), ``bounded`` (sequence with a
            maximum) or ``sequence`` (unbounded).
        size: the array length or sequence bound (0 otherwise).
        string_bound: the maximum length of a bounded string (0 when unbounded).
    """

    base: str
    kind: str = "single"
    size: int = 0
    string_bound: int = 0

    @property
    def nested(self) -> bool:
        """Whether the element type is a message type."""
        return self.base not in PRIMITIVES and self.base != "string"


@dataclass(frozen=True)
class Field:
    """One field: its name, type and default value (``None``: the type's zero)."""

    name: str
    type: FieldType
    default: object = None


@dataclass(frozen=True)
class Constant:
    """One constant line (``uint8 ADD=0``)."""

    name: str
    base: str
    value: object


@dataclass(frozen=True)
class MsgType:
    """A parsed message type.

    Attributes:
        name: the full type name, ``pkg/msg/Type``.
        fields: the fields in wire order.
        constants: the constants, in definition order.
        text: the ``.msg`` text it was parsed from.
    """

    name: str
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...]
    text: str


def _resolve(base: str, package: str) -> str:
    """The full name of a type written ``Type``, ``pkg/Type`` or ``pkg/msg/Type``."""
    if base in PRIMITIVES or base == "string":
        return base
    parts = base.split("/")
    if len(parts) == 1:
        return f"{package}/msg/{base}"
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return base


def _parse_type(text: str, package: str, where: str) -> FieldType:
    match = _TYPE.match(text)
    if match is None:
        raise AlicaError(f"{where}: cannot read the type {text!r}")
    base = _resolve(match["base"], package)
    sbound = int(match["sbound"] or 0)
    if sbound and base != "string":
        raise AlicaError(f"{where}: only strings take a bound, not {base!r}")
    if match.group(0).endswith("]"):
        size = int(match["size"] or 0)
        kind = "bounded" if match["le"] else ("array" if match["size"] else "sequence")
        if kind != "sequence" and size == 0:
            raise AlicaError(f"{where}: an array or bounded sequence needs a size > 0")
        return FieldType(base, kind, size, sbound)
    return FieldType(base, "single", 0, sbound)


def _literal(base: str, text: str, where: str) -> object:
    """The value of a constant or default written ``text`` for a primitive ``base``."""
    text = text.strip()
    try:
        if base == "string":
            return text[1:-1] if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'" else text
        if base == "bool":
            if text.lower() not in {"true", "false", "1", "0"}:
                raise ValueError(text)
            return text.lower() in {"true", "1"}
        if base.startswith("float"):
            return float(text)
        return int(text, 0)
    except ValueError:
        raise AlicaError(f"{where}: {text!r} is not a {base} value") from None


def parse_msg(name: str, text: str) -> MsgType:
    """Parse the ``.msg`` text of the type ``name`` (``pkg/msg/Type``).

    Raises:
        AlicaError: a line cannot be read; the message names the type and line.
    """
    package = name.split("/")[0]
    fields: list[Field] = []
    constants: list[Constant] = []
    for number, raw in enumerate(text.splitlines(), 1):
        where = f"{name} line {number}"
        parts = raw.split(None, 1)
        if not parts or parts[0].startswith("#"):
            continue
        if len(parts) < 2:
            raise AlicaError(f"{where}: expected 'type name', got {raw!r}")
        ftype = _parse_type(parts[0], package, where)
        rest = parts[1]
        if "=" in rest.split("#", 1)[0]:
            cname, value = rest.split("=", 1)
            if ftype.base != "string":
                value = value.split("#", 1)[0]
            constants.append(Constant(cname.strip(), ftype.base, _literal(ftype.base, value, where)))
            continue
        words = rest.split("#", 1)[0].split(None, 1)
        if not _NAME.match(words[0]):
            raise AlicaError(f"{where}: {words[0]!r} is not a field name")
        default = None
        if len(words) > 1 and ftype.kind == "single" and not ftype.nested:
            default = _literal(ftype.base, words[1], where)
        fields.append(Field(words[0], ftype, default))
    return MsgType(name, tuple(fields), tuple(constants), text)


@functools.cache
def _registry(distro: str) -> dict[str, MsgType]:
    parsed = {name: parse_msg(name, text) for name, text in definitions(distro).items()}
    for msg in parsed.values():
        for field in msg.fields:
            if field.type.nested and field.type.base not in parsed:
                raise AlicaError(f"{msg.name}.{field.name}: type {field.type.base!r} is not defined")
    return parsed


def known_types(distro: str = "jazzy") -> tuple[str, ...]:
    """The sorted names of every type defined for ``distro``.

    Raises:
        AlicaError: the distro is unknown.
    """
    return tuple(sorted(_registry(distro)))


def lookup(typename: str, distro: str = "jazzy") -> MsgType:
    """The parsed type ``typename`` (``pkg/msg/Type``) of ``distro``.

    Raises:
        AlicaError: the distro or the type is unknown; the message names the known ones.
    """
    check_distro(distro)
    registry = _registry(distro)
    if typename not in registry:
        known = ", ".join(sorted(registry))
        raise AlicaError(f"unknown ROS 2 message type {typename!r} for {distro}: known types are {known}")
    return registry[typename]


def dds_name(typename: str) -> str:
    """The DDS type name: ``geometry_msgs/msg/Twist`` -> ``geometry_msgs::msg::dds_::Twist_``.

    Raises:
        AlicaError: the name is not of the form ``pkg/msg/Type``.
    """
    parts = typename.split("/")
    if len(parts) != 3 or not all(parts):
        raise AlicaError(f"ROS 2 type name {typename!r} is not of the form pkg/msg/Type")
    package, interface, name = parts
    return f"{package}::{interface}::dds_::{name}_"


def _depends(msg: MsgType, distro: str) -> list[str]:
    """Every nested type ``msg`` uses, depth first in field order, each once."""
    seen: list[str] = []

    def visit(current: MsgType) -> None:
        for field in current.fields:
            if field.type.nested and field.type.base not in seen:
                seen.append(field.type.base)
                visit(lookup(field.type.base, distro))

    visit(msg)
    return seen


def _field_description(field: Field) -> dict[str, object]:
    ftype = field.type
    if ftype.nested:
        type_id = _NESTED_ID
    elif ftype.base == "string":
        type_id = _BOUNDED_STRING_ID if ftype.string_bound else _STRING_ID
    else:
        type_id = PRIMITIVES[ftype.base][2]
    return {
        "name": field.name,
        "type": {
            "type_id": type_id + _KIND_OFFSET[ftype.kind],
            "capacity": ftype.size,
            "string_capacity": ftype.string_bound,
            "nested_type_name": ftype.base if ftype.nested else "",
        },
    }


def _description(msg: MsgType) -> dict[str, object]:
    fields = msg.fields or (Field("structure_needs_at_least_one_member", FieldType("uint8")),)
    return {"type_name": msg.name, "fields": [_field_description(f) for f in fields]}


def type_hash(typename: str, distro: str = "jazzy") -> str:
    """The REP-2016 type hash rmw_zenoh puts in keys and liveliness tokens.

    Humble has no type hashes: its rmw_zenoh writes ``TypeHashNotSupported``.
    Later distros get ``RIHS01_`` and the sha256 of the type description
    (the type, then every referenced type sorted by name; field names and type
    ids, capacities and nested names; no defaults, constants or comments) as
    compact JSON with ``", "`` and ``": "`` separators.

    Raises:
        AlicaError: the distro or the type is unknown.
    """
    msg = lookup(typename, distro)
    if distro == "humble":
        return "TypeHashNotSupported"
    referenced = sorted(_depends(msg, distro))
    document = {
        "type_description": _description(msg),
        "referenced_type_descriptions": [_description(lookup(name, distro)) for name in referenced],
    }
    text = json.dumps(document, separators=(", ", ": "), ensure_ascii=False)
    return "RIHS01_" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def schema_text(typename: str, distro: str = "jazzy") -> str:
    """The ``ros2msg`` MCAP schema of ``typename``, as ``ros2 bag record`` writes it.

    The type's ``.msg`` text, then for every nested type (depth first, each
    once) a line of 80 ``=``, a line ``MSG: pkg/Type`` and that type's text.

    Raises:
        AlicaError: the distro or the type is unknown.
    """
    msg = lookup(typename, distro)
    parts = [_ending(msg.text)]
    for name in _depends(msg, distro):
        package, _, short = name.split("/")
        parts.append(f"{_SEPARATOR}\nMSG: {package}/{short}\n{_ending(lookup(name, distro).text)}")
    return "".join(parts)


def _ending(text: str) -> str:
    return text if text.endswith("\n") else text + "\n"
