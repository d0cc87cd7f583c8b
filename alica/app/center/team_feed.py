"""The control center of a team of processes: ``alica center --team ENDPOINT`` and ``alica run --processes --center``.

The agents (``alica agent``) publish their trace events on zenoh and answer a
question for their history (:mod:`alica.comm.center_feed`); this module
connects that to the same :class:`~alica.app.center.live.LiveHub` and page
a simulated run serves:

* :class:`TeamFeed` opens a :class:`~alica.comm.center_feed.CenterLink` to
  the team, hands every agent's history (once, when it is first seen, and
  again for a restarted agent) and then its events to the hub. Events of
  several agents come **in arrival order**, not sorted by time: the team's
  view folds them agent by agent, each agent's own in its order; the events
  of an agent seen late come as one block after the others' live ones.
* :class:`RemoteTeam` is what the operator's actions act on: it checks them
  like a simulated team does, publishes them to the agents (each applies them
  between two ticks on its own thread) and puts the ``operator`` event into
  the hub. Its reload sends ``{"what": "reload"}``: each agent loads its own
  files again and proposes them to its team. Where the center can read the
  plan files too (``alica run --processes --center``; ``alica center --team`` when
  the header's plan file loads), it loads them itself
  and offers the library to the hub, so the page's plan trees follow once the
  agents' events say they adopted it; the :class:`CommandLoop` loads them again
  when the agents adopt a library the center was not offered (``--watch``).
* :func:`serve_team` is ``alica center --team``: it waits (bounded) for a
  first agent to answer, serves the page, and runs the operator's actions
  and the clock until Ctrl-C or SIGTERM.

Time is seconds since the team's start, as the agents count it (the
``--start-at`` every agent of a team shares, sent with its history).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from alica.app.center.live import LiveHub, wait_for_stop
from alica.app.center.team_view import TeamView
from alica.engine import PlanDecision
from alica.errors import AlicaError
from alica.lang.walk import literal_text
from alica.model import PlanLibrary
from alica.model.digest import library_digest

if TYPE_CHECKING:
    from alica.app.plan_watch import Invalid, PlanWatch
    from alica.comm.credentials import TeamKeys

TICK = 0.1
"""Wall seconds between two turns of the loop that runs the operator's actions and moves the clock on."""
JOIN_WAIT = 10.0
"""Seconds ``alica center --team`` waits for a first agent to answer before it gives up."""


def _texts(facts: Iterable[tuple[bool, str, tuple[object, ...]]]) -> list[str]:
    return [literal_text(p, n, a) for p, n, a in facts]


class RemoteTeam:
    """The operator's side of a team of processes: what ``hub.run_commands`` calls (as on a simulated team).

    Args:
        feed: the team's feed (its link publishes, its hub takes the ``operator`` events).
        problems: the planning problems the plan file has (``None``: the plan file did not load;
            then the agents alone check the problem's name).
        plans: the team's plan files as this process reads them (``None``: it does not; a reload then
            leaves the page's plan trees as they are).
    """

    def __init__(self, feed: TeamFeed, problems: Iterable[str] | None, plans: PlanWatch | None = None) -> None:
        self.feed = feed
        self.problems = None if problems is None else set(problems)
        self.plans = plans

    def now(self) -> float:
        """Seconds since the team's start."""
        return self.feed.now()

    def _send(self, command: dict[str, Any]) -> None:
        link = self.feed.link
        if link is None or not link.alive:
            raise AlicaError("no agent of the team is reached: the command would go nowhere")
        link.send(command)

    def _check(self, problem: str) -> None:
        if self.problems is not None and problem not in self.problems:
            raise AlicaError(
                f"no planning problem named '{problem}'; problems: {', '.join(sorted(self.problems)) or 'none'}"
            )

    def set_goal(self, problem: str, goal: str) -> None:
        """Every agent sets the goal of ``problem``: the leader replans (see ``SimulatedTeam.set_goal``)."""
        self._check(problem)
        self._send({"what": "goal", "problem": problem, "goal": goal})
        self._operator("goal", problem=problem, goal=goal)

    def set_facts(self, facts: Iterable[tuple[bool, str, tuple[object, ...]]], *, by_operator: bool = False) -> None:
        """Every agent sets the facts ``(positive, predicate, args)`` in its world model."""
        facts = [(bool(p), str(n), tuple(a)) for p, n, a in facts]
        self._send({"what": "facts", "facts": [[p, n, list(a)] for p, n, a in facts]})
        if by_operator:
            self._operator("facts", facts=_texts(facts))
        else:
            self.feed.put({"t": round(self.now(), 6), "agent": "-", "event": "operator", "facts": _texts(facts)})

    def decide_plan(self, problem: str, generation: int, decision: PlanDecision) -> None:
        """Every agent learns the decision on the plan of ``generation`` (see ``SimulatedTeam.decide_plan``)."""
        self._check(problem)
        if not isinstance(decision, PlanDecision):
            raise TypeError(f"a plan decision is a PlanDecision, not {decision!r}")
        details = decision.describe()
        self._send({"what": "decision", "problem": problem, "generation": int(generation), **details})
        self._operator(str(details.pop("action")), problem=problem, generation=generation, **details)

    def reload(self) -> dict[str, Any]:
        """Every agent loads its plan files again and proposes them to its team (the operator's reload action).

        Returns:
            What the plan files are as this process reads them: ``{"ok": True, "digest": ...}`` (offered to the
            hub: the page's plan trees switch when the agents adopt it), ``{"ok": False, "errors": [...]}``
            (each agent reports its own in a ``reload`` event), or ``{"ok": True, "digest": None}`` when this
            process does not read them; ``sent`` names the agents the command went to.

        Raises:
            AlicaError: no agent of the team is reached.
        """
        self._send({"what": "reload"})
        self._operator("reload")
        sent = sorted(self.feed.link.alive)
        loaded = self.load_plans()
        if loaded is None:
            return {"ok": True, "digest": None, "sent": sent}
        if isinstance(loaded, PlanLibrary):
            return {"ok": True, "digest": library_digest(loaded), "sent": sent}
        return {"ok": False, "errors": list(loaded.errors), "sent": sent}

    def load_plans(self) -> PlanLibrary | Invalid | None:
        """Load the plan files as this process reads them; a valid library is offered to the hub.

        Returns:
            The library, what is wrong with the files (:class:`~alica.app.plan_watch.Invalid`), or ``None``
            when this process does not read them.
        """
        if self.plans is None:
            return None
        loaded = self.plans.reload()
        hub = self.feed.hub
        if isinstance(loaded, PlanLibrary) and hub is not None:
            hub.offer(loaded)
        return loaded

    def _operator(self, what: str, **fields: Any) -> None:
        self.feed.put({"t": round(self.now(), 6), "agent": "operator", "event": "operator", "what": what, **fields})


class TeamFeed:
    """A team of processes' events into a hub (see the module docstring).

    Args:
        connect: agents' listen endpoints.
        prefix: the team's key prefix.
        start: the team's start (seconds since the epoch) when known, else taken from the first history.
        keys: the team's credentials as the center's identity (TLS, and signed operator's commands).
    """

    def __init__(
        self, connect: Iterable[str], prefix: str, start: float | None = None, *, keys: TeamKeys | None = None
    ) -> None:
        self.connect = tuple(connect)
        self.prefix = prefix
        self.keys = keys
        self.start = start
        self.hub: LiveHub | None = None
        self.link: Any = None
        self.header: dict[str, Any] | None = None
        self.seen: set[str] = set()
        """Agents whose history came."""
        self._lock = threading.Lock()
        self._pending: list[dict[str, Any]] = []
        self._first = threading.Event()

    # -- the link's side (zenoh's threads) ------------------------------------------

    def open(self) -> None:
        """Open the link to the team.

        Raises:
            AlicaError: no agent listens at the endpoints, or a bad prefix.
        """
        from alica.comm.center_feed import CenterLink

        try:
            config = self.keys.zenoh_settings(self.prefix) if self.keys is not None else None
            self.link = CenterLink(
                self.connect, self.prefix, self._history, self._event, self._gone, config=config, keys=self.keys
            )
        except ValueError as exc:
            raise AlicaError(f"cannot reach the team at {', '.join(self.connect)}: {exc}") from None

    def _history(self, answer: dict[str, Any]) -> None:
        name = str(answer["agent"])
        header = answer.get("header")
        with self._lock:
            if self.start is None and isinstance(answer.get("start"), (int, float)):
                self.start = float(answer["start"])
            if self.header is None and isinstance(header, dict):
                self.header = {k: v for k, v in header.items() if k != "recorder"}
            again = name in self.seen
            self.seen.add(name)
        t = round(self.now(), 6)
        lead = f"a new process of {name}: its history again" if again else f"{name}'s history"
        dropped = int(answer.get("dropped") or 0)
        count = len(answer["events"])
        note = f"{lead}: {count} event{'s' * (count != 1)}" + (
            f" (its first {dropped} are no longer kept)" if dropped else ""
        )
        self.put({"t": t, "agent": "-", "event": "note", "message": note})
        for event in answer["events"]:
            if isinstance(event, dict):
                self.put(event)
        self._first.set()

    def _event(self, name: str, event: dict[str, Any]) -> None:
        self.put(event)

    def _gone(self, name: str) -> None:
        if name in self.seen:
            message = f"{name}'s liveliness token is gone: its process ended, or it is cut off"
            self.put({"t": round(self.now(), 6), "agent": "-", "event": "note", "message": message})

    def put(self, event: dict[str, Any]) -> None:
        """One event into the hub (held until the hub exists)."""
        with self._lock:
            hub = self.hub
            if hub is None:
                self._pending.append(event)
                return
        hub(event)

    # -- the center's side ---------------------------------------------------------

    def wait_first(self, timeout: float) -> bool:
        """Wait until some agent's history came (at most ``timeout`` seconds); whether one did."""
        return self._first.wait(timeout)

    def attach(self, hub: LiveHub) -> None:
        """Hand the events so far, then every new one, to ``hub``."""
        with self._lock:
            self.hub = hub
            pending, self._pending = self._pending, []
            for event in pending:  # under the lock: nothing overtakes what was held
                hub(event)

    def now(self) -> float:
        """Seconds since the team's start (0 until it is known)."""
        return 0.0 if self.start is None else time.time() - self.start

    def close(self) -> None:
        """Close the link."""
        if self.link is not None:
            self.link.close()


def load_problems(header: Mapping[str, Any], skills: Sequence[str] = ()) -> tuple[Any, list[str]]:
    """The plan library the header's plan files make, and notes on what did not load.

    The files are looked for as the agents' command lines named them, from the current folder
    (:func:`~alica.app.center.plan_view.plan_candidates`), and loaded with the skill modules and
    plan folders the header records plus ``skills`` (:func:`~alica.app.trace_sources.viewer_sources`).

    Raises:
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    from alica.app.center.plan_view import _load_library
    from alica.app.trace_sources import viewer_sources

    files = header.get("plans")
    if not isinstance(files, list) or not files:
        return None, ["the agents' header names no plan file: the operator can plan for no problem"]
    sources = viewer_sources(header, skills)
    library, why = _load_library(str(files[0]), Path.cwd() / "team", sources.loader)
    if library is None:
        return None, [*sources.notes, f"{why}; the operator can plan for no problem"]
    return library, sources.notes


def header_plans(
    header: Mapping[str, Any], library: PlanLibrary | None, skills: Sequence[str] = ()
) -> PlanWatch | None:
    """The plan file the agents' header names, as :func:`load_problems` found it, for the reload action.

    ``None`` when it did not load (``library`` is ``None``): the reload then only goes to the agents.

    Raises:
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    from alica.app.center.plan_view import find_plan_file
    from alica.app.plan_watch import PlanWatch
    from alica.app.trace_sources import viewer_sources

    files = header.get("plans")
    if library is None or not isinstance(files, list) or not files:
        return None
    path, _ = find_plan_file(str(files[0]), Path.cwd() / "team")
    if path is None:
        return None
    sources = viewer_sources(header, skills)
    return PlanWatch(path, library, lambda: sources.loader().load(path))


class CommandLoop:
    """A thread that runs the operator's queued actions on a :class:`RemoteTeam` and moves the pages' clock on.

    When the agents adopt a library the hub was not offered (they reloaded on their own, ``--watch``), it
    loads the plan files once for that digest (:meth:`RemoteTeam.load_plans`), so the trees follow.
    """

    def __init__(self, hub: LiveHub, team: RemoteTeam) -> None:
        self.hub = hub
        self.team = team
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name="alica-center-commands", daemon=True)
        self._looked: str | None = None

    def _run(self) -> None:
        while not self.stop.wait(TICK):
            self.hub.run_commands(self.team)
            self.hub.tick(self.team.now())
            missing = self.hub.missing()
            if missing is not None and missing != self._looked:
                self._looked = missing
                self.team.load_plans()

    def start(self) -> CommandLoop:
        self.thread.start()
        return self

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=2.0)


def start_live(
    feed: TeamFeed,
    header: dict[str, Any],
    library: Any,
    host: str,
    port: int,
    token: str,
    out: TextIO,
    skills: Sequence[str] = (),
    plans: PlanWatch | None = None,
) -> tuple[LiveHub, Any, CommandLoop]:
    """Serve the live page for ``feed``'s team: the hub (fed from then on), the server, the loop of commands.

    Args:
        skills: skill modules to load the plan trees with besides those the header records (``--skills``).
        plans: the team's plan files as this process reads them (:class:`RemoteTeam`'s ``plans``).
    """
    from alica.app.center.operator import problems
    from alica.app.center.plan_view import entry_states, trace_trees
    from alica.app.center.server import live_app, serve_in_thread
    from alica.app.trace_sources import viewer_sources

    known = problems(library) if library is not None else {}
    hub = LiveHub(header, TeamView(header, entries=entry_states([library] if library is not None else [])), library)
    sources = viewer_sources(header, skills)
    if plans is not None and library is not None:  # this process started the team: the plans as it loaded them
        trees = trace_trees(header, Path.cwd() / "team", loaded=([library], []))
    else:  # the plan files as the agents named them
        trees = trace_trees(header, Path.cwd() / "team", sources.loader)
    trees["notes"] = [*sources.notes, *trees["notes"]]
    remote = RemoteTeam(feed, known if library is not None else None, plans)
    server = serve_in_thread(
        live_app(hub, known, token, trees, reload=lambda team: team.reload()), host, port, token, out
    )
    feed.attach(hub)
    loop = CommandLoop(hub, remote).start()
    return hub, server, loop


def serve_team(
    connect: Iterable[str],
    prefix: str,
    host: str,
    port: int,
    token: str,
    *,
    wait: float = JOIN_WAIT,
    out: TextIO = sys.stdout,
    skills: Sequence[str] = (),
    keys: TeamKeys | None = None,
) -> None:
    """``alica center --team``: serve the live page of a running team of processes until Ctrl-C or SIGTERM.

    Args:
        skills: skill modules to load besides those the agents' header records (``--skills``).
        keys: the team's credentials as the center's identity (``--team-keys``).

    Raises:
        AlicaError: nothing listens at the endpoints, or no agent with the key prefix answered within ``wait`` s.
    """
    feed = TeamFeed(connect, prefix, keys=keys)
    feed.open()
    try:
        if not feed.wait_first(wait):
            seen = sorted(feed.link.alive)
            why = (
                f"agents {', '.join(seen)} are there but none answered (agents started with --no-center-feed?)"
                if seen
                else f"no agent with the key prefix '{prefix}' is there (the agents' --key-prefix)"
            )
            raise AlicaError(f"no agent of the team answered within {wait:g} s at {', '.join(feed.connect)}: {why}")
        assert feed.header is not None
        header = dict(feed.header)
        library, notes = load_problems(header, skills)
        plans = header_plans(header, library, skills)
        hub, server, loop = start_live(feed, header, library, host, port, token, out, skills, plans)
        for note in notes:
            hub({"t": round(feed.now(), 6), "agent": "-", "event": "note", "message": note})
            print(f"alica center: {note}", file=sys.stderr, flush=True)
        try:
            wait_for_stop()
        finally:
            loop.close()
            server.should_exit = True
    finally:
        feed.close()
