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


def byte_place(data: bytes, offset: int, file: str) -> SourceSpan:
    """The line and column of byte ``offset`` in ``data`` (UTF-8 text), for a decoding error.

    The column counts the characters before the offset on its line (invalid bytes
    count one each), so it matches what an editor shows.
    """
    offset = max(0, min(offset, len(data)))
    line_start = data.rfind(b"\n", 0, offset) + 1
    before = data[line_start:offset].decode("utf-8", errors="replace")
    return SourceSpan(file, data.count(b"\n", 0, offset) + 1, len(before) + 1)
