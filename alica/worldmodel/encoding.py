"""Plain data: checking it, a canonical text for hashing, a stable sort order.

Everything stored in a :class:`~alica.worldmodel.WorldModel` (names,
arguments, values, set items, objects) is *plain data*: ``str``, ``int``,
``float``, ``bool``, ``None`` and tuples of these, nested to any depth. Plain
data is immutable, so a write can be passed by reference to every replica.

Python's own ``hash`` of a string changes from process to process
(``PYTHONHASHSEED``); nothing here uses it. Hashes come from BLAKE2b (entry
hashes) and CRC-32 (bucket choice) over a canonical text, and orders from
:func:`order_key`, so two processes that make the same writes produce the same
digests and the same dumps.
"""

from __future__ import annotations

import math
import zlib
from hashlib import blake2b
from numbers import Integral, Real

OrderKey = tuple[object, ...]


def canonical(value: object, *, key: bool = False) -> tuple[object, str]:
    """Check ``value`` is plain data and give its canonical text, in one pass.

    Subclasses of the plain types (``numpy.float64``, an ``IntEnum``) are
    converted to the plain type, so stored data never depends on a library.
    The text is canonical: strings are length-prefixed, so no choice of
    characters makes two different values encode alike, and ``1``, ``1.0`` and
    ``True`` (equal in Python) encode differently.

    Args:
        value: the value to check.
        key: the value is part of a key (an argument, a set item or an
            object), where NaN is refused because it never equals itself.

    Returns:
        ``(plain_value, text)``: ``value`` itself when already plain, else a
        plain copy, and its canonical text.

    Raises:
        ValueError: ``value`` contains something other than str, int, float,
            bool, None or tuple, or (in a key) a NaN; the message completes
            a sentence such as "the value of pos is ...".
    """
    kind = type(value)
    if kind is str:
        return value, f"s{len(value)}:{value}"  # type: ignore[arg-type]
    if kind is int:
        return value, f"i{value}"
    if kind is float:
        if key and math.isnan(value):  # type: ignore[arg-type]
            raise ValueError("NaN, which never equals itself; use a number or a symbol instead")
        return value, f"f{value!r}"
    if kind is bool:
        return value, ("T" if value else "F")
    if value is None:
        return None, "N"
    if kind is tuple:
        items: list[object] = []
        texts: list[str] = []
        copied = False
        for item in value:  # type: ignore[attr-defined]
            fixed, text = canonical(item, key=key)
            copied = copied or fixed is not item
            items.append(fixed)
            texts.append(text)
        return (tuple(items) if copied else value), "(" + ",".join(texts) + ")"
    if isinstance(value, str):
        return canonical(str(value), key=key)
    if isinstance(value, Integral):
        return canonical(int(value), key=key)
    if isinstance(value, Real):
        return canonical(float(value), key=key)
    if isinstance(value, list):
        hint = "store a tuple instead (stored data must be immutable)"
    else:
        hint = "store only str, int, float, bool, None or tuples of these"
    raise ValueError(f"a {type(value).__name__} ({value!r}); {hint}")


def check_name(name: object, what: str) -> str:
    """A predicate, function, set or type name: a non-empty string.

    Args:
        name: the name to check.
        what: what the name names, for the error message.

    Returns:
        The name.

    Raises:
        ValueError: ``name`` is not a non-empty string.
    """
    if type(name) is not str or not name:
        raise ValueError(f"{what} must be a non-empty string, got {name!r}")
    return name


def encode(value: object) -> str:
    """The canonical text of plain data (see :func:`canonical`).

    Raises:
        ValueError: ``value`` is not plain data.
    """
    return canonical(value)[1]


def order_key(value: object) -> OrderKey:
    """A sort key giving one total order over plain data, the same in every process.

    None sorts first, then booleans, numbers (ints and floats together), strings
    and tuples (element by element).

    Args:
        value: plain data.

    Returns:
        A key for :func:`sorted`.
    """
    kind = type(value)
    if kind is str:
        return (3, value)
    if kind is bool:
        return (1, int(value))  # type: ignore[call-overload]
    if kind is int or kind is float:
        return (2, value)
    if value is None:
        return (0,)
    return (4, tuple(order_key(item) for item in value))  # type: ignore[attr-defined]


def to_json(value: object) -> object:
    """Plain data as JSON data: tuples become lists.

    Args:
        value: plain data.

    Returns:
        Data :func:`json.dumps` accepts.
    """
    if type(value) is tuple:
        return [to_json(item) for item in value]
    return value


def bucket_hash(text: str) -> int:
    """A fast 32-bit CRC of ``text`` (stable across processes), to pick a bucket.

    Args:
        text: the text to hash.

    Returns:
        The hash.
    """
    return zlib.crc32(text.encode("utf-8", "surrogatepass"))


def hash128(text: str) -> int:
    """A 128-bit BLAKE2b hash of ``text`` as an int (stable across processes).

    Args:
        text: the text to hash.

    Returns:
        The hash.
    """
    return int.from_bytes(blake2b(text.encode("utf-8", "surrogatepass"), digest_size=16).digest(), "big")
