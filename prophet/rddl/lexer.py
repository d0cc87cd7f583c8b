"""Splitting RDDL text into tokens, with their lines and columns.

Names may hold inner hyphens (``state-fluent``, ``max-nondef-actions``), a
trailing ``'`` marks a primed (next-state) fluent, ``?x`` is a parameter and
``@v`` an enum value. Comments run from ``//`` to the end of the line. The
lexer also checks that every ``(``, ``[`` and ``{`` is closed by its partner.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from alica.prophet.rddl.errors import RddlError
from alica.source import SourceSpan

NAME = "name"
"""Token kind of a name or keyword (``robotAt``, ``state-fluent``, ``sum_``)."""
PRIMED = "primed"
"""Token kind of a primed name (``robotAt'``); the text excludes the ``'``."""
VAR = "var"
"""Token kind of a parameter (``?x``); the text includes the ``?``."""
ENUM = "enum"
"""Token kind of an enum value (``@low``); the text includes the ``@``."""
INT = "int"
"""Token kind of an integer literal."""
REAL = "real"
"""Token kind of a real literal (with a point or an exponent)."""
SYMBOL = "symbol"
"""Token kind of an operator or punctuation mark."""
EOF = "eof"
"""Token kind of the end of the text."""

_WORD = r"[A-Za-z_][A-Za-z0-9_]*(?:-[A-Za-z_][A-Za-z0-9_]*)*"
_TOKEN = re.compile(
    rf"(?P<space>[ \t\r\f\v]+)|(?P<newline>\n)|(?P<comment>//[^\n]*)"
    rf"|(?P<real>(?:\d+\.\d*|\.\d+)(?:[eE][+-]?\d+)?|\d+[eE][+-]?\d+)|(?P<int>\d+)"
    rf"|(?P<primed>{_WORD}')|(?P<name>{_WORD})|(?P<var>\?{_WORD})|(?P<enum>@{_WORD})"
    r"|(?P<symbol><=>|=>|==|~=|<=|>=|[<>=+\-*/^&|~()\[\]{},;:])"
)
_CLOSER = {"(": ")", "[": "]", "{": "}"}
_OPENER = {v: k for k, v in _CLOSER.items()}


@dataclass(frozen=True, slots=True)
class Token:
    """One token.

    Attributes:
        kind: one of the kind constants of this module.
        text: the token's text (without the ``'`` of a primed name).
        line: 1-based line.
        column: 1-based column.
        width: how many characters the token covers.
    """

    kind: str
    text: str
    line: int
    column: int
    width: int

    def is_symbol(self, text: str) -> bool:
        """Whether this is the operator or punctuation mark ``text``."""
        return self.kind == SYMBOL and self.text == text

    def is_name(self, text: str) -> bool:
        """Whether this is the name or keyword ``text``."""
        return self.kind == NAME and self.text == text

    def shown(self) -> str:
        """The token as a message shows it."""
        if self.kind == EOF:
            return "the end of the text"
        return f"'{self.text}'" + ("'" if self.kind == PRIMED else "")


def tokenize(text: str, file: str = "<string>") -> list[Token]:
    """The tokens of ``text``, ending with an :data:`EOF` token.

    Args:
        text: RDDL text.
        file: the file name messages show.

    Returns:
        The tokens, comments and white space left out.

    Raises:
        RddlError: a character that starts no token, or unbalanced brackets.
    """
    tokens: list[Token] = []
    line, line_start, position = 1, 0, 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        column = position - line_start + 1
        if match is None:
            raise RddlError(
                f"unexpected character {text[position]!r}",
                SourceSpan(file, line, column),
                "remove it; RDDL names start with a letter",
            )
        kind = match.lastgroup or ""
        value = match.group()
        position = match.end()
        if kind == "newline":
            line, line_start = line + 1, position
        elif kind == PRIMED:
            tokens.append(Token(PRIMED, value[:-1], line, column, len(value)))
        elif kind not in {"space", "comment"}:
            tokens.append(Token(kind, value, line, column, len(value)))
    tokens.append(Token(EOF, "", line, position - line_start + 1, 0))
    _check_brackets(tokens, file)
    return tokens


def _check_brackets(tokens: list[Token], file: str) -> None:
    open_: list[Token] = []
    for token in tokens:
        if token.kind != SYMBOL:
            continue
        if token.text in _CLOSER:
            open_.append(token)
        elif token.text in _OPENER:
            if not open_:
                raise RddlError(
                    f"'{token.text}' closes nothing",
                    SourceSpan(file, token.line, token.column),
                    f"remove it or add the '{_OPENER[token.text]}' it closes",
                )
            opener = open_.pop()
            if _CLOSER[opener.text] != token.text:
                raise RddlError(
                    f"'{token.text}' does not match the '{opener.text}' at {opener.line}:{opener.column}",
                    SourceSpan(file, token.line, token.column),
                    f"close the '{opener.text}' with '{_CLOSER[opener.text]}'",
                )
    if open_:
        opener = open_[-1]
        raise RddlError(
            f"'{opener.text}' is never closed",
            SourceSpan(file, opener.line, opener.column),
            f"add the '{_CLOSER[opener.text]}' that closes it",
        )
