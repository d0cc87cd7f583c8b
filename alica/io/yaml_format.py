"""YAML plan files: read into a located tree, write plain data back as YAML.

PyYAML's composer keeps a mark (line, column) on every node; we keep them on
the tree so every later error can name its place. Duplicate keys, which
PyYAML would silently overwrite, are reported, alias expansion is capped, and
so is nesting (a deeper file is reported at the first value past the limit,
not with a Python traceback). Scalars PyYAML cannot construct (``!!int x``,
a number with more digits than Python reads, a month 13) are reported at
their place.
"""

from __future__ import annotations

import datetime
import math
from typing import Any

import yaml

from alica.io.tree import Node
from alica.source import Diagnostic, SourceSpan

#: Largest number of values aliases may expand to in one file (guards against alias bombs).
#: Only values reached again through an alias (``*name`` or ``<<: *name``) count; a big
#: file without aliases is never refused by it.
MAX_ALIAS_VALUES = 200_000

#: Deepest nesting of mappings and lists a plan file may have (plans need about ten).
MAX_DEPTH = 100

_TAG_NAMES = {
    "tag:yaml.org,2002:int": "a whole number",
    "tag:yaml.org,2002:float": "a number",
    "tag:yaml.org,2002:bool": "true or false",
    "tag:yaml.org,2002:null": "null",
    "tag:yaml.org,2002:timestamp": "a date",
    "tag:yaml.org,2002:binary": "base64 data",
}

_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


#: Integers of more bits than this (about 3900 decimal digits) are refused: Python writes at most 4300 digits.
_MAX_INT_BITS = 13_000


def _shown(text: str) -> str:
    """``text``, cut to 30 characters for a message."""
    return text if len(text) <= 30 else text[:27] + "..."


class _TooLarge(Exception):
    pass


class _TooDeep(Exception):
    def __init__(self, span: SourceSpan) -> None:
        super().__init__(str(span))
        self.span = span


class _Reader:
    def __init__(self, text: str, path: str) -> None:
        self.path = path
        self.lines = text.splitlines()
        self.constructor = yaml.SafeLoader("")
        self.expanded = 0
        self.seen: set[int] = set()
        self.diagnostics: list[Diagnostic] = []

    def span(self, mark: Any) -> SourceSpan:
        return SourceSpan(self.path, mark.line + 1, mark.column + 1)

    def convert(self, node: yaml.Node, depth: int = 0, aliased: bool = False) -> Node:
        """The located tree of ``node``; ``aliased`` when reached again through an alias."""
        # PyYAML hands out the same node object for every alias of an anchor: a node
        # seen before (or inside one) is an alias expansion, and only those count.
        if aliased or id(node) in self.seen:
            aliased = True
            self.expanded += 1
            if self.expanded > MAX_ALIAS_VALUES:
                raise _TooLarge
        else:
            self.seen.add(id(node))
        span = self.span(node.start_mark)
        if isinstance(node, (yaml.MappingNode, yaml.SequenceNode)) and depth >= MAX_DEPTH:
            raise _TooDeep(span)
        if isinstance(node, yaml.MappingNode):
            return self._mapping(node, span, depth, aliased)
        if isinstance(node, yaml.SequenceNode):
            return Node([self.convert(item, depth + 1, aliased) for item in node.value], span)
        if not isinstance(node, yaml.ScalarNode):  # PyYAML composes only scalar, sequence and mapping nodes
            raise TypeError(f"unexpected YAML node {type(node).__name__}")
        try:
            value = self.constructor.construct_object(node, deep=True)
        except (ValueError, OverflowError, TypeError, yaml.YAMLError) as exc:
            self.diagnostics.append(self._unreadable(node, span, exc))
            return Node(None, span)
        if type(value) is int and value.bit_length() > _MAX_INT_BITS:
            # a hexadecimal, octal or sexagesimal integer of few characters but more decimal digits
            # than Python writes as text (str() refuses over 4300): refuse it here, where it was written
            digits = int(value.bit_length() * math.log10(2)) + 1
            self.diagnostics.append(
                Diagnostic(
                    span,
                    f"cannot read '{_shown(str(node.value))}' as an integer: it has about {digits} digits",
                    "write a smaller number",
                )
            )
            return Node(None, span)
        if isinstance(value, (datetime.date, datetime.datetime)):
            value = str(node.value)
        elif isinstance(value, bytes):
            value = node.value
        if isinstance(value, str):
            return Node(value, span, text_offset=self._text_offset(node))
        return Node(value, span)

    def _unreadable(self, node: yaml.ScalarNode, span: SourceSpan, exc: Exception) -> Diagnostic:
        """The problem of a scalar PyYAML cannot construct (``!!int x``, 5000 digits, month 13)."""
        text = str(node.value)
        shown = _shown(text)
        kind = _TAG_NAMES.get(node.tag, f"'{node.tag}'")
        digits = sum(c.isdigit() for c in text)
        if node.tag == "tag:yaml.org,2002:int" and digits > 4000:
            reason = f"it has {digits} digits"
            hint = "write a smaller number"
        else:
            marked = exc if isinstance(exc, yaml.MarkedYAMLError) else None
            reason = " ".join(str((marked.problem if marked else None) or exc).split())[:80]
            hint = "write a valid value, or quote it to keep it as text"
        return Diagnostic(span, f"cannot read '{shown}' as {kind}: {reason}", hint)

    def _mapping(self, node: yaml.MappingNode, span: SourceSpan, depth: int, aliased: bool) -> Node:
        items: dict[str, Node] = {}
        key_spans: dict[str, SourceSpan] = {}
        explicit: set[str] = set()
        merged: list[tuple[yaml.Node, yaml.Node]] = []
        own: list[tuple[yaml.Node, yaml.Node]] = []
        for key_node, value_node in node.value:
            if key_node.tag != "tag:yaml.org,2002:merge":
                own.append((key_node, value_node))
                continue
            sources = value_node.value if isinstance(value_node, yaml.SequenceNode) else [value_node]
            merged.extend(pair for source in sources if isinstance(source, yaml.MappingNode) for pair in source.value)
        for from_merge, pairs in ((True, merged), (False, own)):
            for key_node, value_node in pairs:
                key_span = self.span(key_node.start_mark)
                if not isinstance(key_node, yaml.ScalarNode):
                    self.diagnostics.append(
                        Diagnostic(key_span, "a mapping key must be a plain name", "write the key as text")
                    )
                    continue
                key = str(key_node.value)
                if not from_merge and key in explicit:
                    self.diagnostics.append(
                        Diagnostic(
                            key_span,
                            f"duplicate key '{key}' (first written at line {key_spans[key].line})",
                            "remove one of them; YAML would silently keep only the last",
                        )
                    )
                    continue
                if not from_merge:
                    explicit.add(key)
                items[key] = self.convert(value_node, depth + 1, aliased)
                key_spans[key] = key_span
        return Node(items, span, key_spans)

    def _text_offset(self, node: yaml.ScalarNode) -> tuple[int, int] | None:
        line, column = node.start_mark.line + 1, node.start_mark.column + 1
        if node.style is None:
            return (line, column)
        if node.style in ("'", '"'):
            return (line, column + 1)
        if node.style == "|" and line < len(self.lines):
            body = self.lines[line]
            return (line + 1, len(body) - len(body.lstrip()) + 1)
        return None


def read_yaml(text: str, path: str) -> tuple[Node | None, list[Diagnostic]]:
    """Parse one YAML document into a located tree.

    Args:
        text: the file's contents.
        path: the name used in diagnostics.

    Returns:
        The tree (``None`` if the file could not be parsed) and the problems found.
    """
    reader = _Reader(text, path)
    try:
        documents = list(yaml.compose_all(text, Loader=_Loader))
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        span = reader.span(mark) if mark else SourceSpan(path, 1, 1)
        problem = exc.problem or "malformed YAML"
        context = f" {exc.context}" if exc.context else ""
        return None, [Diagnostic(span, f"YAML syntax: {problem}{context}", "fix the YAML syntax at this place")]
    except yaml.YAMLError as exc:
        return None, [Diagnostic(SourceSpan(path, 1, 1), f"YAML syntax: {exc}", "fix the YAML syntax")]
    documents = [d for d in documents if d is not None]
    if not documents:
        return None, [
            Diagnostic(
                SourceSpan(path, 1, 1), "the file holds no plan data", "add sections such as 'plans:' or 'tasks:'"
            )
        ]
    if len(documents) > 1:
        span = reader.span(documents[1].start_mark)
        return None, [
            Diagnostic(span, "more than one YAML document in a plan file", "put each document in its own file")
        ]
    try:
        tree = reader.convert(documents[0])
    except _TooLarge:
        return None, [
            Diagnostic(
                SourceSpan(path, 1, 1),
                f"the file expands to more than {MAX_ALIAS_VALUES} values through aliases (anchors and aliases nested too deep)",
                "write the data out instead of nesting aliases",
            )
        ]
    except _TooDeep as exc:
        return None, [
            Diagnostic(
                exc.span,
                f"mappings and lists are nested more than {MAX_DEPTH} deep",
                "flatten the data; plans need only a few levels",
            )
        ]
    except yaml.YAMLError as exc:
        marked = exc if isinstance(exc, yaml.MarkedYAMLError) else None
        span = reader.span(marked.problem_mark) if marked and marked.problem_mark else SourceSpan(path, 1, 1)
        reason = marked.problem if marked and marked.problem is not None else exc
        return None, [Diagnostic(span, f"YAML value: {reason}", "fix the value")]
    return tree, reader.diagnostics


class _Dumper(yaml.SafeDumper):
    """Indents list entries under their key, as people write YAML."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        super().increase_indent(flow, False)


#: Characters YAML reads as line breaks but PyYAML would write unescaped outside double quotes.
_UNICODE_BREAKS = ("\x85", "\u2028", "\u2029")


def _represent_str(dumper: yaml.SafeDumper, value: str) -> yaml.ScalarNode:
    if any(c in value for c in _UNICODE_BREAKS):  # written raw they would read back as '\n'
        return dumper.represent_scalar("tag:yaml.org,2002:str", value, style='"')
    if "\n" in value:
        return dumper.represent_scalar("tag:yaml.org,2002:str", value, style="|")
    return dumper.represent_scalar("tag:yaml.org,2002:str", value)


def _represent_list(dumper: yaml.SafeDumper, value: list[Any]) -> yaml.SequenceNode:
    flow = bool(value) and all(isinstance(v, (str, int, float, bool)) and len(str(v)) < 40 for v in value)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", value, flow_style=flow)


_Dumper.add_representer(str, _represent_str)
_Dumper.add_representer(list, _represent_list)


def write_yaml(data: object) -> str:
    """Plain data (dicts, lists, scalars) as a YAML document, keys in the given order."""
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100, indent=2)
