"""Team messages over zenoh between agent processes on loopback: latency, throughput, CPU, death detection, partitions, soak.

Every agent is an OS process (multiprocessing ``spawn``) with its own
:class:`~alica.comm.zenoh_transport.ZenohTransport` on a loopback endpoint.
Topology: a **full mesh of explicit links**: agent ``i`` listens on its own
endpoint and connects to every earlier agent's endpoint (peer mode, no
scouting, no gossip, so no other routes exist); in the partition part every
link goes through its own :class:`~alica.comm.relay.LinkRelay` in the parent.

An agent ticks at 30 Hz and sleeps between ticks, as an engine does: each
tick it polls once, publishes a best-effort team message of about 300 bytes
(``("team", time.time(), sender, seq, padding)``) on ``alica/team``, and every
10th tick a reliable one on ``alica/world``. Latency is ``time.time()`` at the
receiver minus the stamp in the payload (all processes read one host clock):

* **at poll**: when the receiver's tick drained it; includes up to one tick
  (33 ms) of waiting for the poll, plus any lateness of the tick;
* **at arrival**: when the zenoh callback thread took the decoded frame in
  (the bench subclasses the transport and stamps inside its private
  ``_receive`` hook; the transport exposes no receive time). Reliable
  messages recovered from a sender's history arrive through another path and
  are not in the arrival figures.

Parts (``--parts``, all by default):

1. ``team``: latency and CPU/RSS per process for teams of ``--sizes`` agents,
   over plain TCP links and over the team's credentials (``--tls``, both by
   default, run back to back per team size: tcp, tls, tcp, tls... with
   ``--repeat``): TLS links with mutual authentication and zenoh's access
   control (:meth:`alica.comm.credentials.TeamKeys.zenoh_settings`), with
   keys made once per run in a temporary folder; the ``link`` column says
   which.
2. ``throughput``: one publisher process sends 1 KB payloads as fast as it
   can for ``--flood`` seconds, reliable and best-effort, to 1 and 3
   receiver processes that poll at 30 Hz; reliable loss and order checked.
   The in-memory SimNetwork in one process is the reference line.
3. ``kill``: ``kill -9`` of one agent of 5; the time until each survivor's
   ``peers()`` no longer lists it (survivors check ``peers()`` every 1 ms
   between ticks); the victim is restarted before the next repetition.
4. ``partition``: 4 agents, reliable message every tick, links
   {a00,a01} | {a02,a03} cut for ``--cut`` seconds then healed; the time from
   the heal until every reliable message sent across the cut meanwhile was
   delivered (polled), with count and order checks.
5. ``soak``: ``--soak-agents`` agents for ``--soak`` seconds: reliable loss
   and order, RSS every 10 s, latency spikes over 50 ms.

The other parts run over plain TCP.

Run: ``.venv/bin/python bench/transport.py [--quick] [--parts team,throughput,kill,partition,soak] [--soak 600]
[--tls off|on|both] [--repeat N]``
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import multiprocessing.connection as mpc
import os
import statistics
import sys
import tempfile
import time
import traceback
from array import array
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from alica.comm.transport import QoS

TEAM = "alica/team"
WORLD = "alica/world"
PAD = "x" * 250
KB = "x" * 1000
SPIKE = 0.050
WARMUP = 2.0
"""Seconds after an agent's first tick before latencies are recorded (spikes are counted from the first tick)."""
CTX = mp.get_context("spawn")


@dataclass(frozen=True)
class Spec:
    """What one agent process does."""

    name: str
    listen: str
    connect: tuple[str, ...]
    expect: tuple[str, ...]
    team: str = "bench"
    role: str = "agent"  # "agent" | "flood" | "sink"
    rate: float = 30.0
    reliable_every: int = 10
    duration: float = 10.0
    drain: float = 2.0
    watch: float = 0.0
    rss_every: float = 10.0
    keep_log: bool = False
    reliable: bool = True
    phase: float = 0.0
    """Seconds after the common start at which this agent's ticks begin (agents are not in step)."""
    keys: str = ""
    """The folder of the team's credentials: TLS links with mutual authentication and access control ("": plain TCP)."""


# ---------------------------------------------------------------------------------------------- in the agent process


def _rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _stamped_transport(spec: Spec) -> Any:
    """A ZenohTransport that also stamps each frame when the zenoh thread takes it in."""
    from alica.comm.zenoh_transport import ZenohTransport

    class Stamped(ZenohTransport):
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            self.arr_team = array("d")
            self.arr_world = array("d")
            self.arrived = 0
            self.first_arrival = 0.0
            self.last_arrival = 0.0
            self.spikes: list[tuple[float, float, str, str]] = []
            self.measure_from = float("inf")
            super().__init__(*args, **kwargs)

        def _receive(self, frame: Any) -> str | None:
            now = time.time()
            lat = now - frame[6]
            self.arrived += 1
            if not self.first_arrival:
                self.first_arrival = now
            self.last_arrival = now
            if frame[6] < self.measure_from:
                pass
            elif frame[2] == TEAM:
                self.arr_team.append(lat)
            elif frame[2] == WORLD:
                self.arr_world.append(lat)
            if lat > SPIKE and frame[6] >= self.measure_from - WARMUP:
                self.spikes.append((now, lat, frame[1], frame[2]))
            return super()._receive(frame)

    config = None
    if spec.keys:
        from alica.comm.credentials import TeamKeys

        config = TeamKeys.load(spec.keys, spec.name).zenoh_settings(spec.team)
    return Stamped(spec.name, listen=[spec.listen], connect=list(spec.connect), team=spec.team, config=config)


def _child(spec: Spec, conn: Any, start_at: Any, stop: Any) -> None:
    transport = None
    try:
        transport = _stamped_transport(spec)
        transport.subscribe(TEAM)
        transport.subscribe(WORLD)
        deadline = time.time() + 60.0
        while not set(spec.expect) <= transport.peers():
            if time.time() > deadline:
                raise TimeoutError(f"{spec.name} saw {sorted(transport.peers())} of {sorted(spec.expect)} in 60 s")
            time.sleep(0.01)
        conn.send(("ready", spec.name, time.time()))
        while start_at.value == 0.0 and not stop.value:
            time.sleep(0.005)
        t0 = max(start_at.value + spec.phase, time.time())
        transport.measure_from = start_at.value + WARMUP
        time.sleep(max(0.0, t0 - time.time()))
        run = {"agent": _run_agent, "flood": _run_flood, "sink": _run_sink}[spec.role]
        result = run(spec, transport, conn, stop, t0)
        result["zenoh"] = asdict(transport.stats)
        conn.send(("result", spec.name, result))
    except BaseException:
        try:
            conn.send(("error", spec.name, traceback.format_exc()))
        except Exception:
            pass
    finally:
        if transport is not None:
            transport.close()
        conn.close()


class _Checker:
    """Per-sender order of the reliable payloads a receiver polled."""

    def __init__(self) -> None:
        self.last: dict[str, int] = {}
        self.count: dict[str, int] = {}
        self.gaps = 0
        self.dups = 0

    def take(self, sender: str, seq: int) -> None:
        last = self.last.get(sender, 0)
        if seq <= last:
            self.dups += 1
            return
        self.gaps += seq - last - 1
        self.last[sender] = seq
        self.count[sender] = self.count.get(sender, 0) + 1


def _run_agent(spec: Spec, transport: Any, conn: Any, stop: Any, t0: float) -> dict[str, Any]:
    period = 1.0 / spec.rate
    end = t0 + spec.duration
    poll_team, poll_world = array("d"), array("d")
    checker = _Checker()
    log: list[tuple[str, int, float, float]] = []
    rss = [(0.0, _rss())]
    next_rss = t0 + spec.rss_every
    known = transport.peers()
    sent_team = sent_world = 0
    max_late = 0.0
    late_ticks = 0
    ticks = 0
    cpu0 = os.times()
    cpu_frac = 0.0
    drain_until = 0.0
    next_t = t0

    def check_peers() -> None:
        nonlocal known
        now_peers = transport.peers()
        if now_peers != known:
            conn.send(("peers", spec.name, time.time(), tuple(known - now_peers), tuple(now_peers - known)))
            known = now_peers

    while True:
        now = time.time()
        if not drain_until and (now >= end or stop.value):
            c = os.times()
            cpu_frac = (c.user + c.system - cpu0.user - cpu0.system) / max(1e-9, now - t0)
            drain_until = now + spec.drain
        if drain_until and now >= drain_until:
            break
        late = now - next_t
        max_late = max(max_late, late)
        late_ticks += late > 0.010
        measure = now >= transport.measure_from
        for env in transport.poll():
            payload = env.payload
            lat = now - payload[1]
            if env.topic == TEAM:
                if measure:
                    poll_team.append(lat)
            elif env.topic == WORLD:
                if measure:
                    poll_world.append(lat)
                checker.take(env.sender, payload[3])
                if spec.keep_log:
                    log.append((env.sender, payload[3], payload[1], now))
        if not drain_until:
            sent_team += 1
            transport.publish(TEAM, ("team", time.time(), spec.name, sent_team, PAD))
            if spec.reliable_every and ticks % spec.reliable_every == 0:
                sent_world += 1
                transport.publish(WORLD, ("world", time.time(), spec.name, sent_world, PAD), QoS.RELIABLE)
        check_peers()
        if now >= next_rss:
            rss.append((now - t0, _rss()))
            next_rss += spec.rss_every
        ticks += 1
        next_t += period
        if next_t < time.time() - period:  # more than a tick behind: do not catch up in a burst
            next_t = time.time()
        while True:
            rem = next_t - time.time()
            if rem <= 0:
                break
            if spec.watch:
                time.sleep(min(rem, spec.watch))
                check_peers()
            else:
                time.sleep(rem)
    rss.append((time.time() - t0, _rss()))
    return {
        "sent_team": sent_team,
        "sent_world": sent_world,
        "poll_team": poll_team.tobytes(),
        "poll_world": poll_world.tobytes(),
        "arr_team": transport.arr_team.tobytes(),
        "arr_world": transport.arr_world.tobytes(),
        "spikes": transport.spikes,
        "received": dict(checker.count),
        "gaps": checker.gaps,
        "dups": checker.dups,
        "log": log,
        "rss": rss,
        "cpu": cpu_frac,
        "ticks": ticks,
        "max_late": max_late,
        "late_ticks": late_ticks,
        "t0": t0,
    }


def _run_flood(spec: Spec, transport: Any, conn: Any, stop: Any, t0: float) -> dict[str, Any]:
    qos = QoS.RELIABLE if spec.reliable else QoS.BEST_EFFORT
    rss0 = _rss()
    end = t0 + spec.duration
    sent = 0
    cpu0 = os.times()
    now = time.time()
    while now < end:
        for _ in range(100):
            sent += 1
            transport.publish(WORLD, (now, sent, KB), qos)
        now = time.time()
    c = os.times()
    return {
        "sent": sent,
        "wall": now - t0,
        "cpu": (c.user + c.system - cpu0.user - cpu0.system) / (now - t0),
        "rss0": rss0,
        "rss1": _rss(),
    }


def _run_sink(spec: Spec, transport: Any, conn: Any, stop: Any, t0: float) -> dict[str, Any]:
    period = 1.0 / spec.rate
    checker = _Checker()
    delivered = 0
    first = last = 0.0
    idle_since = 0.0
    next_t = t0
    while True:
        now = time.time()
        got = transport.poll()
        if got:
            delivered += len(got)
            first = first or now
            last = now
            idle_since = 0.0
            for env in got:
                checker.take(env.sender, env.payload[1])
        elif stop.value:
            idle_since = idle_since or now
            if now - idle_since >= spec.drain:
                break
        next_t += period
        time.sleep(max(0.0, next_t - time.time()))
    return {
        "delivered": delivered,
        "first": first,
        "last": last,
        "arrived": transport.arrived,
        "first_arrival": transport.first_arrival,
        "last_arrival": transport.last_arrival,
        "received": dict(checker.count),
        "gaps": checker.gaps,
        "dups": checker.dups,
        "t0": t0,
    }


# ---------------------------------------------------------------------------------------------- in the parent


@dataclass
class Team:
    """Agent processes, their pipes, and what they reported."""

    start_at: Any = field(default_factory=lambda: CTX.RawValue("d", 0.0))
    stop: Any = field(default_factory=lambda: CTX.RawValue("i", 0))
    procs: dict[str, Any] = field(default_factory=dict)
    conns: dict[Any, str] = field(default_factory=dict)
    ready: dict[str, float] = field(default_factory=dict)
    events: list[tuple[str, float, tuple[str, ...], tuple[str, ...]]] = field(default_factory=list)
    results: dict[str, dict[str, Any]] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)

    def spawn(self, spec: Spec) -> None:
        reader, writer = CTX.Pipe(duplex=False)
        proc = CTX.Process(target=_child, args=(spec, writer, self.start_at, self.stop), name=spec.name, daemon=True)
        proc.start()
        writer.close()
        self.procs[spec.name] = proc
        self.conns[reader] = spec.name
        self.ready.pop(spec.name, None)

    def pump(self, timeout: float) -> None:
        if not self.conns:
            time.sleep(timeout)
            return
        for reader in mpc.wait(list(self.conns), timeout):
            try:
                msg = reader.recv()
            except (EOFError, OSError):
                del self.conns[reader]  # type: ignore[arg-type]
                continue
            kind, name = msg[0], msg[1]
            if kind == "ready":
                self.ready[name] = msg[2]
            elif kind == "peers":
                self.events.append((name, msg[2], msg[3], msg[4]))
            elif kind == "result":
                self.results[name] = msg[2]
            elif kind == "error":
                self.errors[name] = msg[2]

    def wait_until(self, done: Any, timeout: float) -> bool:
        end = time.time() + timeout
        while not done():
            if self.errors:
                raise RuntimeError(
                    "agent failed: " + "; ".join(f"{n}: {e.strip().splitlines()[-1]}" for n, e in self.errors.items())
                )
            if time.time() > end:
                return False
            self.pump(min(0.05, max(0.0, end - time.time())))
        return True

    def begin(self, names: list[str], timeout: float = 90.0) -> float:
        if not self.wait_until(lambda: set(names) <= set(self.ready), timeout):
            raise RuntimeError(f"not ready after {timeout:g} s: {sorted(set(names) - set(self.ready))}")
        t0 = time.time() + 0.5
        self.start_at.value = t0
        return t0

    def finish(self, names: list[str], timeout: float) -> None:
        """Stop the agents, gather the results of ``names``; every process ends, however."""
        self.stop.value = 1
        try:
            self.wait_until(lambda: set(names) <= set(self.results) | set(self.errors), timeout)
        finally:
            self.shutdown()

    def shutdown(self) -> None:
        self.stop.value = 1
        for proc in self.procs.values():
            proc.join(timeout=5.0)
        for proc in self.procs.values():
            if proc.is_alive():
                proc.terminate()
                proc.join(timeout=2.0)
            if proc.is_alive():
                proc.kill()
                proc.join(timeout=2.0)
        for reader in self.conns:
            reader.close()
        self.conns.clear()


def _mesh(names: list[str], team: str, *, aligned: bool = False, keys: str = "", **kw: Any) -> list[Spec]:
    """Full-mesh specs: agent ``i`` listens on its endpoint and connects to every earlier one's.

    Unless ``aligned``, agent ``i`` ticks ``i / n`` of a tick after agent 0 (robots are not in step).
    With ``keys`` (the folder of the team's credentials), the links are TLS.
    """
    from alica.comm.credentials import tls_endpoint
    from alica.comm.zenoh_transport import free_endpoints

    endpoints = free_endpoints(len(names))
    if keys:
        endpoints = [tls_endpoint(e) for e in endpoints]
    return [
        Spec(
            name,
            endpoints[i],
            tuple(endpoints[:i]),
            tuple(n for n in names if n != name),
            team=team,
            phase=0.0 if aligned else i / len(names) / kw.get("rate", 30.0),
            keys=keys,
            **kw,
        )
        for i, name in enumerate(names)
    ]


def _floats(results: list[dict[str, Any]], key: str) -> list[float]:
    out = array("d")
    for r in results:
        out.frombytes(r[key])
    return sorted(out)


def _pct(data: list[float], q: float) -> float:
    if not data:
        return float("nan")
    return data[min(len(data) - 1, int(q * len(data)))]


def _ms(data: list[float]) -> str:
    if not data:
        return "-"
    return f"{_pct(data, 0.5) * 1e3:.2f} / {_pct(data, 0.99) * 1e3:.2f} / {data[-1] * 1e3:.1f}"


def _mb(n: float) -> str:
    return f"{n / 2**20:.1f}"


def _reliable_check(results: dict[str, dict[str, Any]]) -> tuple[int, int, int, int]:
    """(delivered, expected, gaps, duplicates) of the reliable team messages, over every receiver."""
    sent = {n: r["sent_world"] for n, r in results.items()}
    delivered = expected = gaps = dups = 0
    for name, r in results.items():
        for sender, count in sent.items():
            if sender != name:
                expected += count
                delivered += r["received"].get(sender, 0)
        gaps += r["gaps"]
        dups += r["dups"]
    return delivered, expected, gaps, dups


def _zsum(results: dict[str, dict[str, Any]], key: str) -> int:
    return sum(r["zenoh"][key] for r in results.values())


def _names(size: int) -> list[str]:
    return [f"a{i:02d}" for i in range(size)]


def run_team(
    size: int, duration: float, *, team: str = "t", rss_every: float = 10.0, aligned: bool = False, keys: str = ""
) -> dict[str, dict[str, Any]]:
    """Run ``size`` agents for ``duration`` seconds; with ``keys`` (a folder made by ``make_keys`` for their names) over TLS."""
    names = _names(size)
    link = "tls" if keys else "tcp"
    specs = _mesh(
        names, f"{team}{size}{int(aligned)}{link}", duration=duration, rss_every=rss_every, aligned=aligned, keys=keys
    )
    box = Team()
    try:
        for spec in specs:
            box.spawn(spec)
        box.begin(names)
        box.wait_until(lambda: False, duration + 0.5)
        box.finish(names, 30.0 + size)
    finally:
        box.shutdown()
    if box.errors:
        raise RuntimeError("; ".join(f"{n}: {e.strip().splitlines()[-1]}" for n, e in box.errors.items()))
    return box.results


def part_team(sizes: list[int], duration: float, aligned: list[int], tls: str = "off", repeat: int = 1) -> None:
    from alica.comm.credentials import make_keys

    links = {"off": ["tcp"], "on": ["tls"], "both": ["tcp", "tls"]}[tls]
    print(f"\n## 1+3. Team messages at 30 Hz between agent processes ({duration:g} s per team size, full mesh)\n")
    print("latency in ms as p50 / p99 / max; 'at poll' includes waiting for the receiver's next tick (up to 33 ms);")
    print(
        "ticks: 'staggered' = agent i ticks i/n of a tick after agent 0; 'in step' = every agent ticks at the same instant;"
    )
    print(
        "link: 'tcp' = plain TCP; 'tls' = the team's credentials (TLS with mutual authentication, zenoh access control)\n"
    )
    print(
        "| agents | ticks | link | team msgs polled | team at arrival | team at poll | reliable at arrival | reliable at poll "
        "| reliable delivered / expected, gaps, dups | arrival > 50 ms | CPU per process mean / max | "
        "RSS per process MB (end, max) | ticks late > 10 ms, max late ms |"
    )
    print("|---:|---|---|---:|---|---|---|---|---|---:|---|---|---|")
    runs = [(n, False) for n in sizes if n > 0] + [(n, True) for n in aligned if n > 0]  # (0: none)
    with tempfile.TemporaryDirectory(prefix="alica-bench-keys-") as tmp:
        keys = ""
        if "tls" in links and runs:
            keys = os.path.join(tmp, "keys")
            make_keys(keys, _names(max(n for n, _ in runs)))
        figures: dict[tuple[int, bool, str], list[dict[str, float]]] = {}
        for size, in_step in runs:
            for _ in range(repeat):
                for link in links:
                    row = _team_row(size, duration, in_step, link, keys if link == "tls" else "")
                    if row is not None:
                        figures.setdefault((size, in_step, link), []).append(row)
    print(
        "\nCPU: user+sys time of the whole process (zenoh's threads included) over the publishing window / wall time; "
        f"the machine has {os.cpu_count()} cores shared by all the processes."
    )
    if len(links) == 2:
        _tls_cost(runs, figures)


def _tls_cost(runs: list[tuple[int, bool]], figures: dict[tuple[int, bool, str], list[dict[str, float]]]) -> None:
    """The cost of TLS per team size: tls against tcp, means over the runs of each."""
    print("\nTLS against plain TCP, means over the runs of each link (tls - tcp; CPU also in % of tcp's):\n")
    print(
        "| agents | ticks | runs tcp, tls | CPU per process % | team at arrival p50 ms | team at arrival p99 ms "
        "| reliable at arrival p50 ms | reliable at arrival p99 ms | team at poll p50 ms | team at poll p99 ms "
        "| RSS per process MB |"
    )
    print("|---:|---|---|---|---|---|---|---|---|---|---|")
    for size, in_step in runs:
        tcp, tls = figures.get((size, in_step, "tcp"), []), figures.get((size, in_step, "tls"), [])
        if not tcp or not tls:
            continue
        cells = []
        for key in ("cpu", "arr50", "arr99", "rel50", "rel99", "poll50", "poll99", "rss"):
            a, b = statistics.mean(r[key] for r in tcp), statistics.mean(r[key] for r in tls)
            cell = f"{a:.2f} -> {b:.2f} ({b - a:+.2f}"
            cell += f", {(b - a) / a * 100:+.0f} %)" if key == "cpu" and a else ")"
            cells.append(cell)
        print(f"| {size} | {'in step' if in_step else 'staggered'} | {len(tcp)}, {len(tls)} | {' | '.join(cells)} |")


def _team_row(size: int, duration: float, in_step: bool, link: str, keys: str) -> dict[str, float] | None:
    """Run one team and print its row of the table of :func:`part_team`; its main figures (``None``: it failed)."""
    phase = "in step" if in_step else "staggered"
    try:
        res = run_team(size, duration, aligned=in_step, keys=keys)
    except Exception as exc:
        print(f"| {size} | {phase} | {link} | failed: {exc} |", flush=True)
        return None
    rs = list(res.values())
    team_poll = _floats(rs, "poll_team")
    arrival = _floats(rs, "arr_team")
    d, e, g, u = _reliable_check(res)
    cpu = [r["cpu"] * 100 for r in rs]
    rss_end = [r["rss"][-1][1] for r in rs]
    spikes = sum(len(r["spikes"]) for r in rs)
    print(
        f"| {size} | {phase} | {link} | {len(team_poll)} | {_ms(arrival)} | {_ms(team_poll)} | {_ms(_floats(rs, 'arr_world'))} | "
        f"{_ms(_floats(rs, 'poll_world'))} | {d} / {e}, {g}, {u} | {spikes} | "
        f"{statistics.mean(cpu):.1f} % / {max(cpu):.1f} % | {_mb(statistics.median(rss_end))}, {_mb(max(rss_end))} | "
        f"{sum(r['late_ticks'] for r in rs)} of {sum(r['ticks'] for r in rs)}, {max(r['max_late'] for r in rs) * 1e3:.1f} |",
        flush=True,
    )
    world = _floats(rs, "arr_world")
    return {
        "cpu": statistics.mean(cpu),
        "arr50": _pct(arrival, 0.5) * 1e3,
        "arr99": _pct(arrival, 0.99) * 1e3,
        "rel50": _pct(world, 0.5) * 1e3,
        "rel99": _pct(world, 0.99) * 1e3,
        "poll50": _pct(team_poll, 0.5) * 1e3,
        "poll99": _pct(team_poll, 0.99) * 1e3,
        "rss": statistics.median(rss_end) / 2**20,
    }


def run_flood(receivers: int, reliable: bool, duration: float) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    names = ["pub"] + [f"sink{i}" for i in range(receivers)]
    specs = _mesh(names, f"f{receivers}{int(reliable)}", duration=duration, drain=1.5, reliable=reliable)
    specs = [replace(specs[0], role="flood")] + [replace(s, role="sink") for s in specs[1:]]
    box = Team()
    try:
        for spec in specs:
            box.spawn(spec)
        box.begin(names)
        box.wait_until(lambda: "pub" in box.results, duration + 30.0)
        box.finish(names, 60.0)
    finally:
        box.shutdown()
    if box.errors or set(box.results) != set(names):
        raise RuntimeError(f"missing results {sorted(set(names) - set(box.results))}; errors {box.errors}")
    return box.results["pub"], [box.results[n] for n in names[1:]]


def simnet_rate(receivers: int, reliable: bool, count: int) -> float:
    from alica.clock import ManualClock
    from alica.comm import SimNetwork

    clock = ManualClock()
    net = SimNetwork(clock)
    pub = net.attach("pub")
    sinks = [net.attach(f"sink{i}") for i in range(receivers)]
    for s in sinks:
        s.subscribe(WORLD)
    qos = QoS.RELIABLE if reliable else QoS.BEST_EFFORT
    got = 0
    start = time.perf_counter()
    for i in range(count // 100):
        for j in range(100):
            pub.publish(WORLD, (0.0, i * 100 + j, KB), qos)
        clock.advance(0.001)
        for s in sinks:
            got += len(s.poll())
    elapsed = time.perf_counter() - start
    return count / elapsed


def part_throughput(duration: float) -> None:
    print(
        f"\n## 2. Messages per second, one publisher process, 1 KB payloads, {duration:g} s, receivers poll at 30 Hz\n"
    )
    print(
        "| qos | receivers | published / s | publisher CPU | publisher RSS MB start -> end | delivered / s per receiver "
        "(at poll) | arrived / s per receiver (zenoh thread) | delivered / sent per receiver | gaps, dups at the app | zenoh recovered, duplicates, queries |"
    )
    print("|---|---:|---:|---:|---|---|---|---|---|---|")
    for reliable in (True, False):
        for receivers in (1, 3):
            qos = "reliable" if reliable else "best-effort"
            try:
                pub, sinks = run_flood(receivers, reliable, duration)
            except Exception as exc:
                print(f"| {qos} | {receivers} | failed: {exc} |", flush=True)
                continue
            rate = pub["sent"] / pub["wall"]
            dps = [s["delivered"] / max(1e-9, s["last"] - s["t0"]) for s in sinks]
            aps = [s["arrived"] / max(1e-9, s["last_arrival"] - s["t0"]) for s in sinks]
            gaps = (
                f"{sum(s['gaps'] for s in sinks)}, {sum(s['dups'] for s in sinks)}" if reliable else "- (latest value)"
            )
            print(
                f"| {qos} | {receivers} | {rate:,.0f} | {pub['cpu'] * 100:.0f} % | {_mb(pub['rss0'])} -> {_mb(pub['rss1'])} | "
                f"{', '.join(f'{x:,.0f}' for x in dps)} | {', '.join(f'{x:,.0f}' for x in aps)} | "
                f"{', '.join(str(s['delivered']) + ' / ' + str(pub['sent']) for s in sinks)} | "
                f"{gaps} | {sum(s['zenoh']['recovered'] for s in sinks)}, "
                f"{sum(s['zenoh']['duplicates'] for s in sinks)}, {sum(s['zenoh']['queries'] for s in sinks)} |",
                flush=True,
            )
    print()
    print("reference, in-memory SimNetwork in one process (publish + poll, 1 KB payload by reference, 1 ms steps):\n")
    print("| qos | receivers | published / s | deliveries / s |")
    print("|---|---:|---:|---:|")
    for reliable in (True, False):
        for receivers in (1, 3):
            rate = simnet_rate(receivers, reliable, 200_000)
            qos = "reliable" if reliable else "best-effort"
            print(f"| {qos} | {receivers} | {rate:,.0f} | {rate * receivers:,.0f} |", flush=True)
    print(
        "\nbest-effort keeps the latest value per sender and topic: a receiver polling at 30 Hz is handed one "
        "message per tick; 'arrived' counts what reached its zenoh thread."
    )


def part_kill(size: int, reps: int) -> None:
    print(f"\n## 4. kill -9 of one agent of {size} (30 Hz, full mesh) until the survivors' peers() drop it\n")
    names = [f"a{i:02d}" for i in range(size)]
    specs = {s.name: s for s in _mesh(names, "k", duration=1e6, watch=0.001)}
    box = Team()
    rows: list[tuple[int, str, list[float], float]] = []
    try:
        for spec in specs.values():
            box.spawn(spec)
        box.begin(names)
        box.wait_until(lambda: False, 1.0)
        for rep in range(reps):
            victim = names[1 + rep % (size - 1)]
            survivors = [n for n in names if n != victim]
            mark = len(box.events)
            t_kill = time.time()
            box.procs[victim].kill()

            def gone(mark: int = mark, victim: str = victim, survivors: list[str] = survivors) -> bool:
                seen = {e[0] for e in box.events[mark:] if victim in e[2]}
                return set(survivors) <= seen

            box.wait_until(gone, 10.0)
            detect = {}
            for name, t, lost, _ in box.events[mark:]:
                if victim in lost and name not in detect:
                    detect[name] = t - t_kill
            box.procs[victim].join(timeout=2.0)
            mark = len(box.events)
            t_restart = time.time()
            box.spawn(specs[victim])

            def back(mark: int = mark, victim: str = victim, survivors: list[str] = survivors) -> bool:
                seen = {e[0] for e in box.events[mark:] if victim in e[3]}
                return victim in box.ready and set(survivors) <= seen

            box.wait_until(back, 30.0)
            rejoin = max((e[1] for e in box.events[mark:] if victim in e[3]), default=float("nan")) - t_restart
            rows.append((rep + 1, victim, [detect.get(n, float("nan")) for n in survivors], rejoin))
            box.wait_until(lambda: False, 1.0)
    except Exception as exc:
        print(f"failed: {exc}")
    finally:
        box.finish(list(box.procs), 30.0)
    print(
        "| repetition | victim | detected by survivors, ms: min / median / max | restarted process seen by all after, s |"
    )
    print("|---:|---|---|---:|")
    every: list[float] = []
    for rep, victim, times, rejoin in rows:
        ok = sorted(t for t in times if t == t)
        every += ok
        missing = len(times) - len(ok)
        cell = f"{ok[0] * 1e3:.1f} / {statistics.median(ok) * 1e3:.1f} / {ok[-1] * 1e3:.1f}" if ok else "-"
        print(f"| {rep} | {victim} | {cell}{f' ({missing} never)' if missing else ''} | {rejoin:.2f} |")
    if every:
        every.sort()
        print(
            f"\nall {len(every)} detections: median {statistics.median(every) * 1e3:.1f} ms, max {every[-1] * 1e3:.1f} ms "
            "(survivors check peers() every ~1 ms; the restart time includes spawning Python and importing zenoh)"
        )


def part_partition(reps: int, cut: float, recover: float) -> None:
    from alica.comm.relay import LinkRelay

    print(
        f"\n## 5. Partition {{a00,a01}} | {{a02,a03}} for {cut:g} s, then heal (4 agents, reliable message every tick)\n"
    )
    names = [f"a{i:02d}" for i in range(4)]
    side = {"a00": 0, "a01": 0, "a02": 1, "a03": 1}
    base = _mesh(names, "p", duration=1e6, reliable_every=1, keep_log=True, drain=3.0)
    relays: dict[tuple[str, str], LinkRelay] = {}
    specs = []
    for j, spec in enumerate(base):
        connect = []
        for i in range(j):
            relay = relays[(names[i], names[j])] = LinkRelay(base[i].listen)
            connect.append(relay.endpoint)
        specs.append(replace(spec, connect=tuple(connect)))
    crossing = [r for (a, b), r in relays.items() if side[a] != side[b]]
    box = Team()
    windows: list[tuple[float, float]] = []
    try:
        for spec in specs:
            box.spawn(spec)
        box.begin(names)
        box.wait_until(lambda: False, 2.0)
        for _ in range(reps):
            t_cut = time.time()
            for relay in crossing:
                relay.cut()
            box.wait_until(lambda: False, cut)
            t_heal = time.time()
            for relay in crossing:
                relay.heal()
            windows.append((t_cut, t_heal))
            box.wait_until(lambda: False, recover)
        box.finish(names, 30.0)
    except Exception as exc:
        print(f"failed: {exc}")
    finally:
        box.shutdown()
        for relay in relays.values():
            relay.close()
    res = box.results
    if set(res) != set(names):
        print(f"missing results: {sorted(set(names) - set(res))}; errors: {box.errors}")
        return
    print(
        "| repetition | reliable msgs sent across the cut while cut | delivered | heal -> all delivered (at poll), s | "
        "heal -> links back (peers() again), s: median / max |"
    )
    print("|---:|---:|---:|---:|---|")
    recs: list[float] = []
    for k, (t_cut, t_heal) in enumerate(windows):
        sent = delivered = 0
        last_poll = 0.0
        for name, r in res.items():
            for sender, _seq, stamp, polled in r["log"]:
                if side[sender] != side[name] and t_cut <= stamp < t_heal:
                    delivered += 1
                    last_poll = max(last_poll, polled)
        # what was sent: each sender's log line count seen by a same-side receiver is the truth of how many it sent
        for sender in names:
            mate = next(n for n in names if n != sender and side[n] == side[sender])
            sent_in = sum(1 for s, _, stamp, _ in res[mate]["log"] if s == sender and t_cut <= stamp < t_heal)
            sent += sent_in * 2  # two receivers on the other side
        nxt = windows[k + 1][0] if k + 1 < len(windows) else float("inf")
        backs = [t - t_heal for _, t, _, joined in box.events if joined and t_heal <= t < nxt]
        rec = last_poll - t_heal
        recs.append(rec)
        back_cell = f"{statistics.median(backs):.2f} / {max(backs):.2f}" if backs else "-"
        print(f"| {k + 1} | {sent} | {delivered} | {rec:.2f} | {back_cell} |")
    d, e, g, u = _reliable_check(res)
    print(
        f"\nwhole run: reliable delivered {d} of {e} expected, gaps {g}, duplicates at the app {u}; "
        f"zenoh recovered {_zsum(res, 'recovered')}, dropped duplicates {_zsum(res, 'duplicates')}, "
        f"lost {_zsum(res, 'lost')}, queries {_zsum(res, 'queries')}"
    )
    print(
        "'sent while cut' counts what same-side receivers got from each sender in the window (x2 receivers "
        "across); zenoh reconnects with a retry period of 0.1 s doubling to 1 s."
    )


def part_soak(size: int, duration: float) -> None:
    print(f"\n## 6. Soak: {size} agent processes at 30 Hz for {duration:g} s (full mesh)\n")
    try:
        res = run_team(size, duration, team="s", rss_every=10.0)
    except Exception as exc:
        print(f"failed: {exc}")
        return
    rs = list(res.values())
    d, e, g, u = _reliable_check(res)
    arrival = _floats(rs, "arr_team")
    poll = _floats(rs, "poll_team")
    growth = []
    for r in rs:
        samples = r["rss"]
        base = next((b for t, b in samples if t >= 10.0), samples[0][1])
        growth.append((samples[0][1], base, samples[-1][1], max(b for _, b in samples)))
    print("| figure | value |")
    print("|---|---|")
    print(f"| reliable delivered / expected | {d} / {e} |")
    print(f"| reliable gaps, duplicates (per-sender sequence at the receiver) | {g}, {u} |")
    print(
        f"| zenoh recovered, duplicates, lost, queries, undecodable | {_zsum(res, 'recovered')}, "
        f"{_zsum(res, 'duplicates')}, {_zsum(res, 'lost')}, {_zsum(res, 'queries')}, {_zsum(res, 'undecodable')} |"
    )
    print(f"| team msgs polled | {len(poll)} |")
    print(f"| team latency at arrival p50 / p99 / max ms | {_ms(arrival)} |")
    print(f"| team latency at poll p50 / p99 / max ms | {_ms(poll)} |")
    print(f"| reliable latency at poll p50 / p99 / max ms | {_ms(_floats(rs, 'poll_world'))} |")
    print(f"| arrivals > 50 ms (team + reliable) | {sum(len(r['spikes']) for r in rs)} |")
    print(f"| team msgs at poll > 50 ms / > 100 ms | {sum(x > 0.05 for x in poll)} / {sum(x > 0.1 for x in poll)} |")
    print(
        f"| ticks late > 10 ms, max tick lateness ms | {sum(r['late_ticks'] for r in rs)} of {sum(r['ticks'] for r in rs)}, {max(r['max_late'] for r in rs) * 1e3:.1f} |"
    )
    cpu = [r["cpu"] * 100 for r in rs]
    print(f"| CPU per process mean / max | {statistics.mean(cpu):.1f} % / {max(cpu):.1f} % |")
    print(
        f"| RSS MB at start, median (min - max) | {_mb(statistics.median(x[0] for x in growth))} ({_mb(min(x[0] for x in growth))} - {_mb(max(x[0] for x in growth))}) |"
    )
    print(f"| RSS MB at 10 s, median | {_mb(statistics.median(x[1] for x in growth))} |")
    print(
        f"| RSS MB at end, median (min - max) | {_mb(statistics.median(x[2] for x in growth))} ({_mb(min(x[2] for x in growth))} - {_mb(max(x[2] for x in growth))}) |"
    )
    print(
        f"| RSS growth 10 s -> end, MB per process: median / max | {_mb(statistics.median(x[2] - x[1] for x in growth))} / {_mb(max(x[2] - x[1] for x in growth))} |"
    )
    print(f"| RSS growth 10 s -> max, MB per process: max | {_mb(max(x[3] - x[1] for x in growth))} |")
    print(
        "\nRSS includes this bench's own latency samples (8 bytes per message polled and per message arrived, "
        "about 2.9 MB per process in 600 s) and the transport's reliable history (600 s of its own messages)."
    )
    series = rs[0]["rss"]
    print(
        f"\nRSS of a00 over time (s: MB): {', '.join(f'{t:.0f}: {_mb(b)}' for t, b in series[:: max(1, len(series) // 12)])}"
    )
    spikes = sorted((s for r in rs for s in r["spikes"]), key=lambda s: -s[1])[:10]
    if spikes:
        t0 = rs[0]["t0"]
        print(
            "largest arrival spikes (s after start, ms, sender, topic): "
            + "; ".join(f"{t - t0:.1f}, {lat * 1e3:.0f}, {snd}, {top}" for t, lat, snd, top in spikes)
        )


def _ints(text: str) -> list[int]:
    return [int(s) for s in text.split(",") if s.strip()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="short runs of every part, for a smoke run")
    parser.add_argument("--parts", default="team,throughput,kill,partition,soak", help="comma-separated parts to run")
    parser.add_argument("--sizes", default="3,10,20", help="team sizes of the latency/CPU part (default 3,10,20)")
    parser.add_argument(
        "--in-step", default="10", help="team sizes also run with every agent ticking in step (default 10; 0: none)"
    )
    parser.add_argument("--duration", type=float, default=20.0, metavar="S", help="seconds per team size (default 20)")
    parser.add_argument(
        "--tls",
        choices=("off", "on", "both"),
        default="both",
        help="links of the team part: plain TCP, TLS with the team's credentials, or both back to back (default both)",
    )
    parser.add_argument(
        "--repeat", type=int, default=1, help="runs of each team size and link, interleaved (default 1)"
    )
    parser.add_argument(
        "--flood", type=float, default=5.0, metavar="S", help="seconds of the throughput runs (default 5)"
    )
    parser.add_argument("--reps", type=int, default=5, help="repetitions of kill and partition (default 5)")
    parser.add_argument("--cut", type=float, default=3.0, metavar="S", help="seconds a partition lasts (default 3)")
    parser.add_argument("--soak", type=float, default=600.0, metavar="SECONDS", help="soak length (default 600)")
    parser.add_argument("--soak-agents", type=int, default=10, help="agent processes in the soak (default 10)")
    args = parser.parse_args(argv)
    if args.quick:
        args.sizes, args.duration, args.flood, args.reps, args.soak = "3,10", 5.0, 2.0, 2, min(args.soak, 30.0)
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    import zenoh  # noqa: F401  (fail early when it is missing)

    print(f"# zenoh transport between processes ({os.cpu_count()} cores, Python {sys.version.split()[0]})")
    started = time.time()
    if "team" in parts:
        part_team(_ints(args.sizes), args.duration, _ints(args.in_step), args.tls, max(1, args.repeat))
    if "throughput" in parts:
        part_throughput(args.flood)
    if "kill" in parts:
        part_kill(5, args.reps)
    if "partition" in parts:
        part_partition(args.reps, args.cut, 5.0)
    if "soak" in parts:
        part_soak(args.soak_agents, args.soak)
    print(f"\n(total {time.time() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
