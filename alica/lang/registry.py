"""Registry of named domain predicates and functions callable from formulas."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from alica.lang.ast import KEYWORDS

Arity = int | tuple[int, int | None]

_NAME_RE = re.compile(r"\??[A-Za-z_][A-Za-z0-9_]*")
_KINDS = ("predicate", "function")


@dataclass(frozen=True, slots=True)
class Entry:
    """One registered callable.

    Attributes:
        name: the name used in formulas.
        fn: the Python callable; called as ``fn(*args)``, or
            ``fn(belief, *args)`` when ``needs_belief``.
        min_arity: fewest arguments accepted.
        max_arity: most arguments accepted, ``None`` for no limit.
        kind: ``'predicate'`` (gives a truth value) or ``'function'``.
        needs_belief: whether the belief base is passed first.
        doc: one-line description for error hints and documentation.
    """

    name: str
    fn: Callable[..., Any]
    min_arity: int
    max_arity: int | None
    kind: str = "predicate"
    needs_belief: bool = False
    doc: str = ""

    def accepts(self, count: int) -> bool:
        """Whether ``count`` arguments are allowed."""
        return count >= self.min_arity and (self.max_arity is None or count <= self.max_arity)

    def arity_text(self) -> str:
        """The accepted argument count in words, e.g. ``'2 arguments'``."""
        low, high = self.min_arity, self.max_arity
        if high == low:
            return f"{low} argument" + ("" if low == 1 else "s")
        if high is None:
            return f"at least {low} argument" + ("" if low == 1 else "s")
        return f"{low} to {high} arguments"


def _arity_bounds(arity: Arity) -> tuple[int, int | None]:
    if isinstance(arity, bool):
        raise ValueError(f"invalid arity {arity!r}")
    if isinstance(arity, int):
        if arity < 0:
            raise ValueError(f"arity must not be negative, got {arity}")
        return arity, arity
    try:
        low, high = arity
    except (TypeError, ValueError):
        raise ValueError(f"arity must be an int or a (min, max) pair, got {arity!r}") from None
    if not isinstance(low, int) or low < 0 or (high is not None and (not isinstance(high, int) or high < low)):
        raise ValueError(f"invalid arity range {arity!r}")
    return low, high


class Registry:
    """Named predicates and functions that formulas may call.

    Registered names take precedence over facts of the belief base with the
    same name. A registry also keeps a cache of compiled formulas, cleared
    whenever an entry changes.
    """

    def __init__(self) -> None:
        self._entries: dict[str, Entry] = {}
        self._compiled: dict[tuple[int, bool], tuple[object, Callable[..., Any]]] = {}

    def register(
        self,
        name: str,
        fn: Callable[..., Any],
        arity: Arity,
        *,
        kind: str = "predicate",
        needs_belief: bool = False,
        doc: str = "",
        replace: bool = False,
    ) -> Entry:
        """Add a callable under ``name``.

        Args:
            name: identifier used in formulas (not a keyword).
            fn: the callable.
            arity: exact argument count, or ``(min, max)`` with ``max`` None
                for variadic.
            kind: ``'predicate'`` or ``'function'``.
            needs_belief: pass the belief base as first argument.
            doc: short description.
            replace: allow replacing an existing entry.

        Returns:
            The new entry.

        Raises:
            ValueError: for a taken name (unless ``replace``), an invalid
                name, kind or arity.
        """
        if not isinstance(name, str) or not _NAME_RE.fullmatch(name) or name in KEYWORDS:
            raise ValueError(f"{name!r} is not a valid formula identifier")
        if kind not in _KINDS:
            raise ValueError(f"kind must be 'predicate' or 'function', got {kind!r}")
        if not callable(fn):
            raise ValueError(f"{name}: {fn!r} is not callable")
        if name in self._entries and not replace:
            raise ValueError(f"{name!r} is already registered (pass replace=True to replace it)")
        low, high = _arity_bounds(arity)
        entry = Entry(name, fn, low, high, kind, needs_belief, doc)
        self._entries[name] = entry
        self._compiled.clear()
        return entry

    def _decorator(
        self, name: str, arity: Arity, kind: str, needs_belief: bool, doc: str, replace: bool
    ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
        def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
            self.register(
                name,
                fn,
                arity,
                kind=kind,
                needs_belief=needs_belief,
                doc=doc or (fn.__doc__ or "").strip().split("\n")[0],
                replace=replace,
            )
            return fn

        return decorate

    def predicate(
        self,
        name: str,
        arity: Arity,
        *,
        needs_belief: bool = False,
        doc: str = "",
        replace: bool = False,
    ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
        """Decorator registering a predicate; see :meth:`register`."""
        return self._decorator(name, arity, "predicate", needs_belief, doc, replace)

    def function(
        self,
        name: str,
        arity: Arity,
        *,
        needs_belief: bool = False,
        doc: str = "",
        replace: bool = False,
    ) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
        """Decorator registering a function; see :meth:`register`."""
        return self._decorator(name, arity, "function", needs_belief, doc, replace)

    def unregister(self, name: str) -> None:
        """Remove ``name``.

        Raises:
            KeyError: if it is not registered.
        """
        del self._entries[name]
        self._compiled.clear()

    def get(self, name: str) -> Entry | None:
        """The entry for ``name``, or None."""
        return self._entries.get(name)

    def copy(self) -> Registry:
        """An independent registry with the same entries."""
        other = Registry()
        other._entries = dict(self._entries)
        return other

    def names(self) -> list[str]:
        """Registered names, sorted."""
        return sorted(self._entries)

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[Entry]:
        return iter(list(self._entries.values()))

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Registry({', '.join(self.names())})"
