"""Source locations and diagnostics: the one place that formats ``FILE:LINE:COL``."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True, slots=True, order=True)
class SourceSpan:
    """Where an element was written: 1-based line and column in a file."""

    file: str
    line: int = 0
    column: int = 0

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"

    def shifted(self, columns: int) -> SourceSpan:
        """The same place, ``columns`` further right on the line."""
        return SourceSpan(self.file, self.line, self.column + columns)


@dataclass(frozen=True, slots=True, order=True)
class Diagnostic:
    """One problem found in a plan document.

    Args:
        span: where the problem is.
        message: what is wrong, naming the element.
        hint: what to do about it.
        severity: ``error`` or ``warning``.
    """

    span: SourceSpan
    message: str
    hint: str = field(default="")
    severity: str = field(default="error")

    def format(self) -> str:
        """``FILE:LINE:COL: error: message (fix: hint)``."""
        text = f"{self.span}: {self.severity}: {self.message}"
        if self.hint:
            text += f" (fix: {self.hint})"
        return text
