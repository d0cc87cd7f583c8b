"""The control center's live mode: a running simulated team's events, shared with the web server.

The team runs on the main thread in simulated time, paced to the wall clock
(:meth:`LiveSession.pace` after every tick); the web server runs in a thread of its own with its event
loop (:meth:`LiveSession.start`). :class:`LiveHub` sits between them:

* it is one of the team's observers: every trace event is copied, stamped
  with the wall time it happened at, folded into the team's view (the same
  fold a replay uses, :class:`~alica.app.center.team_view.TeamView`) and
  handed to the server's listeners;
* the operator's actions (a goal, facts, a decision on a proposed plan, a
  reload of the plan files) are callables queued by the server and run by
  :meth:`LiveSession.pace` on the team's thread between two ticks, so the team
  is never touched from two threads;
* it serves the plan trees the pages draw, and follows a hot reload
  (:mod:`alica.engine.reload`): the libraries given to the team are offered
  to it (:meth:`LiveHub.offer`, kept by digest), and when a ``reload`` event
  says an agent ``adopted`` one, the hub serves that library's trees from then
  on and says so in its snapshot (``plans``: the digest whose trees it
  serves), so every page fetches them again and redraws.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import json
import math
import queue
import secrets
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TextIO

from alica.app.center.team_view import TeamView
from alica.app.pacing import WallPace
from alica.errors import AlicaError
from alica.model import PlanLibrary
from alica.model.digest import library_digest

CLOCK_EVERY = 0.2
"""Wall seconds between two updates that only move the pages' clock on (events are pushed as they come)."""

Command = Callable[[Any], Any]
"""An operator's action: called with the team on the team's thread; what it returns goes back to the page."""

KEEP_OFFERED = 8
"""Libraries offered to a hub that it keeps until one is adopted (the newest)."""

NO_TREES: dict[str, Any] = {"trees": {}, "agents": {}, "notes": []}
"""The plan trees a hub serves before it is given any (:meth:`LiveHub.serve_trees`)."""


@dataclass(eq=False)
class Listener:
    """One page's connection: woken (from any thread) when events arrive."""

    loop: asyncio.AbstractEventLoop
    wake: asyncio.Event = field(default_factory=asyncio.Event)
    pending: bool = False


class LiveHub:
    """The events of a running team, for the server (see the module docstring).

    Args:
        header: the run's trace header (:func:`alica.engine.trace_header`): plans, root, agents, world.
        view: the team's state, folded event by event.
        library: the library the team starts with, when known: its digest names the first trees served.
    """

    def __init__(self, header: dict[str, Any], view: TeamView, library: PlanLibrary | None = None) -> None:
        self.header = header
        self.view = view
        self.events: list[dict[str, Any]] = []
        self.walls: list[float] = []
        """The wall time (``time.time()``) at which each event reached the hub."""
        self.status: dict[str, Any] = {"running": True, "t": 0.0, "summary": None}
        self.plans: str | None = library_digest(library) if library is not None else None
        """The digest of the library whose plan trees the hub serves (``None``: the plan files', digest not known);
        the snapshot's ``plans``."""
        self._trees: dict[str, Any] = dict(NO_TREES)
        self._notes: list[str] = []
        self._offered: dict[str, PlanLibrary] = {}
        self._wanted: str | None = None
        self._lock = threading.Lock()
        self._listeners: set[Listener] = set()
        self._commands: queue.Queue[tuple[Command, concurrent.futures.Future[Any]]] = queue.Queue()
        self._snapshot: tuple[tuple[int, float, bool, str | None], str] = ((-1, -1.0, True, None), "")
        self._clock_told = -math.inf

    # -- the team's side -------------------------------------------------

    def __call__(self, event: dict[str, Any]) -> None:
        """Take one event (an observer of the team, on the team's thread)."""
        copy = dict(event)
        with self._lock:
            self.view.apply(copy)
            self.events.append(copy)
            self.walls.append(time.time())
            adopted = copy.get("adopted")
            if copy.get("event") == "reload" and copy.get("status") == "adopted" and isinstance(adopted, str):
                self._adopted(adopted)
        self._wake()

    def offer(self, library: PlanLibrary) -> None:
        """A library given to the team (:attr:`TeamReloads.offers <alica.app.plan_watch.TeamReloads.offers>`):
        its trees are served once an agent says it adopted it (at once, if one said so already)."""
        digest = library_digest(library)
        with self._lock:
            self._offered.pop(digest, None)
            self._offered[digest] = library
            while len(self._offered) > KEEP_OFFERED:
                del self._offered[next(iter(self._offered))]
            if self._wanted == digest:
                self._adopted(digest)
        self._wake(force=True)

    def missing(self) -> str | None:
        """The digest an agent adopted and no library offered has (a team of processes loads it then)."""
        with self._lock:
            return self._wanted

    def _adopted(self, digest: str) -> None:
        """An agent adopted ``digest``: serve its trees if it was offered, else wait for it (under the lock)."""
        if digest == self.plans:
            self._wanted = None
            return
        library = self._offered.get(digest)
        if library is None:
            self._wanted = digest
            return
        from alica.app.center.plan_view import entry_states, trace_trees

        trees = trace_trees(self.header, ".", loaded=([library], []))
        self._trees = {**trees, "notes": [*self._notes, *trees["notes"]]}
        self.view.entries = entry_states([library])
        self.plans = digest
        self._wanted = None

    def tick(self, now: float) -> None:
        """The team's time moved on to ``now``; pages hear of it at most :data:`CLOCK_EVERY` wall seconds apart."""
        with self._lock:
            self.status["t"] = round(now, 6)
        wall = time.monotonic()
        if wall - self._clock_told >= CLOCK_EVERY:
            self._clock_told = wall
            self._wake()

    def finish(self, summary: dict[str, Any]) -> None:
        """The run is over; the page shows the summary. Later operator actions are refused."""
        with self._lock:
            self.status.update(running=False, summary=summary)
        self._wake(force=True)
        while True:  # anything queued meanwhile gets its answer
            try:
                _, future = self._commands.get_nowait()
            except queue.Empty:
                break
            future.set_exception(AlicaError("the run is over"))

    def run_commands(self, team: Any) -> None:
        """Run the operator's queued actions on the team (on the team's thread)."""
        while True:
            try:
                command, future = self._commands.get_nowait()
            except queue.Empty:
                return
            try:
                future.set_result(command(team))
            except AlicaError as exc:
                future.set_exception(exc)

    # -- the server's side -----------------------------------------------

    def serve_trees(self, trees: dict[str, Any]) -> None:
        """The plan trees to serve until a reload (:func:`~alica.app.center.plan_view.trace_trees`'s shape);
        their notes stay with the trees of every later library."""
        with self._lock:
            self._trees = dict(trees)
            self._notes = list(trees.get("notes") or [])

    def trees(self) -> dict[str, Any]:
        """The plan trees served now, with ``plans``: the digest of their library (``None``: not known)."""
        with self._lock:
            return {**self._trees, "plans": self.plans}

    def submit(self, command: Command) -> concurrent.futures.Future[Any]:
        """Queue an operator's action for the team's thread; the future holds its result or its error."""
        future: concurrent.futures.Future[Any] = concurrent.futures.Future()
        with self._lock:
            running = self.status["running"]
        if not running:
            future.set_exception(AlicaError("the run is over: the team takes no more operator actions"))
        else:
            self._commands.put((command, future))
        return future

    def listen(self) -> Listener:
        """A new listener for the calling event loop."""
        listener = Listener(asyncio.get_running_loop())
        with self._lock:
            self._listeners.add(listener)
        return listener

    def forget(self, listener: Listener) -> None:
        """Stop waking ``listener``."""
        with self._lock:
            self._listeners.discard(listener)

    def since(self, count: int) -> tuple[list[dict[str, Any]], list[float], int]:
        """The events after the first ``count``, their wall times, and the number of events now."""
        with self._lock:
            return self.events[count:], self.walls[count:], len(self.events)

    def snapshot_json(self) -> str:
        """The team's state now as JSON (computed once per change, shared by every page)."""
        with self._lock:
            key = (len(self.events), float(self.status["t"]), bool(self.status["running"]), self.plans)
            if self._snapshot[0] != key:
                state = self.view.snapshot()
                state["t"] = max(float(state.get("t") or 0.0), key[1])
                state["status"] = dict(self.status)
                state["plans"] = self.plans
                self._snapshot = (key, json.dumps(state))
            return self._snapshot[1]

    def _wake(self, force: bool = False) -> None:
        with self._lock:
            due = [ear for ear in self._listeners if force or not ear.pending]
            for ear in due:
                ear.pending = True
        for ear in due:
            try:
                ear.loop.call_soon_threadsafe(ear.wake.set)
            except RuntimeError:  # the page's loop is closed: the server is stopping
                self.forget(ear)


class LiveSession:
    """The control center of one simulated run: a hub, the server in its thread, and the pace of the run.

    Args:
        speed: simulated seconds per wall second (``inf``: as fast as the machine allows).
        host: the address to bind.
        port: the port (0 picks a free one).
        token: the access token (default: a new random one).
        out: where the line to open goes.
    """

    def __init__(
        self,
        speed: float = 1.0,
        host: str = "127.0.0.1",
        port: int = 8765,
        token: str | None = None,
        out: TextIO = sys.stdout,
    ) -> None:
        if not speed > 0:
            raise AlicaError(f"the speed must be a positive number of simulated seconds per wall second, got {speed}")
        self.speed = speed
        self.host, self.port = host, port
        self.token = token or secrets.token_urlsafe(24)
        self.out = out
        self.hub: LiveHub | None = None
        self.server: Any = None
        self.reloads: Any = None
        """The run's :class:`~alica.app.plan_watch.TeamReloads`: the page's reload action loads the plan files."""
        self._pace = WallPace(speed)

    def start(self, header: dict[str, Any], library: PlanLibrary) -> LiveHub:
        """Serve the page for a run with this trace header; the hub returned is the run's observer.

        Raises:
            AlicaError: the address cannot be bound.
        """
        from alica.app.center.operator import problems
        from alica.app.center.plan_view import entry_states, trace_trees
        from alica.app.center.server import live_app, serve_in_thread

        self.hub = LiveHub(header, TeamView(header, entries=entry_states([library])), library)
        trees = trace_trees(header, ".", loaded=([library], []))  # the plans the team runs, as this run loaded them
        self.server = serve_in_thread(
            live_app(self.hub, problems(library), self.token, trees, reload=self.reload),
            self.host,
            self.port,
            self.token,
            self.out,
        )
        return self.hub

    def reload(self, team: Any) -> dict[str, Any]:
        """The operator's reload action (on the team's thread): the plan files are loaded again and given to the team.

        Returns:
            ``{"ok": True, "digest": ...}`` (the team adopts the library when every agent has it), or
            ``{"ok": False, "errors": ["file:line:col: ...", ...]}`` (the team goes on with its plans).

        Raises:
            AlicaError: this run has no plan files to load again (a demo builds its plans itself).
        """
        if self.reloads is None:
            raise AlicaError(
                "this run cannot load its plan files again: its plans were not loaded from files the center "
                "watches (alica run PLAN --center can reload)"
            )
        result: dict[str, Any] = self.reloads.reload(by_operator=True)
        return result

    def pace(self, team: Any) -> None:
        """After a tick: the operator's actions run, the page learns the time, the wall clock catches up."""
        assert self.hub is not None, "start() the session first"
        self.hub.run_commands(team)
        now = team.now()
        self.hub.tick(now)
        self._pace(now)

    def finish(self, summary: dict[str, Any]) -> None:
        """The run is over: the page shows ``summary``; then serve until Ctrl-C or SIGTERM."""
        if self.hub is None:
            return
        self.hub.finish(summary)
        print("the run is over; the control center stays up until Ctrl-C", file=sys.stderr, flush=True)
        try:
            wait_for_stop()
        finally:
            self.server.should_exit = True


def wait_for_stop() -> None:
    """Block until SIGTERM or Ctrl-C (the page stays up meanwhile)."""
    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    try:
        while not stop.wait(0.5):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
