"""The one exception of the RDDL reader, checker and writer."""

from __future__ import annotations

from alica.errors import PlannerError
from alica.source import Diagnostic, SourceSpan


class RddlError(PlannerError, ValueError):
    """An RDDL text that cannot be read, or blocks whose names do not agree.

    The message has the form ``FILE:LINE:COL: error: message (fix: hint)`` when
    the problem has a place in a file (the format of :class:`alica.source.Diagnostic`).

    Attributes:
        span: where the problem is (None when it has no place in a file).
        message: what is wrong, without the place.
        hint: what to do about it (may be empty).
    """

    def __init__(self, message: str, span: SourceSpan | None = None, hint: str = "") -> None:
        self.span = span
        self.message = message
        self.hint = hint
        if span is None:
            text = f"error: {message}" + (f" (fix: {hint})" if hint else "")
        else:
            text = Diagnostic(span, message, hint).format()
        super().__init__(text)
