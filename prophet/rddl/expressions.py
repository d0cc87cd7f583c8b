"""Reading RDDL expressions: a token cursor and recursive descent by precedence.

From the loosest to the tightest binding: ``<=>``, ``=>``, ``|``, ``^`` and
``&``, ``~``, comparisons, ``+ -``, ``* /``, unary minus. All binary operators
group to the left. The body of ``sum_{...}``, ``prod_{...}``, ``forall_{...}``
and ``exists_{...}`` and the ``else`` branch of ``if`` reach as far right as
they can, as in pyRDDLGym.
"""

from __future__ import annotations

from difflib import get_close_matches

from alica.prophet.rddl.ast import (
    Aggregate,
    Apply,
    Binary,
    BoolConst,
    Constant,
    Distribution,
    EnumValue,
    Expr,
    If,
    IntConst,
    Name,
    Neg,
    Not,
    Param,
    RealConst,
    TypedParam,
)
from alica.prophet.rddl.errors import RddlError
from alica.prophet.rddl.lexer import ENUM, EOF, INT, NAME, PRIMED, REAL, SYMBOL, VAR, Token
from alica.source import SourceSpan

AGGREGATES = ("sum", "prod", "forall", "exists")
"""The words written before ``_{`` of a quantifier or aggregation."""
DISTRIBUTIONS = frozenset(
    {"Bernoulli", "KronDelta", "DiracDelta", "Normal", "Uniform", "Poisson", "Exponential", "Gamma", "Weibull"}
)
"""The distributions the reader knows (written like a function: ``Normal(m, v)``)."""
KEYWORDS = (
    frozenset(
        "domain instance horizon discount objects init-state requirements state-action-constraints action-preconditions"
        " termination state-invariants types object bool int real neg-inf pos-inf pvariables non-fluent non-fluents"
        " state-fluent interm-fluent derived-fluent observ-fluent action-fluent param-fluent level default"
        " max-nondef-actions terminate-when terminal cpfs cdfs policy reward forall exists argmax argmin sum prod"
        " true false if then else switch case otherwise Discrete UnnormDiscrete Binomial NegativeBinomial Beta Geometric"
        " Pareto Student Gumbel Laplace Cauchy Gompertz ChiSquare Kumaraswamy MultivariateNormal MultivariateStudent"
        " Dirichlet Multinomial det inverse pinverse cholesky row col enum constraints".split()
    )
    | DISTRIBUTIONS
)
"""RDDL's reserved words (pyRDDLGym's list): no domain, block, type, object or pvariable may take one as its name."""

_LEVELS: tuple[tuple[str, ...], ...] = (
    ("<=>",),
    ("=>",),
    ("|",),
    ("^", "&"),
    (),  # prefix ~
    ("==", "~=", "<", "<=", ">", ">="),
    ("+", "-"),
    ("*", "/"),
)
OPERATORS = {op: level for level, ops in enumerate(_LEVELS) for op in ops}
"""Binary operator -> binding level (0 binds loosest); the parser and the writer share it."""
NOT_LEVEL = 4
"""``~`` binds tighter than ``^`` and looser than the comparisons."""


def suggestion(word: str, options: list[str] | tuple[str, ...] | frozenset[str]) -> str:
    """A ``did you mean`` hint for ``word`` among ``options`` (empty when nothing is close)."""
    close = get_close_matches(word, sorted(options), n=1, cutoff=0.5)
    return f"did you mean '{close[0]}'?" if close else ""


class Cursor:
    """A position in a token list, with the helpers every reader needs."""

    def __init__(self, tokens: list[Token], file: str) -> None:
        self.tokens = tokens
        self.file = file
        self.index = 0

    def peek(self, ahead: int = 0) -> Token:
        """The token ``ahead`` places after the current one (the end token past the end)."""
        return self.tokens[min(self.index + ahead, len(self.tokens) - 1)]

    def advance(self) -> Token:
        """The current token; moves past it."""
        token = self.peek()
        if token.kind != EOF:
            self.index += 1
        return token

    def span(self, token: Token) -> SourceSpan:
        """The place of ``token``."""
        return SourceSpan(self.file, token.line, token.column)

    def error(self, token: Token, message: str, hint: str = "") -> RddlError:
        """An :class:`RddlError` at ``token``."""
        return RddlError(message, self.span(token), hint)

    def too_deep(self) -> RddlError:
        """The error for an expression nested deeper than Python's recursion limit allows to read."""
        return self.error(self.peek(), "the expression is nested too deeply to read", "split it, or bracket less")

    def accept(self, text: str) -> Token | None:
        """The current token if it is the symbol ``text`` (moving past it), else None."""
        if self.peek().is_symbol(text):
            return self.advance()
        return None

    def expect(self, text: str, what: str = "") -> Token:
        """The symbol ``text``, or an error that names what was found instead."""
        token = self.peek()
        if token.is_symbol(text):
            return self.advance()
        if text == ";" and self.index > 0:
            before = self.tokens[self.index - 1]
            place = SourceSpan(self.file, before.line, before.column + before.width)
            raise RddlError(f"missing ';' after {what or before.shown()}, found {token.shown()}", place, "add ';'")
        raise self.error(token, f"expected '{text}'{' ' + what if what else ''}, found {token.shown()}")

    def name(self, what: str) -> Token:
        """A name token (``what`` says what it names, for the message)."""
        token = self.peek()
        if token.kind != NAME:
            raise self.error(token, f"expected {what}, found {token.shown()}")
        return self.advance()

    def new_name(self, what: str) -> Token:
        """A name that a declaration introduces: no reserved word."""
        token = self.name(what)
        if token.text in KEYWORDS:
            raise self.error(token, f"'{token.text}' is an RDDL keyword and cannot name {what}", "choose another name")
        return token

    def expr(self) -> Expr:
        """An expression."""
        return self._binary(0)

    def _binary(self, lowest: int) -> Expr:
        """Precedence climbing: an operand, then operators of level ``lowest`` or tighter (one frame per nesting)."""
        token = self.peek()
        if lowest <= NOT_LEVEL and token.is_symbol("~"):
            self.advance()
            left: Expr = Not(self._binary(NOT_LEVEL), line=token.line, column=token.column)
        else:
            left = self.unary()
        while True:
            token = self.peek()
            level = OPERATORS.get(token.text, -1) if token.kind == SYMBOL else -1
            if level < lowest:
                return left
            self.advance()
            left = _binary(token, left, self._binary(level + 1))

    def unary(self) -> Expr:
        """A unary minus or ``~`` applied to a unary expression, or a primary expression."""
        token = self.peek()
        if token.is_symbol("-"):
            self.advance()
            number = self.peek()
            if number.kind in {INT, REAL}:
                self.advance()
                return _number(number, negative=True, line=token.line, column=token.column)
            return Neg(self.unary(), line=token.line, column=token.column)
        if token.is_symbol("~"):
            self.advance()
            return Not(self.unary(), line=token.line, column=token.column)
        return self.primary()

    def primary(self) -> Expr:
        """A constant, parameter, pvariable, bracketed expression, ``if``, aggregation or distribution."""
        token = self.advance()
        if token.is_symbol("(") or token.is_symbol("["):
            inner = self.expr()
            self.expect(
                ")" if token.text == "(" else "]", f"to close the '{token.text}' at {token.line}:{token.column}"
            )
            return inner
        if token.kind in {INT, REAL}:
            return _number(token, negative=False, line=token.line, column=token.column)
        if token.kind == ENUM:
            return EnumValue(token.text, line=token.line, column=token.column)
        if token.kind == VAR:
            return Param(token.text, line=token.line, column=token.column)
        if token.kind == PRIMED:
            return Apply(
                token.text,
                self.args() if self.peek().is_symbol("(") else (),
                True,
                line=token.line,
                column=token.column,
            )
        if token.kind != NAME:
            raise self.error(token, f"expected an expression, found {token.shown()}")
        if token.text in {"true", "false"}:
            return BoolConst(token.text == "true", line=token.line, column=token.column)
        if token.text == "if":
            self.expect("(", "after 'if'")
            cond = self.expr()
            self.expect(")", "after the condition of 'if'")
            self._keyword("then")
            then = self.expr()
            self._keyword("else")
            return If(cond, then, self.expr(), line=token.line, column=token.column)
        word = token.text[:-1]
        if token.text.endswith("_") and word in AGGREGATES and self.peek().is_symbol("{"):
            return Aggregate(word, self.typed_params(), self.expr(), line=token.line, column=token.column)
        if token.text in DISTRIBUTIONS and self.peek().is_symbol("("):
            return Distribution(token.text, self.args(), line=token.line, column=token.column)
        if token.text in KEYWORDS:
            raise self.error(token, f"expected an expression, found the keyword '{token.text}'")
        return Apply(
            token.text, self.args() if self.peek().is_symbol("(") else (), line=token.line, column=token.column
        )

    def args(self) -> tuple[Expr, ...]:
        """``(e1, e2, ...)``."""
        self.expect("(")
        if self.accept(")"):
            return ()
        items = [self.expr()]
        while self.accept(","):
            items.append(self.expr())
        self.expect(")", "to close the arguments")
        return tuple(items)

    def typed_params(self) -> tuple[TypedParam, ...]:
        """``{?x : t, ?y : u}``."""
        self.expect("{")
        params: list[TypedParam] = []
        while True:
            var = self.advance()
            if var.kind != VAR:
                raise self.error(var, f"expected a parameter '?name', found {var.shown()}")
            self.expect(":", f"after '{var.text}'")
            type_ = self.name("a type")
            params.append(
                TypedParam(
                    var.text, Name(type_.text, line=type_.line, column=type_.column), line=var.line, column=var.column
                )
            )
            if not self.accept(","):
                break
        self.expect("}", "to close the parameter list")
        return tuple(params)

    def constant(self) -> Constant:
        """A value: a number (maybe negative), ``true``, ``false``, an enum value or an object name."""
        token = self.peek()
        if token.is_symbol("-") and self.peek(1).kind in {INT, REAL}:
            self.advance()
            return _number(self.advance(), negative=True, line=token.line, column=token.column)
        self.advance()
        if token.kind in {INT, REAL}:
            return _number(token, negative=False, line=token.line, column=token.column)
        if token.kind == ENUM:
            return EnumValue(token.text, line=token.line, column=token.column)
        if token.kind == NAME and token.text in {"true", "false"}:
            return BoolConst(token.text == "true", line=token.line, column=token.column)
        if token.kind == NAME and token.text not in KEYWORDS:
            return Apply(token.text, line=token.line, column=token.column)
        raise self.error(token, f"expected a value (a number, true, false, @value or an object), found {token.shown()}")

    def _keyword(self, word: str) -> None:
        token = self.advance()
        if not token.is_name(word):
            raise self.error(token, f"expected '{word}', found {token.shown()}")


def _number(token: Token, *, negative: bool, line: int, column: int) -> IntConst | RealConst:
    if token.kind == INT:
        value = int(token.text)
        return IntConst(-value if negative else value, line=line, column=column)
    real = float(token.text)
    return RealConst(-real if negative else real, line=line, column=column)


def _binary(token: Token, left: Expr, right: Expr) -> Expr:
    return Binary(token.text, left, right, line=token.line, column=token.column)
