"""A plan library's digest, and what changed between two libraries.

The digest names a library's content, not its files: two agents that loaded
the same plans from different folders, or one from YAML and one from XML,
get the same digest, and so do two processes (nothing in it depends on a
process's string hashing). Where an element was written (its span) is left
out, so an edit that only moves lines changes nothing. The team compares
digests to agree on the library it runs (hot reload, :mod:`alica.engine.reload`).
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
from collections.abc import Iterator
from dataclasses import dataclass

from alica.model.library import PlanLibrary

#: Characters of a digest (hexadecimal; 64 bits of SHA-256).
DIGEST_LENGTH = 16


def canonical(value: object) -> object:
    """``value`` as JSON data whose text is the same in every process.

    Dataclasses become their compared fields (spans are not compared) with the
    class name, enums their values, sets sorted lists, mappings sorted pairs.
    """
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        out: dict[str, object] = {"@": type(value).__name__}
        for f in dataclasses.fields(value):
            if f.compare:
                out[f.name] = canonical(getattr(value, f.name))
        return out
    if isinstance(value, enum.Enum):
        return canonical(value.value)
    if isinstance(value, (tuple, list)):
        return [canonical(v) for v in value]
    if isinstance(value, (set, frozenset)):
        return sorted((canonical(v) for v in value), key=_text)
    if isinstance(value, dict):
        return sorted(([canonical(k), canonical(v)] for k, v in value.items()), key=_text)
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    return repr(value)


def _text(value: object) -> str:
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def _digest(value: object) -> str:
    return hashlib.sha256(_text(value).encode("utf-8")).hexdigest()[:DIGEST_LENGTH]


def elements(library: PlanLibrary) -> Iterator[tuple[str, object]]:
    """``("kind name", element)`` of every named element of ``library``, kinds in file order, names sorted.

    Kinds: task, roleset, behaviour, plan, plantype, problem, skill (declared in a plan
    file), predicate and function (declared for formulas).
    """
    for kind, index in (
        ("task", library.tasks),
        ("roleset", library.rolesets),
        ("behaviour", library.behaviours),
        ("plan", library.plans),
        ("plantype", library.plantypes),
        ("problem", library.problems),
        ("skill", library.skills),
    ):
        for name in sorted(index):
            yield f"{kind} {name}", index[name]
    for kind in ("predicates", "functions"):
        declared = {f"{kind[:-1]} {d.name}/{d.arity}": d for doc in library.documents for d in getattr(doc, kind)}
        yield from sorted(declared.items())


def element_digests(library: PlanLibrary) -> dict[str, str]:
    """``"kind name"`` -> the digest of that element (see :func:`elements`)."""
    return {key: _digest(canonical(element)) for key, element in elements(library)}


def library_digest(library: PlanLibrary) -> str:
    """The digest of ``library``'s content (:data:`DIGEST_LENGTH` hexadecimal characters)."""
    return _digest(sorted(element_digests(library).items()))


@dataclass(frozen=True, slots=True)
class LibraryChanges:
    """The elements one library adds, removes and changes against another, as ``"kind name"``, sorted."""

    added: tuple[str, ...] = ()
    removed: tuple[str, ...] = ()
    changed: tuple[str, ...] = ()

    @property
    def empty(self) -> bool:
        """Whether nothing changed."""
        return not (self.added or self.removed or self.changed)

    def names(self, kind: str) -> set[str]:
        """Names of the elements of ``kind`` (``plan``, ``behaviour``, ...) added, removed or changed."""
        prefix = kind + " "
        return {k[len(prefix) :] for k in (*self.added, *self.removed, *self.changed) if k.startswith(prefix)}

    def describe(self) -> dict[str, list[str]]:
        """As JSON data (for the trace), empty lists left out."""
        return {
            k: list(v) for k, v in (("added", self.added), ("removed", self.removed), ("changed", self.changed)) if v
        }

    def text(self) -> str:
        """One line: ``changed plan Gate; added behaviour Wave``, or ``no change``."""
        parts = [f"{what} {', '.join(keys)}" for what, keys in self.describe().items()]
        return "; ".join(parts) or "no change"


def library_changes(old: PlanLibrary, new: PlanLibrary) -> LibraryChanges:
    """What ``new`` adds, removes and changes against ``old``."""
    before, after = element_digests(old), element_digests(new)
    return LibraryChanges(
        added=tuple(sorted(after.keys() - before.keys())),
        removed=tuple(sorted(before.keys() - after.keys())),
        changed=tuple(sorted(k for k in before.keys() & after.keys() if before[k] != after[k])),
    )
