"""The exceptions the library raises.

One root, :class:`AlicaError`, and a few branches that mix in the matching
builtin so callers can catch either. Library code raises; only ``main()``
functions turn errors into exit codes.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from alica.source import Diagnostic


class AlicaError(Exception):
    """Root of every error the library raises on purpose."""


class PlanFormatError(AlicaError, ValueError):
    """One or more problems in plan files, each with file, line and column.

    Attributes:
        diagnostics: every problem found, in file and line order.
    """

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diagnostics: tuple[Diagnostic, ...] = tuple(sorted(diagnostics))
        if not self.diagnostics:
            raise ValueError("PlanFormatError needs at least one diagnostic")
        super().__init__("\n".join(d.format() for d in self.diagnostics))

    @property
    def errors(self) -> Sequence[Diagnostic]:
        """The diagnostics of severity ``error``."""
        return [d for d in self.diagnostics if d.severity == "error"]


class FormulaError(AlicaError, ValueError):
    """A formula that cannot be parsed or checked.

    Attributes:
        message: what is wrong.
        column: 1-based column inside the formula text.
        text: the formula text.
        hint: what to do about it (may be empty).
    """

    def __init__(self, message: str, column: int, text: str, hint: str = "") -> None:
        self.message = message
        self.column = column
        self.text = text
        self.hint = hint
        pointer = " " * (column - 1) + "^"
        super().__init__(f"{message} at column {column}\n  {text}\n  {pointer}")


class EvaluationError(AlicaError, RuntimeError):
    """A formula that parsed but cannot be evaluated against a belief base."""


class UnknownSkillError(AlicaError, LookupError):
    """A behaviour names a skill the registry does not know."""


class PlannerError(AlicaError, RuntimeError):
    """A planner that cannot run or failed."""


class SkillError(AlicaError, RuntimeError):
    """A skill that failed while running."""


class TraceFormatError(AlicaError, ValueError):
    """A trace file that cannot be read: not JSON Lines, another format, or a newer version.

    The message reads ``FILE:LINE: error: what (fix: how)``.
    """
