"""The one exception of the PDDL reader, writer and grounder."""

from __future__ import annotations

from alica.errors import PlannerError
from alica.source import Diagnostic, SourceSpan


class PddlError(PlannerError, ValueError):
    """A PDDL text that cannot be read, or a task the grounder cannot handle.

    The message has the form ``FILE:LINE:COL: error: message`` when the
    problem has a place in a file (the format of :class:`alica.source.Diagnostic`).

    Attributes:
        span: where the problem is (None when it has no place in a file).
        message: what is wrong, without the place.
    """

    def __init__(self, message: str, span: SourceSpan | None = None, hint: str = "") -> None:
        self.span = span
        self.message = message
        if span is None:
            text = f"error: {message}" + (f" (fix: {hint})" if hint else "")
        else:
            text = Diagnostic(span, message, hint).format()
        super().__init__(text)
