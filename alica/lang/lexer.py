"""Tokenizer for formulas: one compiled regular expression.

Token kinds are normalised: operators and keywords use their canonical
spelling as kind (``&&`` and ``and`` both give kind ``'and'``, ``=`` gives
``'=='``, ``**`` gives ``'^'``, ``implies`` gives ``'->'``); literals and names
use ``'NUM'``, ``'STR'`` and ``'IDENT'``; the end of text is ``'EOF'``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from alica.errors import FormulaError
from alica.lang.ast import KEYWORDS

_TOKEN_RE = re.compile(
    r"""
    (?P<ws>\s+)
  | (?P<num>[0-9]+(?:\.[0-9]+)?(?:[eE][+-]?[0-9]+)?)
  | (?P<ident>\??[A-Za-z_][A-Za-z0-9_]*)
  | (?P<str>"(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')
  | (?P<op><->|->|<=|>=|==|!=|&&|\|\||\*\*|[-+*/%^()<>=!,.:])
    """,
    re.VERBOSE | re.DOTALL,
)

_SYNONYMS: dict[str, str] = {
    "&&": "and",
    "||": "or",
    "!": "not",
    "=": "==",
    "**": "^",
    "implies": "->",
    "iff": "<->",
}

_ESCAPES: dict[str, str] = {
    "\\": "\\",
    '"': '"',
    "'": "'",
    "n": "\n",
    "t": "\t",
    "r": "\r",
}

_IDENT_CHAR = re.compile(r"[A-Za-z0-9_]")


@dataclass(frozen=True, slots=True)
class Token:
    """One token.

    Attributes:
        kind: normalised kind (see module docstring).
        text: the token as written.
        column: 1-based column of its first character.
        value: the literal value for ``NUM`` and ``STR``, the name for
            ``IDENT``, else ``None``.
    """

    kind: str
    text: str
    column: int
    value: object = None

    def describe(self) -> str:
        """How to name this token in an error message."""
        if self.kind == "EOF":
            return "end of formula"
        if self.kind == "STR":
            return f"string {self.text}"
        return f"'{self.text}'"


def _unescape(body: str, column: int, text: str) -> str:
    """Resolve backslash escapes in a string literal's body."""
    if "\\" not in body:
        return body
    out: list[str] = []
    i = 0
    while i < len(body):
        char = body[i]
        if char == "\\":
            code = body[i + 1]
            if code not in _ESCAPES:
                raise FormulaError(
                    f"unknown escape '\\{code}' in string",
                    column + 1 + i,
                    text,
                    "use \\\\, \\\", \\', \\n, \\t or \\r",
                )
            out.append(_ESCAPES[code])
            i += 2
        else:
            out.append(char)
            i += 1
    return "".join(out)


def _number(lexeme: str, column: int, text: str) -> int | float:
    """Convert a numeric lexeme, rejecting values Python cannot represent."""
    try:
        value: int | float
        if "." in lexeme or "e" in lexeme or "E" in lexeme:
            value = float(lexeme)
            if not math.isfinite(value):
                raise ValueError(lexeme)
        else:
            value = int(lexeme)
    except ValueError:
        raise FormulaError(f"number '{lexeme[:20]}' is out of range", column, text, "use a smaller number") from None
    return value


def tokenize(text: str) -> list[Token]:
    """Split formula text into tokens, ending with an ``EOF`` token.

    Args:
        text: the formula.

    Returns:
        The tokens; the ``EOF`` token's column is one past the last
        non-blank character.

    Raises:
        FormulaError: on a character that starts no token, an unterminated
            string, a bad escape or a malformed number.
    """
    tokens: list[Token] = []
    pos = 0
    end = len(text)
    match = _TOKEN_RE.match
    while pos < end:
        m = match(text, pos)
        column = pos + 1
        if m is None:
            char = text[pos]
            if char in "\"'":
                raise FormulaError("unterminated string", column, text, f"close the string with {char}")
            if char == "?":
                raise FormulaError(
                    "unknown character '?'",
                    column,
                    text,
                    "'?' may only start a variable name such as ?x",
                )
            raise FormulaError(
                f"unknown character {char!r}",
                column,
                text,
                "formulas use names, numbers, quoted strings, parentheses and operators such as and, or, not, ->, <, +",
            )
        kind = m.lastgroup
        lexeme = m.group()
        pos = m.end()
        if kind == "ws":
            continue
        if kind == "num":
            if pos < end and _IDENT_CHAR.match(text, pos):
                raise FormulaError(
                    f"malformed number '{lexeme}{text[pos]}'",
                    column,
                    text,
                    "separate a number from a following name with an operator",
                )
            tokens.append(Token("NUM", lexeme, column, _number(lexeme, column, text)))
        elif kind == "ident":
            if lexeme in KEYWORDS:
                tokens.append(Token(_SYNONYMS.get(lexeme, lexeme), lexeme, column))
            else:
                tokens.append(Token("IDENT", lexeme, column, lexeme))
        elif kind == "str":
            tokens.append(Token("STR", lexeme, column, _unescape(lexeme[1:-1], column, text)))
        else:
            tokens.append(Token(_SYNONYMS.get(lexeme, lexeme), lexeme, column))
    tokens.append(Token("EOF", "", len(text.rstrip()) + 1))
    return tokens
