"""``--watch``: the plan files of a running team, loaded again when they change on disk.

:class:`PlanWatch` polls the size and modification time of every file of the
running library (the entry file and what it imports). A file that changed is
loaded once it has stayed the same for one poll, so an editor's save is read
whole, not half-written. The new set is loaded and validated from scratch: a
valid library goes to the engine (:meth:`AgentEngine.reload
<alica.engine.agent.AgentEngine.reload>`, :meth:`SimulatedTeam.reload
<alica.engine.runner.SimulatedTeam.reload>`), which adopts it when the whole
team has it; an invalid one is reported with file, line and column, and the
team goes on with the plans it runs.

Polling a handful of files a few times a second costs microseconds and behaves
the same on every system and file system; a notification library
(watchfiles, watchdog) would add a thread and a dependency for no gain here.

:func:`reload_line` turns the engine's ``reload`` trace events into the lines
``alica run`` and ``alica agent`` print.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from alica.errors import AlicaError, PlanFormatError
from alica.model import PlanLibrary

#: Wall seconds between two looks at the files.
POLL_S = 0.1


@dataclass(frozen=True, slots=True)
class Invalid:
    """Changed files that do not load: what is wrong, with file, line and column (or why the run refuses them)."""

    errors: tuple[str, ...]


def _stat(path: Path) -> tuple[int, int] | None:
    try:
        info = path.stat()
    except OSError:
        return None
    return info.st_mtime_ns, info.st_size


class PlanWatch:
    """Watches the files of a running library (see the module docstring).

    Args:
        entry: the plan file the run was started with.
        library: the library loaded from it.
        load: loads the entry file again (a fresh loader each time: nothing cached).
        interval: wall seconds between two looks.
        clock: the wall clock (``time.monotonic``; tests give their own).
    """

    def __init__(
        self,
        entry: str | os.PathLike[str],
        library: PlanLibrary,
        load: Callable[[], PlanLibrary],
        interval: float = POLL_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.entry = Path(entry)
        self.load = load
        self.interval = interval
        self.clock = clock
        self.files: dict[Path, tuple[int, int] | None] = {}
        self._watch(library)
        self._next = 0.0
        self._changed: dict[Path, tuple[int, int] | None] = {}
        self.loads = 0
        """How often the files were loaded again (valid or not)."""

    def _watch(self, library: PlanLibrary) -> None:
        """Watch the entry file and every file the library was read from."""
        paths = {self.entry, *(Path(d.path) for d in library.documents if d.path)}
        self.files = {p: _stat(p) for p in sorted(paths)}

    def poll(self) -> PlanLibrary | Invalid | None:
        """Look at the files (at most every ``interval``): a new library, what is wrong with the files, or None."""
        now = self.clock()
        if now < self._next:
            return None
        self._next = now + self.interval
        current = {p: _stat(p) for p in self.files}
        moved = {p: s for p, s in current.items() if s != self.files[p]}
        if not moved:
            self._changed = {}
            return None
        if moved != self._changed:  # still being written: read it once it stayed the same for one look
            self._changed = moved
            return None
        self._changed = {}
        self.files.update(moved)
        return self.reload()

    def reload(self) -> PlanLibrary | Invalid:
        """Load the files now (the control center's reload action does, as a change does)."""
        self.loads += 1
        try:
            library = self.load()
        except PlanFormatError as exc:
            return Invalid(tuple(d.format() for d in exc.diagnostics))
        except AlicaError as exc:
            return Invalid((str(exc),))
        self._watch(library)
        return library


def reload_line(event: dict[str, Any]) -> str | None:
    """One line for a ``reload`` trace event (``None`` for events that are not one)."""
    if event.get("event") != "reload":
        return None
    who, status = event.get("agent", "-"), event.get("status")
    if status == "proposed":
        return f"reload: {who} loaded plans {event.get('proposed')} ({_changes(event)}); waiting for the team"
    if status == "agreed":
        return f"reload: {who} (leader): the team has plans {event.get('proposed')}; switching at t={event.get('at')}"
    if status == "waiting":
        differ = event.get("differ") or {}
        others = ", ".join(f"{name} has {digest}" for name, digest in sorted(differ.items()))
        return (
            f"reload: {who} does not switch to plans {event.get('proposed')}: {others} "
            f"(the team goes on with {event.get('library')})"
        )
    if status == "adopted":
        return f"reload: {who} switched plans {event.get('library')} -> {event.get('adopted')} ({_changes(event)})"
    if status == "invalid":
        errors = "\n  ".join(str(e) for e in event.get("errors") or ())
        return f"reload: the changed plan files do not load; the team goes on with the plans it runs:\n  {errors}"
    if event.get("note"):
        return f"reload: {who}: {event.get('key')}: {event['note']}"
    return None


def _changes(event: dict[str, Any]) -> str:
    changes = event.get("changes") or {}
    return "; ".join(f"{what} {', '.join(keys)}" for what, keys in changes.items()) or "no change"


def invalid_event(now: float, invalid: Invalid, agent: str = "-") -> dict[str, Any]:
    """The trace event of files that do not load."""
    return {"t": round(now, 6), "agent": agent, "event": "reload", "status": "invalid", "errors": list(invalid.errors)}


class TeamReloads:
    """What ``--watch`` and the control center's reload action do to a team, or to one agent.

    Args:
        watch: the team's plan files.
        team: the simulated team (:meth:`SimulatedTeam.reload <alica.engine.runner.SimulatedTeam.reload>`), or
            one agent's engine (``alica agent``: :meth:`AgentEngine.reload <alica.engine.agent.AgentEngine.reload>`).
        observers: the run's trace observers (an ``invalid`` event goes to them).
    """

    def __init__(self, watch: PlanWatch, team: Any, observers: Iterable[Callable[[dict[str, Any]], None]]) -> None:
        self.watch = watch
        self.team = team
        self.observers = list(observers)
        self.offers: list[Callable[[PlanLibrary], None]] = []
        """Called with every valid library given to the team (the control center shows its plan tree once adopted)."""

    def look(self, _now: float = 0.0) -> None:
        """After a tick: give the team what changed on disk, if anything."""
        result = self.watch.poll()
        if result is not None:
            self.apply(result)

    def reload(self, *, by_operator: bool = False) -> dict[str, Any]:
        """Load the files now and give the team the result (the control center's reload action).

        With ``by_operator`` the run's trace gets the operator's action too (an ``operator`` event, agent
        ``operator``, ``what: reload``, with the outcome), as the center's other actions do.
        """
        outcome = self.apply(self.watch.reload())
        if by_operator:
            event = {"t": round(self.team.now(), 6), "agent": "operator", "event": "operator", "what": "reload"}
            for observer in self.observers:
                observer({**event, **outcome})
        return outcome

    def apply(self, result: PlanLibrary | Invalid) -> dict[str, Any]:
        """Give the team a library, or report files that do not load; returns what happened as JSON data."""
        if isinstance(result, PlanLibrary):
            try:
                digest = self.team.reload(result)
            except AlicaError as exc:
                result = Invalid((str(exc),))
            else:
                for offer in self.offers:
                    offer(result)
                return {"ok": True, "digest": digest}
        event = invalid_event(self.team.now(), result)
        for observer in self.observers:
            observer(event)
        return {"ok": False, "errors": list(result.errors)}


def print_reloads(event: dict[str, Any]) -> None:
    """A trace observer that prints reload events on standard error (:func:`reload_line`)."""
    line = reload_line(event)
    if line is not None:
        print(f"{event.get('t', 0.0):8.2f} s  {line}", file=sys.stderr, flush=True)


def add_watch_option(parser: Any, what: str) -> None:
    """The ``--watch`` option of ``alica run`` and ``alica agent``."""
    parser.add_argument(
        "--watch",
        action="store_true",
        help=f"watch the plan files: when one changes, load and validate the set again; {what}",
    )
