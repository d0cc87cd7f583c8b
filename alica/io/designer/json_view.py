"""Typed reading of a designer file's JSON, every problem located by its key.

``json.loads`` gives untyped values; :class:`View` reads them field by field,
checks each value's type and records what is wrong with the key path where
it was found (``states[2].confAbstractPlanWrappers[0].abstractPlan``), so
the reader of one file reports all of its problems at once and never guesses
at a value of the wrong type. Missing keys read as their defaults: designer
files of different versions leave out different keys.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from alica.io.designer.report import FileError

#: A reference to an element of another file: ``File.ext#id``.
_REFERENCE = re.compile(r"^\s*(?P<file>[^#]*\.(?P<ext>[A-Za-z]+))\s*#\s*(?P<id>-?[0-9]+)\s*$")

#: A scalar of JSON, as a key mapping's constant ``value`` holds it.
Scalar = bool | int | float | str


@dataclass(frozen=True, slots=True)
class Ref:
    """A reference ``File.ext#id`` found at ``key``.

    Attributes:
        file: the file name the reference gives (``Attack.beh``).
        ext: its extension, lower case (``beh``).
        id: the id of the element referred to.
        key: where the reference was written.
        text: the reference as written.
    """

    file: str
    ext: str
    id: int
    key: str
    text: str


def parse_ref(text: str, key: str, sink: Sink) -> Ref | None:
    """The reference ``File.ext#id`` written at ``key``; a malformed one is reported to ``sink``."""
    match = _REFERENCE.match(text)
    if match is None:
        sink.add(key, f"'{text}' is not a reference 'File.ext#id'")
        return None
    return Ref(match["file"].strip(), match["ext"].lower(), int(match["id"]), key, text)


class Sink:
    """The errors found while reading one file."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.errors: list[FileError] = []

    def add(self, key: str, message: str) -> None:
        """Record an error at ``key``."""
        self.errors.append(FileError(self.file, key, message))


def _kind(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "text"
    if isinstance(value, list):
        return "a list"
    return "an object"


class View:
    """A JSON value at a key path of a file.

    Args:
        value: the value (anything ``json.loads`` returns).
        key: its key path; empty for the top of the file.
        sink: where problems go.
    """

    def __init__(self, value: object, key: str, sink: Sink) -> None:
        self.value = value
        self.key = key
        self.sink = sink

    def path(self, name: str) -> str:
        """The key path of the field ``name`` of this object."""
        return f"{self.key}.{name}" if self.key else name

    def _field(self, name: str) -> object:
        if isinstance(self.value, dict):
            return self.value.get(name)
        return None

    def is_object(self) -> bool:
        """Whether the value is a JSON object."""
        return isinstance(self.value, dict)

    def has(self, name: str) -> bool:
        """Whether the field is written and not null."""
        return self._field(name) is not None

    def _wrong(self, name: str, expected: str, value: object) -> None:
        self.sink.add(self.path(name), f"must be {expected}, not {_kind(value)}")

    def text(self, name: str, default: str = "") -> str:
        """A text field (a number is taken as its text)."""
        value = self._field(name)
        if value is None:
            return default
        if isinstance(value, str):
            return value
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return str(value)
        self._wrong(name, "text", value)
        return default

    def number(self, name: str, default: float = 0.0) -> float:
        """A finite number field."""
        value = self._field(name)
        if value is None:
            return default
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            return float(value)
        self._wrong(name, "a finite number", value)
        return default

    def integer(self, name: str, default: int = 0) -> int:
        """A whole number field."""
        value = self._field(name)
        if value is None:
            return default
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
        self._wrong(name, "a whole number", value)
        return default

    def flag(self, name: str, default: bool = False) -> bool:
        """A true/false field."""
        value = self._field(name)
        if value is None:
            return default
        if isinstance(value, bool):
            return value
        self._wrong(name, "true or false", value)
        return default

    def ident(self, name: str) -> int | None:
        """An id field (a whole number, or its text); ``None`` when absent or null."""
        value = self._field(name)
        if value is None:
            return None
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        if isinstance(value, str) and value.strip().lstrip("-").isdigit():
            return int(value)
        self._wrong(name, "an id (a whole number)", value)
        return None

    def ids(self, name: str) -> tuple[int, ...]:
        """A list of ids."""
        out = []
        for item in self.items(name):
            value = item.value
            if isinstance(value, int) and not isinstance(value, bool):
                out.append(value)
            else:
                self.sink.add(item.key, f"must be an id (a whole number), not {_kind(value)}")
        return tuple(out)

    def ref(self, name: str) -> Ref | None:
        """A reference ``File.ext#id``; ``None`` when absent, null or empty."""
        value = self._field(name)
        if value is None or value == "":
            return None
        if not isinstance(value, str):
            self._wrong(name, "a reference 'File.ext#id'", value)
            return None
        return parse_ref(value, self.path(name), self.sink)

    def truthy(self, name: str) -> bool:
        """A field written as true/false or as a number (non-zero is true)."""
        value = self._field(name)
        if value is None:
            return False
        if isinstance(value, (bool, int, float)):
            return bool(value)
        self._wrong(name, "true/false or a number", value)
        return False

    def scalar(self, name: str) -> Scalar | None:
        """A constant: text, a number or true/false; ``None`` when absent or null."""
        value = self._field(name)
        if value is None or isinstance(value, (bool, int, float, str)):
            return value
        self._wrong(name, "text, a number or true/false", value)
        return None

    def items(self, name: str) -> list[View]:
        """The entries of a list field."""
        value = self._field(name)
        if value is None:
            return []
        if not isinstance(value, list):
            self._wrong(name, "a list", value)
            return []
        return [View(item, f"{self.path(name)}[{i}]", self.sink) for i, item in enumerate(value)]

    def objects(self, name: str) -> list[View]:
        """The entries of a list of objects; other entries are reported."""
        out = []
        for item in self.items(name):
            if item.is_object():
                out.append(item)
            else:
                self.sink.add(item.key, f"must be an object, not {_kind(item.value)}")
        return out

    def obj(self, name: str) -> View | None:
        """An object field; ``None`` when absent or null."""
        value = self._field(name)
        if value is None:
            return None
        if not isinstance(value, dict):
            self._wrong(name, "an object", value)
            return None
        return View(value, self.path(name), self.sink)

    def entries(self, name: str) -> list[tuple[str, View]]:
        """The keys and values of an object field, in file order."""
        value = self._field(name)
        if value is None:
            return []
        if not isinstance(value, dict):
            self._wrong(name, "an object", value)
            return []
        return [(str(k), View(v, f"{self.path(name)}.{k}", self.sink)) for k, v in value.items()]
