"""A trace file for the control center: the shared reader's trace, its events in time order.

Reading and checking is :func:`alica.engine.trace.read_trace` (every format
version, ``FILE:LINE: error: ... (fix: ...)`` for bad input, a note for a
version-1 trace); this module only orders the events by time for the replay.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from alica.app.center.team_view import header_roles
from alica.engine.trace import read_trace
from alica.errors import TraceFormatError

__all__ = ["Trace", "TraceFormatError", "load_trace"]


@dataclass(slots=True)
class Trace:
    """A trace as the replay uses it.

    Attributes:
        path: the file.
        events: every event after the header, ordered by ``t`` (file order within one time).
        meta: the header's fields with ``version`` (for a version-1 trace, what the reader told from the events).
        notes: what the reader wants a person to know (a version-1 trace has no poses or maps).
    """

    path: str
    events: list[dict[str, Any]]
    meta: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    @property
    def roles(self) -> dict[str, str]:
        """Agent -> role, as the header names them (none for a version-1 trace)."""
        return header_roles(self.meta)


def load_trace(path: str | Path) -> Trace:
    """Read a trace file with the shared reader.

    Raises:
        TraceFormatError: a missing or unreadable file, or a line the reader refuses (``FILE:LINE: error: ...``).
    """
    trace = read_trace(path)
    events = sorted(trace.events, key=lambda e: float(e["t"]))  # stable: file order within one time
    return Trace(str(path), events, {**trace.meta, "version": trace.version}, list(trace.notes))
