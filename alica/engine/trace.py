"""Trace observers: every allocation, transition, repair, message and fault as one JSON line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import IO, Any, Self


class TraceRecorder:
    """Keeps trace events in memory (for tests and summaries).

    Args:
        keep: event kinds to keep; ``None`` keeps everything.
    """

    def __init__(self, keep: frozenset[str] | None = None) -> None:
        self.keep = keep
        self.events: list[dict[str, Any]] = []

    def __call__(self, event: dict[str, Any]) -> None:
        if self.keep is None or event["event"] in self.keep:
            self.events.append(event)

    def of(self, kind: str, **match: object) -> list[dict[str, Any]]:
        """Events of ``kind`` whose fields equal ``match``."""
        return [e for e in self.events if e["event"] == kind and all(e.get(k) == v for k, v in match.items())]

    def lines(self) -> list[str]:
        """The events as JSON lines (keys sorted), as a trace file holds them."""
        return [json.dumps(e, sort_keys=True, default=str) for e in self.events]


class JsonlTrace:
    """Writes trace events to a JSON Lines file, one event per line, keys sorted.

    Args:
        path: the file to write (created or truncated).
        line_buffered: write each event through at once (an agent process that
            may be killed keeps its trace up to the kill); else in blocks.
    """

    def __init__(self, path: str | Path, *, line_buffered: bool = False) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: IO[str] | None = self.path.open("w", encoding="utf-8", buffering=1 if line_buffered else -1)
        self.count = 0

    def __call__(self, event: dict[str, Any]) -> None:
        if self._file is None:
            raise ValueError(f"trace {self.path} is closed")
        self._file.write(json.dumps(event, sort_keys=True, default=str))
        self._file.write("\n")
        self.count += 1

    def close(self) -> None:
        """Flush and close the file."""
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
