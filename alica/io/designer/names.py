"""Valid, unique names for designer elements, chosen deterministically.

The designer allows any text as a name: empty names, ``MISSING_NAME``, an
element's numeric id, blanks (``FromPlanATo PlanB``), and one name for a
behaviour and a plan (``Tackle.beh`` and ``Tackle.pml``). Our format needs
names that formulas can read (``succeeded(Tackle)``), unique in their
namespace: behaviours, plans and plan types share one; tasks, role sets,
skills and predicates have their own; states, entry points, transitions,
synchronisations and variables are unique within their plan.

:func:`sanitize` makes one name valid; :class:`Namespace` makes names unique
in the order they are claimed, so the same input always gives the same names.
A name that is valid and free is kept as it is.
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable

from alica.lang.ast import KEYWORDS

_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_INVALID = re.compile(r"[^A-Za-z0-9_]+")

#: The designer's name for an element nobody named.
MISSING_NAME = "MISSING_NAME"


def is_identifier(name: str) -> bool:
    """Whether ``name`` is a name formulas can read (letters, digits, ``_``; not starting with a digit)."""
    return bool(_IDENTIFIER.match(name))


def is_placeholder(name: str, element_id: int | None = None) -> bool:
    """Whether ``name`` is the designer's stand-in for no name: empty, ``MISSING_NAME`` or a number (the id)."""
    text = name.strip()
    return not text or text == MISSING_NAME or text.isdigit() or (element_id is not None and text == str(element_id))


def sanitize(raw: str, fallback: str, reserved: Iterable[str] = ()) -> str:
    """``raw`` as a valid name: kept when it is one, else made one.

    Accents are dropped (``Überholen`` -> ``Uberholen``), every run of other
    characters becomes ``_`` (``a b-c`` -> ``a_b_c``), a leading digit gets a
    ``_`` before it, and a keyword of the formula language or a reserved name
    gets one after it (``and`` -> ``and_``).

    Args:
        raw: the designer's name.
        fallback: the name to use when nothing of ``raw`` is left; must be valid.
        reserved: names that may not be used (besides the language's keywords).
    """
    taken = KEYWORDS | frozenset(reserved)
    if is_identifier(raw) and raw not in taken:
        return raw
    plain = unicodedata.normalize("NFKD", raw).encode("ascii", "ignore").decode("ascii")
    name = _INVALID.sub("_", plain).strip("_") or fallback
    if name[0].isdigit():
        name = "_" + name
    while name in taken:
        name += "_"
    return name


class Namespace:
    """Names unique among themselves, handed out in the order they are claimed.

    Args:
        reserved: names that may not be used in this namespace (e.g. the engine's
            own predicates, or the names of another namespace formulas also read).
    """

    def __init__(self, reserved: Iterable[str] = ()) -> None:
        self._reserved = frozenset(reserved)
        self._taken: set[str] = set()

    @property
    def reserved(self) -> frozenset[str]:
        """The names this namespace never hands out."""
        return self._reserved

    def __contains__(self, name: object) -> bool:
        return name in self._taken

    def claim(self, raw: str, fallback: str, suffix: str = "") -> str:
        """A valid name for ``raw`` that no earlier claim has; it is taken from now on.

        Args:
            raw: the designer's name.
            fallback: the name to use when ``raw`` has nothing usable (must be valid).
            suffix: added first when the name is taken (``Tackle`` -> ``TackleBehaviour``),
                before the numbers ``_2``, ``_3``, ...
        """
        base = sanitize(raw, fallback, self._reserved)
        candidates = [base] + ([base + suffix] if suffix else [])
        name = next((c for c in candidates if self._free(c)), None)
        stem = candidates[-1]
        number = 2
        while name is None:
            candidate = f"{stem}_{number}"
            if self._free(candidate):
                name = candidate
            number += 1
        self._taken.add(name)
        return name

    def _free(self, name: str) -> bool:
        return name not in self._taken and name not in self._reserved and name not in KEYWORDS
