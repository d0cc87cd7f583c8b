"""Read a trace file (JSON Lines) for the control center.

One small loader, tolerant of what the next trace format adds: a first header
line ``{"event": "trace", ...}`` is kept as ``meta`` and not counted as an
event, and ``pose`` events are kept like any other. It will be replaced by the
shared trace reader.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from alica.errors import AlicaError


class TraceFormatError(AlicaError, ValueError):
    """A line of a trace file that cannot be read; the message is ``FILE:LINE: error: ...``.

    Attributes:
        file: the trace file.
        line: the line number, from 1.
    """

    def __init__(self, file: str, line: int, message: str) -> None:
        self.file, self.line = file, line
        super().__init__(f"{file}:{line}: error: {message}")


@dataclass(slots=True)
class Trace:
    """The events of a trace, in file order, and its header if it has one."""

    path: str
    events: list[dict[str, Any]]
    meta: dict[str, Any] = field(default_factory=dict)


def load_trace(path: str | Path) -> Trace:
    """Read a trace file.

    Raises:
        AlicaError: the file is missing or unreadable.
        TraceFormatError: a line is not a JSON object with a numeric ``t`` and a string ``event``.
    """
    name = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise AlicaError(f"trace file {name} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise AlicaError(f"cannot read trace file {name}: {exc}") from None
    events: list[dict[str, Any]] = []
    meta: dict[str, Any] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except json.JSONDecodeError as exc:
            raise TraceFormatError(name, number, f"not JSON ({exc.msg} at column {exc.colno})") from None
        if not isinstance(record, dict):
            raise TraceFormatError(name, number, "a trace line must be a JSON object")
        if record.get("event") == "trace" and not events and not meta:
            meta = record
            continue
        if not isinstance(record.get("event"), str):
            raise TraceFormatError(name, number, "the line has no 'event' name")
        t = record.get("t")
        if isinstance(t, bool) or not isinstance(t, int | float):
            raise TraceFormatError(name, number, "the line has no numeric time 't'")
        events.append(record)
    events.sort(key=lambda e: float(e["t"]))  # stable: file order within one time
    return Trace(name, events, meta)
