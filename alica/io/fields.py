"""Reading typed fields out of a located tree, collecting every problem on the way."""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable

from alica.io.tree import Node
from alica.source import Diagnostic, SourceSpan

_TRUE = {"true", "yes", "on", "1"}
_FALSE = {"false", "no", "off", "0"}
_UNBOUNDED = {"*", "inf", ".inf", "infinity", "n"}


def suggest(word: str, choices: Iterable[str]) -> str:
    """`` did you mean 'x'?`` for the closest choice, or an empty string."""
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"did you mean '{close[0]}'?" if close else ""


def kind_of(node: Node) -> str:
    """A person's word for the node's type."""
    if node.is_mapping:
        return "a mapping"
    if node.is_list:
        return "a list"
    if node.value is None:
        return "nothing"
    return {bool: "true/false", int: "a number", float: "a number", str: "text"}.get(type(node.value), "a value")


class Problems:
    """The diagnostics collected while reading one document set."""

    def __init__(self) -> None:
        self.items: list[Diagnostic] = []

    def add(self, span: SourceSpan | None, message: str, hint: str = "") -> None:
        """Record an error at ``span``."""
        self.items.append(Diagnostic(span or SourceSpan("<unknown>"), message, hint))

    def __bool__(self) -> bool:
        return bool(self.items)


class Fields:
    """The keys of one mapping node, read by type; unknown keys are reported.

    Args:
        node: the mapping.
        what: how to name the element in messages, e.g. ``plan 'Mission'``.
        problems: where problems go.
        allowed: every key the element may have.
    """

    def __init__(self, node: Node, what: str, problems: Problems, allowed: Iterable[str]) -> None:
        self.node = node
        self.what = what
        self.problems = problems
        self.values: dict[str, Node] = node.value if isinstance(node.value, dict) else {}
        allowed = tuple(allowed)
        for key in self.values:
            if key not in allowed:
                hint = suggest(key, allowed) or "allowed keys: " + ", ".join(allowed)
                problems.add(node.key_span(key), f"unknown key '{key}' in {what}", hint)

    @property
    def span(self) -> SourceSpan:
        """Where the element starts."""
        return self.node.span

    def has(self, key: str) -> bool:
        """Whether the key was written (and is not null)."""
        return key in self.values and self.values[key].value is not None

    def get(self, key: str) -> Node | None:
        """The raw node of ``key``, if written."""
        return self.values.get(key)

    def span_of(self, key: str) -> SourceSpan:
        """Where ``key`` was written, or where the element starts when it was not."""
        node = self.values.get(key)
        return node.span if node is not None else self.span

    def _missing(self, key: str, hint: str) -> None:
        self.problems.add(self.span, f"{self.what} has no '{key}'", hint or f"add '{key}:'")

    def _wrong(self, key: str, node: Node, expected: str, hint: str = "") -> None:
        self.problems.add(node.span, f"'{key}' of {self.what} must be {expected}, not {kind_of(node)}", hint)

    def text(self, key: str, *, required: bool = False, default: str = "", hint: str = "") -> str:
        """A text value; numbers are accepted and turned into text."""
        node = self.values.get(key)
        if node is None or node.value is None:
            if required:
                self._missing(key, hint)
            return default
        if isinstance(node.value, bool) or not isinstance(node.value, (str, int, float)):
            self._wrong(key, node, "text", hint)
            return default
        return str(node.value)

    def name(self, key: str = "name") -> str:
        """A required name: non-empty text without surrounding blanks."""
        value = self.text(key, required=True, hint=f"give {self.what} a '{key}'")
        node = self.values.get(key)
        if node is not None and isinstance(node.value, str) and value != value.strip():
            self.problems.add(node.span, f"name '{value}' has blanks at its ends", "remove them")
        if node is not None and isinstance(node.value, str) and not value.strip():
            self.problems.add(node.span, f"{self.what} has an empty '{key}'", "write a name")
        return value.strip()

    def number(self, key: str, default: float, *, low: float | None = None, high: float | None = None) -> float:
        """A number, optionally within [low, high]."""
        node = self.values.get(key)
        if node is None or node.value is None:
            return default
        value = to_number(node.value)
        if value is None or math.isnan(value):
            self._wrong(key, node, "a number")
            return default
        if math.isinf(value) and (low is not None or high is not None):
            self.problems.add(node.span, f"'{key}' of {self.what} is too large", "use a finite value")
            return default
        if (low is not None and value < low) or (high is not None and value > high):
            bounds = f"[{low if low is not None else '-inf'}, {high if high is not None else 'inf'}]"
            self.problems.add(
                node.span, f"'{key}' of {self.what} is {value:g}, outside {bounds}", f"use a value in {bounds}"
            )
        return value

    def integer(self, key: str, default: int, *, low: int | None = 0) -> int:
        """A whole number, at least ``low``."""
        node = self.values.get(key)
        if node is None or node.value is None:
            return default
        value = to_number(node.value)
        if value is not None and not math.isfinite(value):
            self.problems.add(
                node.span, f"'{key}' of {self.what} must be a whole number, not {value:g}", "write a whole number"
            )
            return default
        if value is None or value != int(value):
            self._wrong(key, node, "a whole number")
            return default
        if low is not None and value < low:
            self.problems.add(node.span, f"'{key}' of {self.what} is {int(value)}, below {low}", f"use {low} or more")
        return int(value)

    def cardinality(self, key: str, default: float) -> float:
        """A whole number, or ``*`` (also ``n``, ``inf``) for no upper bound."""
        node = self.values.get(key)
        if node is None or node.value is None:
            return default
        if isinstance(node.value, str) and node.value.strip().lower() in _UNBOUNDED:
            return math.inf
        if isinstance(node.value, float) and node.value == math.inf:
            return math.inf
        return self.integer(key, 0)

    def flag(self, key: str, default: bool) -> bool:
        """``true`` or ``false``."""
        node = self.values.get(key)
        if node is None or node.value is None:
            return default
        if isinstance(node.value, bool):
            return node.value
        if isinstance(node.value, str) and node.value.strip().lower() in _TRUE | _FALSE:
            return node.value.strip().lower() in _TRUE
        self._wrong(key, node, "true or false")
        return default

    def items(self, key: str, *, required: bool = False, hint: str = "") -> list[Node]:
        """The entries of a list (a single value counts as a list of one)."""
        node = self.values.get(key)
        if node is None or node.value is None:
            if required:
                self._missing(key, hint)
            return []
        if isinstance(node.value, list):
            return node.value
        if isinstance(node.value, dict):
            self._wrong(key, node, "a list", hint or f"write '{key}' as a list: one '- ' entry per element")
            return []
        return [node]

    def mapping(self, key: str) -> Node | None:
        """A nested mapping, if written."""
        node = self.values.get(key)
        if node is None or node.value is None:
            return None
        if not isinstance(node.value, dict):
            self._wrong(key, node, "a mapping")
            return None
        return node

    def names(self, key: str, *, required: bool = False, hint: str = "") -> list[tuple[str, SourceSpan]]:
        """A list of names with their places."""
        out = []
        for item in self.items(key, required=required, hint=hint):
            if isinstance(item.value, bool) or not isinstance(item.value, (str, int, float)):
                self.problems.add(
                    item.span, f"each entry of '{key}' in {self.what} must be a name, not {kind_of(item)}", hint
                )
                continue
            out.append((str(item.value).strip(), item.span))
        return out


def to_number(value: object) -> float | None:
    """``value`` as a float, accepting numeric text; ``None`` if it is not a number.

    A whole number too large for a float is an infinity of its sign (callers check
    :func:`math.isfinite`); NaN is returned as NaN.
    """
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        try:
            return float(value)
        except OverflowError:  # more than about 300 digits
            return math.inf if value > 0 else -math.inf
    if isinstance(value, float):
        return value
    if isinstance(value, str):
        try:
            return float(value.strip())
        except ValueError:
            return None
    return None
