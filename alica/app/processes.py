"""``alica run --processes``: one ``alica agent`` process per agent on loopback, with faults and one summary.

Each agent is a new Python interpreter running ``alica agent`` (never a
fork of this process, which may hold zenoh sessions: a forked child of a
process with a session hangs). Agent ``i`` listens on its own loopback
port and connects to every earlier agent: a full mesh of explicit zenoh
links, no scouting. With ``--partition``, every link goes through its own
:class:`~alica.comm.relay.LinkRelay`, and a partition cuts the relays
between the groups; the host's network is never touched.

Faults happen at wall seconds after the team's start: ``--crash NAME@T``
is a ``kill -9`` of the agent's process, ``--recover NAME@T`` starts it
again (a new incarnation with an empty memory, which catches up from its
teammates). The run ends when every agent that has not crashed has
finished its root plan, at ``--time-limit``, or on Ctrl-C; then every
process gets SIGTERM, prints its summary and exits.

The agents do not outlive this process. Each one's standard input is a
pipe this process never writes to, and the agent watches it
(``alica agent --parent-pipe 0``): when this process is gone, even by
``kill -9``, the pipe reaches end of file and the agent stops. With a
``deadline`` each agent also gets ``--time-limit`` of the run's deadline
plus :data:`DEADLINE_MARGIN`, so it ends by itself even when this process
is alive but cannot stop it (frozen, say).
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Literal

from alica.app.plan_watch import reload_line
from alica.comm.faults import describe_fault
from alica.comm.relay import LinkRelay
from alica.comm.zenoh_transport import free_endpoints
from alica.errors import AlicaError

POLL = 0.05
"""Seconds between two looks at the agents and the faults due."""
STOP_GRACE = 10.0
"""Seconds an agent process has to exit after SIGTERM before it is killed."""
DEADLINE_MARGIN = 5.0
"""Seconds past the run's deadline at which an agent ends by itself: after this process has stopped it, normally."""

#: A fault of :meth:`ProcessTeam.run`, ``(t, kind, what)`` with ``t`` in seconds since the start:
#: ``(t, "crash", name)``, ``(t, "recover", name)``, ``(t, "partition", (groups, start, end))`` or ``(t, "heal", None)``.
Fault = (
    tuple[float, Literal["crash", "recover"], str]
    | tuple[float, Literal["partition"], tuple[list[list[str]], float, float | None]]
    | tuple[float, Literal["heal"], None]
)


@dataclass
class _Agent:
    """One agent of the team and its current process."""

    name: str
    index: int
    listen: str
    connect: list[str]
    process: subprocess.Popen[str] | None = None
    incarnation: int = 0
    status: str = "starting"
    summaries: list[dict[str, Any]] = field(default_factory=list)
    reloads: list[dict[str, Any]] = field(default_factory=list)
    """The agent's reload events (``alica agent --watch``), as its lines said them."""
    traces: list[Path] = field(default_factory=list)
    log: IO[str] | None = None
    reader: threading.Thread | None = None


class ProcessTeam:
    """A team of ``alica agent`` processes on loopback.

    Args:
        plan: the plan file every agent runs.
        agents: the roster, as ``--agents`` of ``alica run`` gives it.
        names: the agents' names, in roster order.
        options: more ``alica agent`` options for every agent (``--stand-ins``, ``--fact``, ...).
        workdir: where the agents' traces and logs go.
        relays: link the agents through relays, so that :meth:`partition` can cut them.
        own: more options for single agents, by name (one robot's operator, say).
        deadline: the run's end in seconds after the start (``max_time`` of :meth:`run`); each
            agent gets ``--time-limit`` of it plus :data:`DEADLINE_MARGIN`. ``None``: the agents
            get none from here (``options`` may give one).
        tls: the agents' links are TLS (``tls/`` endpoints; ``options`` give ``--team-keys``).
    """

    def __init__(
        self,
        plan: str,
        agents: str,
        names: Sequence[str],
        options: Sequence[str],
        workdir: Path,
        *,
        relays: bool = False,
        own: dict[str, list[str]] | None = None,
        deadline: float | None = None,
        tls: bool = False,
        per_incarnation: Callable[[str, int], list[str]] | None = None,
    ) -> None:
        self.plan = plan
        self.per_incarnation = per_incarnation
        """Options of an agent's process that change with each start (``--record``'s folder), by name and count."""
        self.deadline = deadline
        self.roster = agents
        self.options = list(options)
        self.own = dict(own or {})
        self.workdir = workdir
        self.start = time.time()
        self.faults: list[dict[str, Any]] = []
        self.on_fault: Callable[[dict[str, Any]], None] | None = None
        """Called with each fault's trace event as it happens (the control center's hub)."""
        self._lock = threading.Lock()
        self.relays: dict[tuple[str, str], LinkRelay] = {}
        endpoints = free_endpoints(len(names))
        if tls:
            from alica.comm.credentials import tls_endpoint

            endpoints = [tls_endpoint(endpoint) for endpoint in endpoints]
        self.agents: dict[str, _Agent] = {}
        for index, name in enumerate(names):
            connect = []
            for earlier, endpoint in zip(names[:index], endpoints[:index], strict=True):
                if relays:
                    relay = self.relays[(earlier, name)] = LinkRelay(endpoint)
                    connect.append(relay.endpoint)
                else:
                    connect.append(endpoint)
            self.agents[name] = _Agent(name, index, endpoints[index], connect)

    # -- processes ------------------------------------------------------------

    def launch(self) -> None:
        """Start every agent's process; the team's clock starts now."""
        self.start = time.time()
        for agent in self.agents.values():
            self._spawn(agent)

    def _spawn(self, agent: _Agent) -> None:
        agent.incarnation += 1
        trace = self.workdir / f"{agent.name}.{agent.incarnation}.jsonl"
        agent.traces.append(trace)
        argv = [
            sys.executable,
            "-m",
            "alica.app.cli",
            "agent",
            self.plan,
            "--name",
            agent.name,
            "--agents",
            self.roster,
            "--listen",
            agent.listen,
            *(arg for endpoint in agent.connect for arg in ("--connect", endpoint)),
            "--start-at",
            repr(self.start),
            "--trace",
            str(trace),
            "--json",
            *self.options,
            *self.own.get(agent.name, ()),
            *(self.per_incarnation(agent.name, agent.incarnation) if self.per_incarnation is not None else ()),
            "--parent-pipe",
            "0",  # its standard input: end of file when this process is gone
        ]
        if self.deadline is not None:
            argv += ["--time-limit", repr(self.deadline + DEADLINE_MARGIN)]
        agent.log = (self.workdir / f"{agent.name}.{agent.incarnation}.log").open("w", encoding="utf-8")
        agent.process = subprocess.Popen(
            argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=agent.log, text=True, bufsize=1
        )
        agent.status = "starting"
        agent.reader = threading.Thread(target=self._read, args=(agent, agent.process), daemon=True)
        agent.reader.start()

    def _read(self, agent: _Agent, process: subprocess.Popen[str]) -> None:
        assert process.stdout is not None
        for line in process.stdout:
            try:
                record = json.loads(line)
            except json.JSONDecodeError:
                continue
            with self._lock:
                if agent.process is not process:
                    continue  # a line of an earlier incarnation
                if record.get("event") == "started":
                    agent.status = "running"
                elif record.get("event") == "status":
                    agent.status = str(record.get("status"))
                elif record.get("event") == "summary":
                    agent.summaries.append(record)
                elif record.get("event") == "reload":
                    agent.reloads.append(record)
                    said = reload_line(record)
                    if said is not None:
                        print(f"{record.get('t', 0.0):8.2f} s  {said}", file=sys.stderr, flush=True)

    def run(
        self,
        faults: Sequence[Fault],
        max_time: float,
        *,
        on_started: Callable[[int, float], None] | None = None,
    ) -> None:
        """Apply ``faults`` at their times until every running agent finished, ``max_time``, or nobody is left.

        Args:
            faults: ``(t, kind, what)`` in seconds since the start: ``("crash", name)``,
                ``("recover", name)``, ``("partition", (groups, start, end))`` or ``("heal", None)``.
            max_time: seconds since the start at most.
            on_started: called once with the number of agents and the time, when every
                agent process has started (reported its first line).
        """
        pending = sorted(faults, key=lambda fault: fault[0])
        announced = on_started is None
        while not self.done() and self.now() < max_time:
            while pending and self.now() >= pending[0][0]:
                fault = pending.pop(0)
                if fault[1] == "crash":
                    self.crash(fault[2])
                elif fault[1] == "recover":
                    self.recover(fault[2])
                elif fault[1] == "partition":
                    self.partition(*fault[2])
                else:
                    self.heal()
            self.exited()
            if not announced and all(a.status != "starting" for a in self.agents.values()):
                announced = True
                assert on_started is not None
                on_started(len(self.agents), self.now())
            if self.all_down() and not any(kind == "recover" for _, kind, _ in pending):
                return  # nobody left, and nobody comes back
            time.sleep(POLL)

    def now(self) -> float:
        """Seconds since the team's start."""
        return time.time() - self.start

    def crash(self, name: str) -> None:
        """``kill -9`` the agent's process."""
        agent = self._agent(name)
        if agent.process is None or agent.status == "crashed":
            return
        at = self.now()  # the kill's time: teammates may see the process gone before it is reaped
        with contextlib.suppress(ProcessLookupError):
            os.kill(agent.process.pid, signal.SIGKILL)
        agent.process.wait()
        _close_pipe(agent.process)
        with self._lock:
            agent.status = "crashed"
        self._fault("crash", at=at, agent=name)

    def recover(self, name: str) -> None:
        """Start a crashed agent's process again."""
        agent = self._agent(name)
        if agent.status != "crashed":
            return
        self._spawn(agent)
        self._fault("recover", agent=name)

    def partition(self, groups: Iterable[Iterable[str]], start: float, end: float | None) -> None:
        """Cut the relays between groups (agents not listed form one more group)."""
        groups = [sorted(group) for group in groups]
        group_of = {name: i for i, group in enumerate(groups) for name in group}
        for name in group_of:
            self._agent(name)
        rest = len(groups)
        for (a, b), relay in self.relays.items():
            if group_of.get(a, rest) != group_of.get(b, rest):
                relay.cut()
        self._fault("partition", groups=groups, start=start, end=end)

    def heal(self) -> None:
        """Let every relay forward again."""
        for relay in self.relays.values():
            relay.heal()
        self._fault("heal")

    def exited(self) -> list[str]:
        """Agents whose process ended by itself (not a crash we made); they count as crashed from then on."""
        gone = []
        with self._lock:
            for agent in self.agents.values():
                process = agent.process
                if process is not None and agent.status not in ("crashed", "exited") and process.poll() is not None:
                    agent.status = "exited"
                    gone.append(agent.name)
        return gone

    def all_down(self) -> bool:
        """Whether no agent process runs (every one crashed or exited)."""
        with self._lock:
            return all(a.status in ("crashed", "exited") for a in self.agents.values())

    def done(self) -> bool:
        """Whether every agent that runs has finished its root plan."""
        with self._lock:
            live = [a for a in self.agents.values() if a.status not in ("crashed", "exited")]
            return bool(live) and all(a.status in ("success", "failure") for a in live)

    def stop(self) -> None:
        """SIGTERM every process (each prints its summary), then kill what is left; close the relays."""
        running = [a for a in self.agents.values() if a.process is not None and a.process.poll() is None]
        for agent in running:
            assert agent.process is not None
            with contextlib.suppress(ProcessLookupError):
                agent.process.send_signal(signal.SIGTERM)
        end = time.monotonic() + STOP_GRACE
        for agent in running:
            assert agent.process is not None
            try:
                agent.process.wait(timeout=max(0.1, end - time.monotonic()))
            except subprocess.TimeoutExpired:
                agent.process.kill()
                agent.process.wait()
        for agent in self.agents.values():
            if agent.process is not None:
                _close_pipe(agent.process)  # after the SIGTERM: the agents' summaries say "stopped"
            if agent.reader is not None:
                agent.reader.join(timeout=5.0)
            if agent.log is not None:
                agent.log.close()
        for relay in self.relays.values():
            relay.close()

    def _agent(self, name: str) -> _Agent:
        try:
            return self.agents[name]
        except KeyError:
            raise AlicaError(f"no agent named '{name}' in the team; agents: {', '.join(self.agents)}") from None

    def _fault(self, kind: str, at: float | None = None, **fields: object) -> None:
        record = {
            "t": round(self.now() if at is None else at, 3),
            "agent": fields.pop("agent", "-"),
            "event": "fault",
            "fault": kind,
            **fields,
        }
        self.faults.append(record)
        if self.on_fault is not None:
            self.on_fault(dict(record))

    # -- results ------------------------------------------------------------------

    def trace(self, path: Path, header: dict[str, Any] | None = None) -> int:
        """Merge the agents' traces and the faults into one JSON Lines file, by time; returns the events written.

        ``header`` (:func:`alica.engine.trace_header`) goes first; the agents' own headers are left out.
        """
        events: list[dict[str, Any]] = [dict(f) for f in self.faults]
        for agent in self.agents.values():
            for incarnation, file in enumerate(agent.traces, 1):
                if not file.exists():
                    continue
                for line in file.read_text(encoding="utf-8").splitlines():
                    try:
                        event = json.loads(line)
                    except json.JSONDecodeError:
                        continue  # the last line of a process killed while writing
                    if not isinstance(event, dict) or event.get("event") == "trace":
                        continue  # an agent's own header: the merged trace has one for the run
                    event["incarnation"] = incarnation
                    events.append(event)
        events.sort(key=lambda e: float(e.get("t", 0.0)))
        if header is not None:
            events.insert(0, header)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", encoding="utf-8") as out:
            for event in events:
                out.write(json.dumps(event, sort_keys=True, default=str) + "\n")
        return len(events)

    def summary(self, plan: str, seed: int) -> dict[str, Any]:
        """The run's summary, in the shape of the simulated run's (``SimulatedTeam.summary``)."""
        agents: dict[str, Any] = {}
        sent = delivered = lost = undecodable = 0
        digests = {}
        for name, agent in self.agents.items():
            last = agent.summaries[-1] if agent.summaries else None
            status = agent.status if agent.status in ("crashed", "exited") else (last or {}).get("status", "running")
            if last is None:
                why = self._last_log_line(agent)
                agents[name] = {"role": "?", "status": status, "tasks": [], "path": "", "reason": why}
                for key in ("ticks", "transitions", "allocations", "messages_in", "messages_out", "repairs"):
                    agents[name][key] = 0
                continue
            agents[name] = {
                key: last.get(key)
                for key in (
                    "role",
                    "tasks",
                    "path",
                    "ticks",
                    "transitions",
                    "allocations",
                    "messages_in",
                    "messages_out",
                    "repairs",
                    "replans",
                )
                if key in last
            }
            agents[name].update(
                status=status,
                incarnations=agent.incarnation,
                overruns=last.get("overruns", 0),
                cpu_percent=last.get("cpu_percent"),
                world_facts=last.get("world_facts"),
            )
            for summary in agent.summaries:
                counters = summary.get("transport", {})
                sent += int(counters.get("sent", 0))
                delivered += int(counters.get("delivered", 0))
                lost += int(counters.get("lost", 0))
                undecodable += int(counters.get("undecodable", 0))
            if status not in ("crashed", "exited"):
                digests[name] = last.get("world_digest")
        statuses = [a["status"] for a in agents.values() if a["status"] not in ("crashed", "exited")]
        return {
            "plan": plan,
            "seed": seed,
            "clock": "wall",
            "processes": True,
            "ticks": max((a.get("ticks", 0) for a in agents.values()), default=0),
            "sim_time_s": round(self.now(), 3),
            "done": bool(statuses) and all(s in ("success", "failure") for s in statuses),
            "success": bool(statuses) and all(s == "success" for s in statuses),
            "agents": agents,
            # publish calls, then copies per receiver; zenoh counts no loss of its own (it retransmits):
            # a copy is lost for good when its sender no longer had it, or arrives and cannot be decoded
            "messages": {
                "sent": sent,
                "delivered": delivered,
                "dropped_lost": lost,
                "dropped_undecodable": undecodable,
            },
            "world_models_agree": len(set(digests.values())) <= 1,
            "faults": [describe_fault(f) for f in self.faults if f["fault"] != "heal"],
            "reloads": sorted(
                (r for a in self.agents.values() for r in a.reloads),
                key=lambda r: (r.get("t", 0.0), r.get("agent", "")),
            ),
        }

    @staticmethod
    def _last_log_line(agent: _Agent) -> str | None:
        if not agent.traces:
            return None
        log = agent.traces[-1].with_suffix(".log")
        if not log.exists():
            return None
        lines = [line for line in log.read_text(encoding="utf-8").splitlines() if line.strip()]
        return lines[-1] if lines else None


def _close_pipe(process: subprocess.Popen[str]) -> None:
    """Close this end of the agent's parent pipe (its standard input)."""
    if process.stdin is not None:
        with contextlib.suppress(OSError):
            process.stdin.close()
