"""Declarations of the predicates and functions a plan file's formulas may read."""

from __future__ import annotations

from dataclasses import dataclass

from alica.model.common import span_field
from alica.source import SourceSpan


@dataclass(frozen=True, slots=True)
class Declaration:
    """A predicate or function of the domain, declared in a plan file (``found/1``).

    Declarations are visible in the declaring file and in every file that
    imports it, directly or not; a mission declares its domain predicates once
    in a shared file.

    Args:
        name: the name used in formulas.
        arity: the number of arguments it takes.
        doc: what it means, one line.
    """

    name: str
    arity: int
    doc: str = ""
    span: SourceSpan | None = span_field()

    def __str__(self) -> str:
        return f"{self.name}/{self.arity}"
