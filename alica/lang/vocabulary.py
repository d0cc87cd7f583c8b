"""The predicates and functions formulas may read, with their arities.

A name in a formula is either a bound variable, a symbol (an object constant
such as ``a`` in ``On(a, g)``), or a predicate or function: a registered one
(:class:`~alica.lang.registry.Registry`) or a fact of the belief base. The
facts a formula may read are *declared* here, so a typo such as
``succeded`` is found when the plan is checked, not as a condition that is
never true at run time.

:func:`default_vocabulary` declares what every plan may read without writing
a declaration: the engine's own facts (``succeeded``, ``failed``,
``elapsed``, ``role``, ``alive``, ``in_task``, ``in_state``). Plan files
declare their domain predicates and functions under ``predicates:`` and
``functions:``; other layers declare theirs through :meth:`Vocabulary.declare`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

from alica.lang.ast import KEYWORDS

#: The two kinds of declared names.
PREDICATE = "predicate"
FUNCTION = "function"

_NAME_RE = re.compile(r"\??[A-Za-z_][A-Za-z0-9_]*")

#: Variables the engine binds in every formula of a plan.
ENGINE_VARIABLES: frozenset[str] = frozenset({"self"})


@dataclass(frozen=True, slots=True)
class Symbol:
    """One declared predicate or function of one arity.

    Attributes:
        name: the name used in formulas.
        arity: the number of arguments.
        kind: ``'predicate'`` (a truth value) or ``'function'`` (any value).
        doc: one line saying what it means.
        origin: who declared it (a file position, ``engine``, a module), for messages.
    """

    name: str
    arity: int
    kind: str = PREDICATE
    doc: str = ""
    origin: str = field(default="", compare=False)

    def __str__(self) -> str:
        return f"{self.name}/{self.arity}"


def arity_text(arities: Iterable[int]) -> str:
    """Accepted argument counts in words: ``'1 argument'``, ``'0 or 1 arguments'``."""
    values = sorted(set(arities))
    if not values:
        return "no declared arity"
    words = ", ".join(str(v) for v in values[:-1])
    words = f"{words} or {values[-1]}" if words else str(values[-1])
    return f"{words} argument" + ("" if values == [1] else "s")


class Vocabulary:
    """Declared predicates and functions by name; a name may be declared with several arities.

    Redeclaring a name with the same arity and kind is allowed (a shared file
    imported twice, or two files agreeing); a name cannot be both a predicate
    and a function.
    """

    def __init__(self, symbols: Iterable[Symbol] = ()) -> None:
        self._symbols: dict[str, dict[int, Symbol]] = {}
        for symbol in symbols:
            self.declare(symbol)

    def declare(self, symbol: Symbol) -> Symbol:
        """Add a declaration.

        Returns:
            The declaration kept (the first one when the same was declared before).

        Raises:
            ValueError: for an invalid name, kind or arity, or a name declared
                before as the other kind.
        """
        if not isinstance(symbol.name, str) or not _NAME_RE.fullmatch(symbol.name) or symbol.name in KEYWORDS:
            raise ValueError(f"{symbol.name!r} is not a valid formula identifier")
        if symbol.kind not in (PREDICATE, FUNCTION):
            raise ValueError(f"kind must be 'predicate' or 'function', got {symbol.kind!r}")
        if isinstance(symbol.arity, bool) or not isinstance(symbol.arity, int) or symbol.arity < 0:
            raise ValueError(f"arity of {symbol.name!r} must be a whole number >= 0, got {symbol.arity!r}")
        by_arity = self._symbols.setdefault(symbol.name, {})
        for other in by_arity.values():
            if other.kind != symbol.kind:
                where = f" ({other.origin})" if other.origin else ""
                raise ValueError(f"'{symbol.name}' is declared as a {other.kind}{where}, not a {symbol.kind}")
        return by_arity.setdefault(symbol.arity, symbol)

    def declare_predicate(self, name: str, arity: int, doc: str = "", *, origin: str = "") -> Symbol:
        """Declare a predicate; see :meth:`declare`."""
        return self.declare(Symbol(name, arity, PREDICATE, doc, origin))

    def declare_function(self, name: str, arity: int, doc: str = "", *, origin: str = "") -> Symbol:
        """Declare a function; see :meth:`declare`."""
        return self.declare(Symbol(name, arity, FUNCTION, doc, origin))

    def lookup(self, name: str) -> tuple[Symbol, ...]:
        """The declarations of ``name``, by arity; empty when it is not declared."""
        return tuple(sorted(self._symbols.get(name, {}).values(), key=lambda s: s.arity))

    def get(self, name: str, arity: int) -> Symbol | None:
        """The declaration of ``name`` with ``arity``, or None."""
        return self._symbols.get(name, {}).get(arity)

    def names(self) -> list[str]:
        """Declared names, sorted."""
        return sorted(self._symbols)

    def copy(self) -> Vocabulary:
        """An independent vocabulary with the same declarations."""
        return Vocabulary(self)

    def __contains__(self, name: object) -> bool:
        return name in self._symbols

    def __iter__(self) -> Iterator[Symbol]:
        return iter([s for name in sorted(self._symbols) for s in self.lookup(name)])

    def __len__(self) -> int:
        return sum(len(by_arity) for by_arity in self._symbols.values())

    def __repr__(self) -> str:
        return f"Vocabulary({', '.join(str(s) for s in self)})"


#: The engine's own facts (see ``alica.engine.belief``): what every condition may read.
ENGINE_FACTS: tuple[Symbol, ...] = (
    Symbol("succeeded", 0, PREDICATE, "every child of the current state succeeded", "engine"),
    Symbol("succeeded", 1, PREDICATE, "succeeded(X): the child X of the current state succeeded", "engine"),
    Symbol("failed", 0, PREDICATE, "some child of the current state failed", "engine"),
    Symbol("failed", 1, PREDICATE, "failed(X): the child X of the current state failed", "engine"),
    Symbol("elapsed", 0, FUNCTION, "seconds since the current state was entered", "engine"),
    Symbol("role", 1, FUNCTION, "role(a): the role of agent a", "engine"),
    Symbol("alive", 1, PREDICATE, "alive(a): agent a is alive", "engine"),
    Symbol("in_task", 2, PREDICATE, "in_task(a, T): agent a is in task T of the current plan", "engine"),
    Symbol("in_state", 2, PREDICATE, "in_state(a, S): agent a is in state S of the current plan", "engine"),
)


def default_vocabulary() -> Vocabulary:
    """A fresh vocabulary holding the engine's own facts (:data:`ENGINE_FACTS`)."""
    return Vocabulary(ENGINE_FACTS)
