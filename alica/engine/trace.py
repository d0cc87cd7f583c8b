"""Trace files: every allocation, transition, repair, message and fault as one JSON line.

A trace is JSON Lines, one event per line, keys sorted. Every event has
``t`` (seconds), ``agent`` (``"-"`` for the team or the world) and
``event`` (its kind). Format version 2 starts with a header line,
``{"event": "trace", "format": "alica-trace", "version": 2, ...}``, that
says what a viewer needs up front (the plans, the agents and their roles,
the seed, the world and its bounds); a run with a world then also records
``pose``, ``object``, ``found`` and ``map`` events (written by the
application layer, which knows the world). Version 1 had no header.
``docs/trace.md`` documents every event kind and the versioning rules.

:class:`JsonlTrace` writes a file (header first), :func:`trace_header`
makes the header, :func:`read_trace` reads a file back into a
:class:`Trace`, with ``FILE:LINE: error: ... (fix: ...)`` for bad input.
"""

from __future__ import annotations

import base64
import json
import math
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Self

from alica.errors import TraceFormatError

#: The ``format`` of the header line.
FORMAT = "alica-trace"
#: The format version this library writes; it reads this one and every older one.
VERSION = 2
#: The ``event`` of the header line.
HEADER_EVENT = "trace"
#: The world kinds of the header's ``world``.
WORLD_KINDS = ("none", "blocks", "lunar")
#: The ``encoding`` of a ``map`` event's ``cells``: one byte per cell (0 unknown, 1 free, 2 occupied),
#: rows from the lowest y up, zlib-compressed, then base64.
MAP_ENCODING = "zlib-u8"


def trace_header(
    *,
    plans: Sequence[str],
    root: str,
    agents: Mapping[str, str],
    seed: int | None,
    world: str = "none",
    bounds: Sequence[float] | None = None,
    roots: Mapping[str, str] | None = None,
    skills: Sequence[str] = (),
    plan_path: Sequence[str] = (),
    **extra: Any,
) -> dict[str, Any]:
    """The header line of a version-2 trace.

    Args:
        plans: the plan files the run loaded, as given (a shipped mission as ``alica:plans/<path>``).
        root: the root plan of the team.
        agents: agent name -> role name, every agent of the run.
        seed: the run's seed (``None`` when it has none).
        world: ``none``, ``blocks`` or ``lunar``.
        bounds: the world's field ``(xmin, ymin, xmax, ymax)`` in metres, with a world.
        roots: agent -> root plan for agents whose root is not ``root`` (an opposing team).
        skills: the skill modules the run loaded besides the installed plug-ins (its ``--skills``), so
            that a viewer can load the plans that use their skills.
        plan_path: the plan folders the run's imports could reach besides the plan file's own
            folder and project, as the run names them (the shipped plans as ``alica:plans``).
        **extra: further fields (the sampling rates, the robots' kinds...).

    Raises:
        ValueError: an unknown world kind, or bounds that are not four numbers.
    """
    if world not in WORLD_KINDS:
        raise ValueError(f"world must be one of {', '.join(WORLD_KINDS)}, got {world!r}")
    if bounds is not None and len(bounds) != 4:
        raise ValueError(f"bounds must be (xmin, ymin, xmax, ymax), got {tuple(bounds)}")
    other = dict(roots or {})
    header: dict[str, Any] = {
        **extra,
        "t": 0.0,
        "agent": "-",
        "event": HEADER_EVENT,
        "format": FORMAT,
        "version": VERSION,
        "plans": [str(p) for p in plans],
        "root": root,
        "agents": {name: {"role": agents[name], "plan": other.get(name, root)} for name in sorted(agents)},
        "seed": seed,
        "world": world,
        "bounds": [round(float(b), 3) for b in bounds] if bounds is not None else None,
        "skills": [str(m) for m in skills],
        "plan_path": [str(p) for p in plan_path],
    }
    return header


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
        header: the header line (:func:`trace_header`), written first; ``None`` writes none
            (a piece of a trace that is merged later, such as one agent process's).
        line_buffered: write each event through at once (an agent process that
            may be killed keeps its trace up to the kill); else in blocks.
    """

    def __init__(
        self, path: str | Path, *, header: Mapping[str, Any] | None = None, line_buffered: bool = False
    ) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: IO[str] | None = self.path.open("w", encoding="utf-8", buffering=1 if line_buffered else -1)
        self.count = 0
        self.bytes = 0
        if header is not None:
            self.write(dict(header))

    def __call__(self, event: dict[str, Any]) -> None:
        self.write(event)

    def write(self, event: Mapping[str, Any]) -> None:
        """Write one event as a line.

        Raises:
            ValueError: the trace is closed.
        """
        if self._file is None:
            raise ValueError(f"trace {self.path} is closed")
        line = json.dumps(event, sort_keys=True, default=str) + "\n"
        self._file.write(line)
        self.count += 1
        self.bytes += len(line.encode("utf-8"))

    def close(self) -> None:
        """Flush and close the file."""
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass(slots=True)
class Trace:
    """A trace read back (:func:`read_trace`).

    Attributes:
        path: the file.
        version: the format version (1 for a trace without a header).
        meta: the header's fields (without ``t``, ``agent`` and ``event``); for a
            version-1 trace what could be told from the events (``agents`` with roles unknown).
        events: every event after the header, in file order.
        notes: what the reader wants a person to know (a version-1 trace lacks poses and maps).
    """

    path: Path
    version: int
    meta: dict[str, Any]
    events: list[dict[str, Any]]
    notes: list[str] = field(default_factory=list)

    def of(self, kind: str, **match: object) -> list[dict[str, Any]]:
        """Events of ``kind`` whose fields equal ``match``."""
        return [e for e in self.events if e["event"] == kind and all(e.get(k) == v for k, v in match.items())]

    @property
    def agents(self) -> list[str]:
        """The agents of the run, by name."""
        return sorted(self.meta.get("agents") or {})

    @property
    def duration(self) -> float:
        """The time of the last event (0 for none)."""
        return max((float(e["t"]) for e in self.events), default=0.0)


def read_trace(path: str | Path) -> Trace:
    """Read a trace file of any version up to :data:`VERSION`.

    A version-1 trace (no header) is read with a note in :attr:`Trace.notes`
    that it carries no robot poses, objects or maps.

    Raises:
        TraceFormatError: a missing or unreadable file, a line that is not a JSON
            object with ``t``, ``agent`` and ``event``, an unknown format, a newer
            version, a second header; the message is ``FILE:LINE: error: ... (fix: ...)``.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise TraceFormatError(
            f"{path}: error: no such file (fix: give the trace a run wrote with --trace or --out)"
        ) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise TraceFormatError(
            f"{path}: error: cannot read the file: {exc} (fix: give a JSON Lines trace file)"
        ) from None
    events: list[tuple[int, dict[str, Any]]] = []
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        events.append((number, _event(path, number, line)))
    if not events:
        raise TraceFormatError(
            f"{path}:1: error: the trace holds no events (fix: give the file a run wrote with --trace or --out)"
        )
    first_line, first = events[0]
    for number, event in events[1:]:
        if event["event"] == HEADER_EVENT:
            raise TraceFormatError(
                f"{path}:{number}: error: a second trace header (fix: a trace file holds one run; "
                "split concatenated traces into one file each)"
            )
    if first["event"] != HEADER_EVENT:
        return _version_one(path, [e for _, e in events])
    meta = _header(path, first_line, first)
    return Trace(path, int(meta["version"]), meta, [e for _, e in events[1:]])


def _event(path: Path, number: int, line: str) -> dict[str, Any]:
    where = f"{path}:{number}"
    try:
        event = json.loads(line)
    except (ValueError, RecursionError) as exc:
        raise TraceFormatError(
            f"{where}: error: not JSON ({_reason(exc)}) (fix: a trace holds one JSON object per line; "
            "a truncated last line comes from a process killed while writing: delete it)"
        ) from None
    if not isinstance(event, dict):
        raise TraceFormatError(
            f"{where}: error: a JSON {type(event).__name__}, not an object (fix: each line is one event, "
            '{"t": ..., "agent": ..., "event": ...})'
        )
    missing = [key for key in ("t", "agent", "event") if key not in event]
    if missing:
        raise TraceFormatError(
            f"{where}: error: an event without {', '.join(missing)} (fix: every event has t, agent and event; "
            "is this an alica trace?)"
        )
    t = event["t"]
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(_seconds(t)):
        raise TraceFormatError(f"{where}: error: t is {t!r}, not a number of seconds (fix: write t as seconds)")
    if not isinstance(event["event"], str) or not isinstance(event["agent"], str):
        raise TraceFormatError(
            f"{where}: error: event and agent must be strings, got {event['event']!r} and {event['agent']!r} "
            "(fix: write them as strings)"
        )
    return event


def _seconds(t: float) -> float:
    """``t`` as a float; infinite for a whole number too large for one."""
    try:
        return float(t)
    except OverflowError:
        return math.inf


def _reason(exc: Exception) -> str:
    if isinstance(exc, json.JSONDecodeError):
        return f"{exc.msg} at column {exc.colno}"
    return "nested too deep" if isinstance(exc, RecursionError) else str(exc)


def _header(path: Path, number: int, header: dict[str, Any]) -> dict[str, Any]:
    where = f"{path}:{number}"
    if header.get("format") != FORMAT:
        raise TraceFormatError(
            f"{where}: error: unknown trace format {header.get('format')!r}, expected {FORMAT!r} "
            "(fix: give a trace written by alica)"
        )
    version = header.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 2:
        raise TraceFormatError(
            f"{where}: error: trace version {version!r} is not a whole number >= 2 "
            "(fix: the header's version must be the one alica wrote)"
        )
    if version > VERSION:
        raise TraceFormatError(
            f"{where}: error: trace format version {version} was written by a newer alica; "
            f"this one reads up to version {VERSION} (fix: upgrade alica)"
        )
    agents = header.get("agents")
    if not isinstance(agents, dict) or not all(isinstance(a, dict) for a in agents.values()):
        raise TraceFormatError(
            f"{where}: error: the header's agents is not an object of agent -> {{role, plan}} "
            "(fix: the header must be the one alica wrote)"
        )
    return {k: v for k, v in header.items() if k not in ("t", "agent", "event")}


def _version_one(path: Path, events: list[dict[str, Any]]) -> Trace:
    names = sorted({e["agent"] for e in events if e["agent"] != "-"})
    meta: dict[str, Any] = {
        "format": FORMAT,
        "version": 1,
        "plans": [],
        "root": None,
        "agents": {name: {"role": None, "plan": None} for name in names},
        "seed": None,
        "world": "none",
        "bounds": None,
    }
    note = (
        f"{path}: note: a version-1 trace (no header, written by an older alica): it has the events of "
        "the agents but no robot poses, objects or maps, and no plans, roles or seed up front; "
        "record the run again for those"
    )
    return Trace(path, 1, meta, events, [note])


def encode_cells(cells: bytes, width: int, height: int) -> str:
    """The ``cells`` text of a ``map`` event: one byte per cell (see :data:`MAP_ENCODING`).

    Raises:
        ValueError: ``cells`` is not ``width * height`` bytes.
    """
    if len(cells) != width * height:
        raise ValueError(f"{width} x {height} cells need {width * height} bytes, got {len(cells)}")
    return base64.b64encode(zlib.compress(bytes(cells), 9)).decode("ascii")


def decode_cells(event: Mapping[str, Any]) -> bytes:
    """The cells of a ``map`` event, one byte per cell, row by row from the lowest y (0 unknown, 1 free, 2 occupied).

    Raises:
        TraceFormatError: an unknown encoding or cells that do not decode to ``width * height`` bytes.
    """
    if event.get("encoding") != MAP_ENCODING:
        raise TraceFormatError(f"map event at t={event.get('t')}: unknown encoding {event.get('encoding')!r}")
    try:
        cells = zlib.decompress(base64.b64decode(str(event["cells"]), validate=True))
        size = int(event["width"]) * int(event["height"])
    except (KeyError, ValueError, TypeError, zlib.error) as exc:
        raise TraceFormatError(f"map event at t={event.get('t')}: the cells do not decode: {exc}") from None
    if len(cells) != size:
        raise TraceFormatError(f"map event at t={event.get('t')}: {len(cells)} cells, expected {size}")
    return cells
