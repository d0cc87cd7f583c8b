"""The ROS 2 wire codec: classic CDR (XCDR1), little endian, as rmw and rosbag2 carry it.

:func:`encode` turns nested dicts into a payload with the encapsulation header
``00 01 00 00``; :func:`decode` turns a payload back into dicts. Primitives
align to their size counted from after the header; strings are a uint32 length
(with the NUL), the UTF-8 bytes and a NUL; sequences are a uint32 count and the
elements; fixed arrays have no count. Arrays of primitives go through numpy in
one piece, and decode to little-endian numpy arrays.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from typing import Any

import numpy as np

from alica.comm.ros2.types import PRIMITIVES, Field, FieldType, MsgType, lookup
from alica.errors import AlicaError

HEADER = b"\x00\x01\x00\x00"
_FORMATS = {
    "bool": "?",
    "byte": "B",
    "char": "B",
    "int8": "b",
    "uint8": "B",
    "int16": "h",
    "uint16": "H",
    "int32": "i",
    "uint32": "I",
    "int64": "q",
    "uint64": "Q",
    "float32": "f",
    "float64": "d",
}
_STRUCTS = {name: struct.Struct("<" + code) for name, code in _FORMATS.items()}
_COUNT = struct.Struct("<I")
_MISSING: Any = object()
_INTEGERS = (int, np.integer)
_NUMBERS = (int, float, np.integer, np.floating)


def _limits(base: str) -> tuple[int, int]:
    info = np.iinfo(np.dtype(PRIMITIVES[base][0]))
    return int(info.min), int(info.max)


def _is_integer_type(base: str) -> bool:
    return base not in {"bool", "float32", "float64"}


class _Encoder:
    """Writes one message into a growing buffer, checking every value."""

    def __init__(self, typename: str, distro: str) -> None:
        self.typename = typename
        self.distro = distro
        self.buf = bytearray(HEADER)

    def fail(self, path: str, text: str) -> AlicaError:
        return AlicaError(f"{self.typename}{path}: {text}")

    def align(self, size: int) -> None:
        pad = -(len(self.buf) - 4) % size
        if pad:
            self.buf += bytes(pad)

    def message(self, msg: MsgType, value: Any, path: str) -> None:
        if not isinstance(value, Mapping):
            raise self.fail(path, f"expected a mapping of {msg.name} fields, got {type(value).__name__}")
        names = {f.name for f in msg.fields}
        for key in value:
            if key not in names:
                known = ", ".join(f.name for f in msg.fields)
                raise self.fail(f"{path}.{key}", f"{msg.name} has no field {key!r} (its fields: {known})")
        for field in msg.fields:
            self.field(field, value.get(field.name, _MISSING), f"{path}.{field.name}")

    def field(self, field: Field, value: Any, path: str) -> None:
        ftype = field.type
        if ftype.kind != "single":
            self.many(ftype, value, path)
        elif value is _MISSING:
            self.single(ftype, _default(field), path)
        else:
            self.single(ftype, value, path)

    def single(self, ftype: FieldType, value: Any, path: str) -> None:
        if ftype.nested:
            self.message(lookup(ftype.base, self.distro), value, path)
        elif ftype.base == "string":
            self.string(value, ftype.string_bound, path)
        else:
            self.scalar(ftype.base, value, path)

    def scalar(self, base: str, value: Any, path: str) -> None:
        packer = _STRUCTS[base]
        checked = self.check_scalar(base, value, path)
        self.align(packer.size)
        try:
            self.buf += packer.pack(checked)
        except (OverflowError, struct.error):
            raise self.fail(path, f"{value!r} is out of the {base} range") from None

    def check_scalar(self, base: str, value: Any, path: str) -> bool | int | float:
        if base == "bool":
            if not isinstance(value, (bool, np.bool_)):
                raise self.fail(path, f"expected a bool, got {value!r}")
            return bool(value)
        if isinstance(value, (bool, np.bool_)):
            raise self.fail(path, f"expected a {base} number, got {value!r}")
        if _is_integer_type(base):
            if base == "byte" and isinstance(value, bytes) and len(value) == 1:
                return value[0]
            if not isinstance(value, _INTEGERS):
                raise self.fail(path, f"expected an integer, got {value!r}")
            low, high = _limits(base)
            if not low <= int(value) <= high:
                raise self.fail(path, f"{value!r} is out of the {base} range [{low}, {high}]")
            return int(value)
        if not isinstance(value, _NUMBERS):
            raise self.fail(path, f"expected a number, got {value!r}")
        return float(value)

    def string(self, value: Any, bound: int, path: str) -> None:
        if not isinstance(value, str):
            raise self.fail(path, f"expected a str, got {value!r}")
        if "\0" in value:
            raise self.fail(path, "a ROS 2 string cannot hold a NUL character")
        try:
            raw = value.encode("utf-8")
        except UnicodeEncodeError as exc:
            raise self.fail(path, f"cannot encode as UTF-8: {exc.reason}") from None
        if bound and len(raw) > bound:
            raise self.fail(path, f"string of {len(raw)} bytes is longer than its bound {bound}")
        self.align(4)
        self.buf += _COUNT.pack(len(raw) + 1)
        self.buf += raw
        self.buf += b"\0"

    def many(self, ftype: FieldType, value: Any, path: str) -> None:
        if value is _MISSING:
            value = _empty(ftype)
        if ftype.base in PRIMITIVES:
            array = _primitive_array(ftype.base, value, lambda text: self.fail(path, text))
            self.check_length(ftype, len(array), path)
            self.count(ftype, len(array))
            if len(array):
                self.align(PRIMITIVES[ftype.base][1])
                self.buf += array.tobytes()
            return
        if not isinstance(value, (list, tuple)):
            raise self.fail(path, f"expected a list, got {type(value).__name__}")
        self.check_length(ftype, len(value), path)
        self.count(ftype, len(value))
        element = FieldType(ftype.base, "single", 0, ftype.string_bound)
        for index, item in enumerate(value):
            self.single(element, item, f"{path}[{index}]")

    def check_length(self, ftype: FieldType, length: int, path: str) -> None:
        if ftype.kind == "array" and length != ftype.size:
            raise self.fail(path, f"expected exactly {ftype.size} elements, got {length}")
        if ftype.kind == "bounded" and length > ftype.size:
            raise self.fail(path, f"expected at most {ftype.size} elements, got {length}")

    def count(self, ftype: FieldType, length: int) -> None:
        if ftype.kind != "array":
            self.align(4)
            self.buf += _COUNT.pack(length)


def _default(field: Field) -> Any:
    if field.default is not None:
        return field.default
    base = field.type.base
    if field.type.nested:
        return {}
    if base == "string":
        return ""
    if base == "bool":
        return False
    return 0.0 if base.startswith("float") else 0


def _empty(ftype: FieldType) -> Any:
    """The value of a missing array field: zeros for fixed arrays, empty otherwise."""
    if ftype.kind != "array":
        return []
    if ftype.base in PRIMITIVES:
        return np.zeros(ftype.size, dtype=PRIMITIVES[ftype.base][0])
    return ["" if ftype.base == "string" else {} for _ in range(ftype.size)]


def _primitive_array(base: str, value: Any, fail: Any) -> np.ndarray[Any, Any]:
    """``value`` as a flat numpy array of ``base``'s wire dtype, checked.

    ``fail(text)`` builds the error to raise.
    """
    dtype = np.dtype(PRIMITIVES[base][0])
    if isinstance(value, (bytes, bytearray, memoryview)):
        if dtype.itemsize != 1 or base == "bool":
            raise fail(f"bytes are accepted only for 1-byte integer arrays, not {base}")
        return np.frombuffer(value, dtype=dtype)
    if isinstance(value, np.ndarray):
        array = value.reshape(-1)
    elif isinstance(value, (list, tuple)):
        try:
            array = np.asarray(value).reshape(-1)
        except (ValueError, TypeError, OverflowError):
            raise fail(f"expected a flat list of {base} values") from None
    else:
        raise fail(f"expected a list or numpy array of {base}, got {type(value).__name__}")
    if array.size == 0:
        return np.zeros(0, dtype=dtype)
    kind = array.dtype.kind
    if base == "bool":
        if kind != "b":
            raise fail(f"expected bools, got an array of {array.dtype}")
        return array.astype(dtype)
    if _is_integer_type(base):
        if kind not in "iu":
            raise fail(f"expected integers, got an array of {array.dtype}")
        low, high = _limits(base)
        smallest, largest = int(array.min()), int(array.max())
        if smallest < low or largest > high:
            bad = smallest if smallest < low else largest
            raise fail(f"element {bad} is out of the {base} range [{low}, {high}]")
        return array.astype(dtype, copy=False)
    if kind not in "iuf":
        raise fail(f"expected numbers, got an array of {array.dtype}")
    with np.errstate(over="ignore", invalid="ignore"):
        converted = array.astype(dtype, copy=False)
    if kind == "f" and array.dtype.itemsize > dtype.itemsize:
        overflow = np.isinf(converted) & np.isfinite(array)
        if overflow.any():
            raise fail(f"element {float(array[overflow][0])!r} is out of the {base} range")
    return converted


def encode(typename: str, value: Mapping[str, Any], distro: str = "jazzy") -> bytes:
    """Serialize ``value`` (nested dicts keyed by field name) as a CDR payload.

    Missing fields take their default (zero, empty, or the ``.msg`` default);
    arrays of primitives accept lists, tuples, numpy arrays and, for 1-byte
    integer types, bytes.

    Raises:
        AlicaError: the type or distro is unknown, or a value is wrong (unknown
            field, wrong kind, integer out of range, wrong array length); the
            message names the type and the field path.
    """
    encoder = _Encoder(typename, distro)
    encoder.message(lookup(typename, distro), value, "")
    return bytes(encoder.buf)


class _Decoder:
    """Reads one message from a payload, checking every length against the data left."""

    def __init__(self, typename: str, distro: str, data: bytes) -> None:
        self.typename = typename
        self.distro = distro
        self.data = data
        self.pos = 4

    def fail(self, path: str, text: str) -> AlicaError:
        return AlicaError(f"{self.typename}{path}: malformed CDR data: {text}")

    def take(self, size: int, align: int, path: str) -> int:
        """Align to ``align``, reserve ``size`` bytes and return where they start."""
        start = self.pos + (-(self.pos - 4) % align)
        if start + size > len(self.data):
            raise self.fail(path, f"needs {size} bytes at offset {start}, the data has {len(self.data)}")
        self.pos = start + size
        return start

    def message(self, msg: MsgType, path: str) -> dict[str, Any]:
        return {f.name: self.field(f.type, f"{path}.{f.name}") for f in msg.fields}

    def field(self, ftype: FieldType, path: str) -> Any:
        if ftype.kind == "single":
            return self.single(ftype, path)
        return self.many(ftype, path)

    def single(self, ftype: FieldType, path: str) -> Any:
        if ftype.nested:
            return self.message(lookup(ftype.base, self.distro), path)
        if ftype.base == "string":
            return self.string(ftype.string_bound, path)
        unpacker = _STRUCTS[ftype.base]
        return unpacker.unpack_from(self.data, self.take(unpacker.size, unpacker.size, path))[0]

    def string(self, bound: int, path: str) -> str:
        length = _COUNT.unpack_from(self.data, self.take(4, 4, path))[0]
        if length == 0:
            return ""
        start = self.take(length, 1, path)
        if self.data[start + length - 1] != 0:
            raise self.fail(path, "a string does not end with NUL")
        try:
            return self.data[start : start + length - 1].decode("utf-8")
        except UnicodeDecodeError as exc:
            raise self.fail(path, f"a string is not UTF-8 ({exc.reason})") from None

    def many(self, ftype: FieldType, path: str) -> Any:
        if ftype.kind == "array":
            count = ftype.size
        else:
            count = _COUNT.unpack_from(self.data, self.take(4, 4, path))[0]
            if ftype.kind == "bounded" and count > ftype.size:
                raise self.fail(path, f"{count} elements exceed the bound {ftype.size}")
        if ftype.base in PRIMITIVES:
            dtype, size, _ = PRIMITIVES[ftype.base]
            if count == 0:
                return np.zeros(0, dtype=dtype)
            start = self.take(count * size, size, path)
            array = np.frombuffer(self.data, dtype=dtype, count=count, offset=start).copy()
            return array if ftype.base != "bool" else array.view("u1") != 0
        if count > len(self.data) - self.pos:
            raise self.fail(path, f"a count of {count} exceeds the {len(self.data) - self.pos} bytes left")
        element = FieldType(ftype.base, "single", 0, ftype.string_bound)
        return [self.single(element, f"{path}[{index}]") for index in range(count)]


def decode(typename: str, data: bytes, distro: str = "jazzy") -> dict[str, Any]:
    """Deserialize a CDR payload of ``typename`` into nested dicts.

    Primitive arrays come back as little-endian numpy arrays, strings as str,
    nested messages as dicts and sequences of them as lists. Bytes after the
    message are ignored.

    Raises:
        AlicaError: the type or distro is unknown, or the data is malformed
            (short, wrong header, a string without NUL, a count larger than the
            data left, invalid UTF-8).
    """
    msg = lookup(typename, distro)
    payload = bytes(data)
    if len(payload) < 4 or payload[:2] != HEADER[:2]:
        raise AlicaError(
            f"{typename}: malformed CDR data: expected the little-endian CDR header 00 01, got {payload[:4].hex(' ')!r}"
        )
    return _Decoder(typename, distro, payload).message(msg, "")
