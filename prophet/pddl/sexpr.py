"""A hand-written S-expression reader that keeps where each element was written.

Nodes are plain slotted classes (not frozen: they are built by the hundred
thousand and never leave the reader). They keep token numbers; :class:`Source` turns one into ``FILE:LINE:COL``
only when an error needs it, so reading stays fast.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from alica.prophet.pddl.errors import PddlError
from alica.source import SourceSpan

_TOKEN = re.compile(r"[()]|;[^\n]*|\??[^\s();?]+|\?")
"""A parenthesis, a comment, or a word; a ``?`` always starts a new word, as Fast Downward reads it
(``(aircraft?a)`` is ``aircraft`` and ``?a``)."""

SECTIONS = frozenset(
    {
        ":requirements",
        ":types",
        ":constants",
        ":predicates",
        ":functions",
        ":action",
        ":derived",
        ":durative-action",
        ":domain",
        ":objects",
        ":init",
        ":goal",
        ":metric",
        ":constraints",
    }
)
"""Keywords that open a top-level part of ``(define ...)``."""

MAX_DEPTH = 100
"""Deepest nesting of lists the reader accepts; the recursive readers after it stay far from Python's limit."""


@dataclass(slots=True)
class Source:
    """A text with its file name; maps token numbers to lines and columns.

    Nodes keep the number of their token (``offset``); the character offsets are
    found again only when a message needs a place.
    """

    text: str
    file: str
    _starts: list[int] = field(default_factory=list)
    _offsets: list[int] = field(default_factory=list)

    def tokens(self) -> list[str]:
        """The tokens (comments included), lower-cased."""
        text = self.text.lower() if self.text.isascii() else self.text
        tokens = _TOKEN.findall(text)
        if not self.text.isascii():
            tokens = [t.lower() for t in tokens]
        return tokens

    def span(self, token: int) -> SourceSpan:
        """The 1-based line and column of token number ``token`` (past the last: the end of the text)."""
        if not self._starts:
            self._starts = [0] + [m.end() for m in re.finditer("\n", self.text)]
            self._offsets = [m.start() for m in _TOKEN.finditer(self.text)]
        offset = self._offsets[token] if token < len(self._offsets) else len(self.text)
        line = bisect.bisect_right(self._starts, offset)
        return SourceSpan(self.file, line, offset - self._starts[line - 1] + 1)

    def where(self, token: int) -> str:
        """``LINE:COL`` of token number ``token``."""
        span = self.span(token)
        return f"{span.line}:{span.column}"

    def error(self, token: int, message: str, hint: str = "") -> PddlError:
        """A :class:`PddlError` at token number ``token``."""
        return PddlError(message, self.span(token), hint)


@dataclass(slots=True, eq=False)
class Symbol:
    """A word: a name, variable, keyword or number (lower-cased), and its token number."""

    text: str
    offset: int


@dataclass(slots=True, eq=False)
class SList:
    """A parenthesised list and the token number of its ``(``."""

    items: tuple[Node, ...]
    offset: int

    def head(self) -> str:
        """The first item's text if it is a symbol, else ''."""
        return self.items[0].text if self.items and isinstance(self.items[0], Symbol) else ""

    def describe(self) -> str:
        """How the list starts, for messages: ``(:action pick-up``."""
        words = []
        for item in self.items[:2]:
            if not isinstance(item, Symbol):
                break
            words.append(item.text)
            if not (item.text in SECTIONS or item.text in ("define", "domain", "problem")):
                break
        return "(" + " ".join(words) if words else "("


Node = Symbol | SList


def read_sexpr(source: Source) -> SList:
    """Read one top-level list from ``source``.

    Raises:
        PddlError: unbalanced parentheses, a section opened inside an unclosed one,
            lists nested more than :data:`MAX_DEPTH` deep, or text outside the top-level list.
    """
    tokens = source.tokens()
    stack: list[tuple[int, list[Node]]] = []
    items: list[Node] = []
    top: SList | None = None
    sections = SECTIONS
    for index, token in enumerate(tokens):
        if token == "(":
            if top is not None:
                raise source.error(
                    index, f"unexpected text after the end of '{top.describe()}' (opened at {source.where(top.offset)})"
                )
            if len(stack) >= MAX_DEPTH:
                raise source.error(
                    index,
                    f"lists are nested more than {MAX_DEPTH} deep",
                    "flatten the formula; PDDL needs a few levels",
                )
            items = []
            stack.append((index, items))
        elif token == ")":
            if not stack:
                raise source.error(index, "unexpected ')' with nothing to close")
            start, done = stack.pop()
            node = SList(tuple(done), start)
            if stack:
                items = stack[-1][1]
                items.append(node)
            else:
                top = node
        elif token[0] == ";":
            continue
        else:
            if top is not None or not stack:
                raise source.error(index, f"unexpected '{token}' outside of '(define ...)'")
            if token in sections and not items and len(stack) > 2:
                unclosed = stack[1]
                shown = SList(tuple(unclosed[1]), unclosed[0]).describe()
                raise source.error(
                    stack[-1][0],
                    f"expected ')' to close '{shown}' opened at {source.where(unclosed[0])} before '({token}'",
                )
            items.append(Symbol(token, index))
    if stack:
        start, rest = stack[-1]
        shown = SList(tuple(rest), start).describe()
        raise source.error(len(tokens), f"expected ')' to close '{shown}' opened at {source.where(start)}")
    if top is None:
        raise source.error(len(tokens), "expected '(define ...)', found an empty text")
    return top
