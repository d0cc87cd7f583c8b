"""The located tree: plan data as read from YAML or XML, every value with its place.

Both formats read into the same tree (mappings, lists, scalars), and one
builder turns a tree into model objects, so the two formats cannot drift
apart in meaning.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from alica.source import SourceSpan

Scalar = str | int | float | bool | None


@dataclass(slots=True)
class Node:
    """A value read from a plan file.

    Args:
        value: ``dict[str, Node]``, ``list[Node]`` or a scalar.
        span: where the value starts.
        key_spans: for mappings, where each key was written.
        text_offset: for string scalars, how the text maps to the file:
            ``(line, column)`` of the first character of the text itself,
            ``None`` when the mapping is not one to one (folded text).
    """

    value: dict[str, Node] | list[Node] | Scalar
    span: SourceSpan
    key_spans: dict[str, SourceSpan] = field(default_factory=dict)
    text_offset: tuple[int, int] | None = None

    @property
    def is_mapping(self) -> bool:
        """Whether the value is a mapping."""
        return isinstance(self.value, dict)

    @property
    def is_list(self) -> bool:
        """Whether the value is a list."""
        return isinstance(self.value, list)

    def key_span(self, key: str) -> SourceSpan:
        """Where ``key`` was written in this mapping (the mapping's span if unknown)."""
        return self.key_spans.get(key, self.span)

    def text_span(self, column: int) -> SourceSpan:
        """The file position of 1-based ``column`` in this scalar's text."""
        if self.text_offset is None or not isinstance(self.value, str):
            return self.span
        line, col = self.text_offset
        before = self.value[: max(column - 1, 0)]
        newlines = before.count("\n")
        if newlines:
            return SourceSpan(self.span.file, line + newlines, len(before) - before.rfind("\n"))
        return SourceSpan(self.span.file, line, col + column - 1)

    def plain(self) -> object:
        """The value without locations: dicts, lists and scalars."""
        if isinstance(self.value, dict):
            return {k: v.plain() for k, v in self.value.items()}
        if isinstance(self.value, list):
            return [v.plain() for v in self.value]
        return self.value


def from_plain(value: object, span: SourceSpan) -> Node:
    """A tree for plain data, every node at ``span`` (for data built in code)."""
    if isinstance(value, dict):
        return Node({str(k): from_plain(v, span) for k, v in value.items()}, span)
    if isinstance(value, (list, tuple)):
        return Node([from_plain(v, span) for v in value], span)
    return Node(value, span)  # type: ignore[arg-type]
