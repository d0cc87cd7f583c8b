"""Recursive-descent parser for formulas.

Grammar, lowest precedence first::

    formula    := implies (('<->' | 'iff') implies)*          left-assoc
    implies    := or (('->' | 'implies') implies)?              right-assoc
    or         := and (('or' | '||') and)*
    and        := not (('and' | '&&') not)*
    not        := ('not' | '!') not | quantified | comparison
    quantified := ('forall' | 'exists') binder (',' binder)* ':' formula
    binder     := IDENT (',' IDENT)* 'in' domain
    domain     := IDENT | 'agents' '(' IDENT ')'          the agents of an entry point, task or state
    comparison := sum (('<' | '<=' | '>' | '>=' | '==' | '=' | '!=') sum)?
    sum        := product (('+' | '-') product)*
    product    := unary (('*' | '/' | '%') unary)*
    unary      := '-' unary | power
    power      := postfix (('^' | '**') unary)?                 right-assoc
    postfix    := atom ('.' IDENT)*
    atom       := NUM | STR | 'true' | 'false' | IDENT | IDENT '(' args ')'
                | aggregate | '(' formula ')'
    aggregate  := 'sum' binder (',' binder)* ':' sum          the sum of the term over the domains
    args       := (formula (',' formula)*)?

A quantifier's body extends as far right as possible; an aggregate's body is
an arithmetic term (``sum a in agents(Explore): gain(frontier(a)) > 3``
compares the sum with 3). ``sum`` is a keyword only where an aggregate can
start (``sum NAME in`` or ``sum NAME,``), so predicates and functions named
``sum`` keep working. The domain ``agents(Explore)`` is kept as the type name
``'agents(Explore)'``: the belief base lists its objects, the agents of entry
point, task or state ``Explore`` of the plan the formula belongs to.

Chains of operators (``a + b + ...``, ``a.b.c``, ``a -> b -> ...``,
``not not a``, ``- - x``, ``a ^ b ^ ...``) are read by loops, so their length
is not limited by Python's stack. Real nesting (parentheses, call arguments
and quantifier bodies) is recursive and capped at :data:`MAX_DEPTH` levels,
with an error at the opening that goes too deep; every later walk over a tree
either loops or recurses only through that nesting.
"""

from __future__ import annotations

from functools import lru_cache

from alica.errors import FormulaError
from alica.lang.ast import (
    AGENTS,
    KEYWORDS,
    And,
    Attr,
    Binary,
    Bool,
    Call,
    Compare,
    Iff,
    Implies,
    Name,
    Node,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
)
from alica.lang.lexer import Token, tokenize

#: How deeply parentheses, call arguments and quantifier bodies may nest.
MAX_DEPTH = 20

_COMPARE = frozenset({"<", "<=", ">", ">=", "==", "!="})
_TERM_HINT = "a term is a name, a number, a quoted string, a call like f(x) or a formula in parentheses"


class _Parser:
    """Parser state over one token list."""

    __slots__ = ("depth", "pos", "text", "tokens")

    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens = tokenize(text)
        self.pos = 0
        self.depth = 0

    # -- token helpers -------------------------------------------------

    @property
    def tok(self) -> Token:
        return self.tokens[self.pos]

    def advance(self) -> Token:
        token = self.tokens[self.pos]
        if token.kind != "EOF":
            self.pos += 1
        return token

    def error(self, message: str, token: Token, hint: str = "") -> FormulaError:
        return FormulaError(message, token.column, self.text, hint)

    def after(self) -> str:
        """`` after 'X'`` naming the previous token, or an empty string."""
        if self.pos == 0:
            return ""
        return f" after '{self.tokens[self.pos - 1].text}'"

    def enter(self, opening: Token) -> None:
        """One level deeper at ``opening`` (a '(' or a quantifier)."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(
                f"formula nested deeper than {MAX_DEPTH} levels; simplify it",
                opening,
                "split the formula or remove redundant parentheses",
            )

    def leave(self) -> None:
        self.depth -= 1

    def expect_ident(self, what: str) -> Token:
        token = self.tok
        if token.kind == "IDENT":
            return self.advance()
        found = "end of formula" if token.kind == "EOF" else f"'{token.text}'"
        extra = " (a keyword)" if token.text in KEYWORDS else ""
        raise self.error(f"expected {what}{self.after()}, found {found}{extra}", token)

    # -- grammar -------------------------------------------------------

    def parse(self) -> Node:
        if self.tok.kind == "EOF":
            raise self.error("empty formula", self.tok, "write a condition such as On(a, b)")
        node = self.formula()
        token = self.tok
        if token.kind != "EOF":
            if token.kind == ")":
                raise self.error("unmatched ')'", token, "remove it or add a matching '('")
            raise self.error(
                f"unexpected {token.describe()} after a complete formula",
                token,
                "join conditions with 'and' or 'or', or add the missing operator",
            )
        return node

    def formula(self) -> Node:
        start = self.tok.column
        left = self.implies()
        while self.tok.kind == "<->":
            self.advance()
            left = Iff(left, self.implies(), start)
        return left

    def implies(self) -> Node:
        starts = [self.tok.column]
        items = [self.disjunction()]
        while self.tok.kind == "->":
            self.advance()
            starts.append(self.tok.column)
            items.append(self.disjunction())
        node = items.pop()
        starts.pop()
        while items:
            node = Implies(items.pop(), node, starts.pop())
        return node

    def disjunction(self) -> Node:
        start = self.tok.column
        first = self.conjunction()
        if self.tok.kind != "or":
            return first
        items = [first]
        while self.tok.kind == "or":
            self.advance()
            items.append(self.conjunction())
        return Or(tuple(items), start)

    def conjunction(self) -> Node:
        start = self.tok.column
        first = self.negation()
        if self.tok.kind != "and":
            return first
        items = [first]
        while self.tok.kind == "and":
            self.advance()
            items.append(self.negation())
        return And(tuple(items), start)

    def negation(self) -> Node:
        nots: list[Token] = []
        while self.tok.kind == "not":
            nots.append(self.advance())
        node = self.quantified() if self.tok.kind in ("forall", "exists") else self.comparison()
        while nots:
            node = Not(node, nots.pop().column)
        return node

    def quantified(self) -> Node:
        head = self.advance()
        binders = self.binders(head.text)
        self.enter(head)
        body = self.formula()
        self.leave()
        return Quantified(head.kind, binders, body, head.column)

    def aggregate(self) -> Node:
        head = self.advance()
        binders = self.binders(head.text)
        self.enter(head)
        body = self.sum()
        self.leave()
        return Quantified("sum", binders, body, head.column)

    def binders(self, head: str) -> tuple[tuple[str, str], ...]:
        """``x, y in Type, z in agents(Entry) :`` up to and including the colon."""
        binders: list[tuple[str, str]] = []
        while True:
            names = [self.expect_ident("a variable name")]
            while self.tok.kind == ",":
                self.advance()
                names.append(self.expect_ident("a variable name"))
            if self.tok.kind != "in":
                raise self.error(
                    f"expected 'in'{self.after()}, found {self.tok.describe()}",
                    self.tok,
                    f"write {head} x in Type: ...",
                )
            self.advance()
            domain = self.expect_ident("a type name")
            type_name = domain.text
            if type_name == AGENTS and self.tok.kind == "(":
                opening = self.advance()
                which = self.expect_ident("an entry point, task or state")
                self.close(opening, "write agents(EntryPoint)")
                type_name = f"{AGENTS}({which.text})"
            binders.extend((name.text, type_name) for name in names)
            if self.tok.kind == ",":
                self.advance()
                continue
            if self.tok.kind == ":":
                self.advance()
                return tuple(binders)
            raise self.error(
                f"expected ':' after the variables of '{head}', found {self.tok.describe()}",
                self.tok,
                f"write {head} x in Type: formula",
            )

    def starts_aggregate(self) -> bool:
        """Whether ``sum`` here starts an aggregate (``sum x in`` or ``sum x,``), not a name."""
        tokens, pos = self.tokens, self.pos
        return (
            self.tok.text == "sum"
            and pos + 2 < len(tokens)
            and tokens[pos + 1].kind == "IDENT"
            and tokens[pos + 2].kind in ("in", ",")
        )

    def comparison(self) -> Node:
        start = self.tok.column
        left = self.sum()
        if self.tok.kind not in _COMPARE:
            return left
        op = self.advance().kind
        right = self.sum()
        if self.tok.kind in _COMPARE:
            raise self.error(
                f"comparisons cannot be chained: unexpected {self.tok.describe()}",
                self.tok,
                "write a < b and b < c",
            )
        return Compare(op, left, right, start)

    def sum(self) -> Node:
        start = self.tok.column
        left = self.product()
        while self.tok.kind in ("+", "-"):
            op = self.advance().kind
            left = Binary(op, left, self.product(), start)
        return left

    def product(self) -> Node:
        start = self.tok.column
        left = self.unary()
        while self.tok.kind in ("*", "/", "%"):
            op = self.advance().kind
            left = Binary(op, left, self.unary(), start)
        return left

    def unary(self) -> Node:
        minus: list[Token] = []
        while self.tok.kind == "-":
            minus.append(self.advance())
        node = self.power()
        while minus:
            node = Unary("-", node, minus.pop().column)
        return node

    def power(self) -> Node:
        # base ^ -...- base ^ ... : each exponent is a unary, read in this loop
        links: list[tuple[int, Node, list[Token]]] = []
        start = self.tok.column
        base = self.postfix()
        while self.tok.kind == "^":
            self.advance()
            minus: list[Token] = []
            while self.tok.kind == "-":
                minus.append(self.advance())
            links.append((start, base, minus))
            start = self.tok.column
            base = self.postfix()
        node = base
        while links:
            start, base, minus = links.pop()
            while minus:
                node = Unary("-", node, minus.pop().column)
            node = Binary("^", base, node, start)
        return node

    def postfix(self) -> Node:
        start = self.tok.column
        node = self.atom()
        while self.tok.kind == ".":
            self.advance()
            name = self.expect_ident("an attribute name")
            node = Attr(node, name.text, start)
        return node

    def atom(self) -> Node:
        token = self.tok
        kind = token.kind
        if kind == "NUM":
            self.advance()
            return Number(token.value, token.column)  # type: ignore[arg-type]
        if kind == "STR":
            self.advance()
            return String(token.value, token.column)  # type: ignore[arg-type]
        if kind in ("true", "false"):
            self.advance()
            return Bool(kind == "true", token.column)
        if kind == "IDENT":
            if self.starts_aggregate():
                return self.aggregate()
            self.advance()
            if self.tok.kind == "(":
                return Call(token.text, self.arguments(), token.column)
            return Name(token.text, token.column)
        if kind == "(":
            self.advance()
            self.enter(token)
            node = self.formula()
            self.leave()
            self.close(token)
            return node
        if kind == "EOF":
            if self.pos == 0:
                raise self.error("empty formula", token)
            raise self.error(f"unexpected end of formula, expected a term{self.after()}", token, _TERM_HINT)
        raise self.error(f"expected a term{self.after()}, found {token.describe()}", token, _TERM_HINT)

    def arguments(self) -> tuple[Node, ...]:
        opening = self.advance()
        self.enter(opening)
        args: list[Node] = []
        if self.tok.kind != ")":
            args.append(self.formula())
            while self.tok.kind == ",":
                self.advance()
                args.append(self.formula())
        self.leave()
        self.close(opening, "separate arguments with ','")
        return tuple(args)

    def close(self, opening: Token, hint: str = "") -> None:
        token = self.tok
        if token.kind == ")":
            self.advance()
            return
        message = f"expected ')' to close '(' opened at column {opening.column}"
        if token.kind != "EOF":
            message += f", found {token.describe()}"
        raise self.error(message, token, hint or "add the missing ')'")


@lru_cache(maxsize=4096)
def _parse_cached(text: str) -> Node:
    parser = _Parser(text)
    try:
        return parser.parse()
    except RecursionError:
        # a safety net: the depth cap keeps the parser far below Python's limit
        raise FormulaError(
            "formula nested too deeply for this stack; simplify it", 1, text, "split the formula into simpler parts"
        ) from None


def parse(text: str) -> Node:
    """Parse formula text into a syntax tree.

    Results are cached by text, so parsing the same condition every tick is
    cheap; the returned nodes are immutable and may be shared.

    Args:
        text: the formula, e.g. ``"On(a, g) and not holding(?r, a)"``.

    Returns:
        The root node.

    Raises:
        FormulaError: with the 1-based column of the offending token and a
            hint, when the text is not a well-formed formula.
        TypeError: when ``text`` is not a string.
    """
    if not isinstance(text, str):
        raise TypeError(f"formula must be a string, not {type(text).__name__}")
    return _parse_cached(text)
