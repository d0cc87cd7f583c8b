"""MAGiC over agent processes: the leader in this process, one worker per process, over zenoh on loopback.

:func:`run_processes` starts n-1 worker processes (``multiprocessing`` with
``spawn``), each with a :class:`~alica.comm.zenoh_transport.ZenohTransport`
that connects to the leader's endpoint, waits until every worker has
subscribed and is reachable, then runs one round on the wall clock and
returns the same :class:`~alica.app.magic.MagicRun` as the lock-step driver.
A worker ends once it has the leader's final (or at its deadline); every
zenoh session is closed, and a worker still running after the round and a
short grace is terminated.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import signal
import time
from collections.abc import Mapping
from dataclasses import dataclass

from alica.app.magic import MagicRun, TransportLink, agent_names
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints
from alica.prophet.magic import MagicLeader, MagicWorker
from alica.prophet.planner import PlanStatus

TEAM = "magic"
"""The zenoh key prefix of a MAGiC team started here."""
GRACE = 2.0
"""Seconds the workers get after the round to report and leave before they are terminated."""


@dataclass(frozen=True, slots=True)
class _Report:
    """What a worker process sends back over its queue when it leaves."""

    name: str
    sent: int
    received: int
    expansions: int


def _worker(
    name: str, endpoint: str, deadline_s: float, memory_mb: float | None, progress_every: int, out: queue.Queue
) -> None:
    """A worker process: search the share it gets until the final, then report its counts."""
    end = time.monotonic() + deadline_s
    with ZenohTransport(name, connect=[endpoint], team=TEAM) as transport:
        worker = MagicWorker(TransportLink(transport), memory_mb=memory_mb, progress_every=progress_every)
        out.put(("ready", name))
        while worker.final is None and time.monotonic() < end:
            worker.step(1)
            if not worker.searching:
                time.sleep(0.001)  # waiting for a message: do not spin
        out.put(_Report(name, worker.counts.sent, worker.counts.received, worker.expansions))


def run_processes(
    domain: str,
    problem: str,
    agents: int,
    *,
    seed: int = 0,
    seconds: float | None = None,
    timeout: float = 60.0,
    memory_mb: float | None = None,
    progress_every: int = 50,
    kill_after: Mapping[str, float] | None = None,
) -> MagicRun:
    """One MAGiC round over ``agents`` processes (this one the leader) linked by zenoh on loopback.

    Args:
        domain: the PDDL domain text.
        problem: the PDDL problem text.
        agents: the team size n (the leader included; n-1 processes are started).
        seed: the seed of the shares' tie-breaking.
        seconds: each share's time budget in wall seconds; ``None``: ``timeout``.
        timeout: wall seconds for the whole run, the start of the processes included;
            reached, the run ends with ``TIMEOUT``.
        memory_mb: each agent's memory bound for its search; ``None``: none.
        progress_every: expansions between two planner events.
        kill_after: faults: ``kill -9`` of a worker process (``agent2``, ...) this many
            seconds after the round started.

    Returns:
        The run; ``first_plan_s`` counts from the round's start (the processes are up by then).

    Raises:
        ValueError: ``agents < 1``.
        PddlError: the domain or the problem is not valid PDDL.
    """
    names = agent_names(agents)
    wall = time.perf_counter()
    end = time.monotonic() + timeout
    [endpoint] = free_endpoints(1)
    context = multiprocessing.get_context("spawn")
    out = context.Queue()
    processes = [
        context.Process(
            target=_worker, args=(name, endpoint, timeout, memory_mb, progress_every, out), name=f"magic-{name}"
        )
        for name in names[1:]
    ]
    reports: dict[str, _Report] = {}
    try:
        with ZenohTransport(names[0], listen=[endpoint], team=TEAM) as transport:
            link = TransportLink(transport)
            leader = MagicLeader(
                link, domain, problem, seed=seed, seconds=seconds or timeout, memory_mb=memory_mb,
                progress_every=progress_every,
            )  # fmt: skip
            for process in processes:
                process.start()
            ready: set[str] = set()
            while time.monotonic() < end and (ready < set(names[1:]) or not link.reachable() >= set(names[1:])):
                try:
                    _kind, name = out.get(timeout=0.05)  # ("ready", name): the only message before the round
                except queue.Empty:
                    continue
                ready.add(name)
            leader.start(names)
            started = time.monotonic()
            kills = sorted((at, name) for name, at in (kill_after or {}).items())
            outcome = None
            while outcome is None and time.monotonic() < end:
                while kills and time.monotonic() - started >= kills[0][0]:
                    _, name = kills.pop(0)
                    victim = processes[names.index(name) - 1]
                    if victim.pid is not None:
                        os.kill(victim.pid, signal.SIGKILL)
                outcome = leader.step(1)
                if outcome is None and leader.idle:
                    time.sleep(0.001)  # waiting for the teammates: leave the interpreter to zenoh's threads
            grace = min(end, time.monotonic() + GRACE)
            while len(reports) < len(processes) and time.monotonic() < grace:
                try:
                    item = out.get(timeout=0.05)
                except queue.Empty:
                    continue
                if isinstance(item, _Report):
                    reports[item.name] = item
            leader_sent, leader_received = leader.counts.sent, leader.counts.received
    finally:
        for process in processes:
            process.join(timeout=max(0.0, min(GRACE, end - time.monotonic())))
            if process.is_alive():
                process.terminate()
                process.join(timeout=1.0)
        out.close()
    return MagicRun(
        status=outcome.status if outcome else PlanStatus.TIMEOUT,
        plan=outcome.plan if outcome else None,
        agents=agents,
        messages=leader_sent + sum(r.sent for r in reports.values()),
        received=leader_received + sum(r.received for r in reports.values()),
        solver=outcome.solver if outcome else None,
        search=str(outcome.search) if outcome and outcome.search else None,
        lost=outcome.lost if outcome else (),
        first_plan_s=outcome.seconds if outcome and outcome.plan is not None else None,
        first_plan_tick=None,
        ticks=0,
        expansions=(outcome.expansions if outcome else 0) + sum(r.expansions for r in reports.values()),
        wall_s=time.perf_counter() - wall,
        outcome=outcome,
    )
