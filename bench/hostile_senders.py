"""Memory bound per fake sender: a rogue zenoh session floods an agent with reliable frames of made-up names.

One real agent (an OS process, multiprocessing ``spawn``, with a
:class:`~alica.comm.zenoh_transport.ZenohTransport` named ``real`` listening
on loopback, subscribed to ``news``, polling at 30 Hz) and, in this process, a
rogue raw zenoh session without credentials connected to it
(:func:`alica.comm.zenoh_transport.zenoh_config`, as on a team without
credentials). The rogue sends, from ``N`` fake sender names, well-formed
reliable frames ``(incarnation, sender, topic, seq, rseq, gseq, sent_at,
encode(payload))`` with about 1 KB payloads, numbered from 5: there is a gap
before them, so the agent's :class:`~alica.comm.reliable.Inbox` holds them
(waiting for the sender's history, which never answers) up to its caps:
``max_held`` per sender, ``max_held_total`` in all, ``max_senders`` senders;
a sender quiet for ``quiet`` (10 x the zenoh lease) loses what is held of it.
The frames go round-robin over the senders (every sender is heard until the
end of the flood), each sender sending 10 % more frames than it can have held
(``--over``), so that the caps are met.

Measured: the agent process's RSS (``/proc/PID/statm``) before the flood, at
its peak (sampled during the flood and until the agent took every frame in),
after every sender went quiet (held frames dropped), and after that with
``malloc_trim(0)`` (memory freed but kept by the C allocator is given back);
the frames held, the inbox's ``dropped`` counters (``held``: not held, a cap
met; ``quiet``: dropped with a quiet sender; ``senders``: senders forgotten)
and ``stats.rejected``. Each row is a fresh agent process. The same is run
with ``roster=["real"]``: every fake name is outside the roster and its frames
are dropped at once (counted in ``rejected["roster"]``).

Run: ``.venv/bin/python bench/hostile_senders.py [--senders 1,10,100,1000] [--lease 0.5] [--payload 1000]``
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import os
import sys
import time
from typing import Any

TEAM = "hostile"
TOPIC = "news"
CTX = mp.get_context("spawn")
PAGE = os.sysconf("SC_PAGE_SIZE")
FIRST_RSEQ = 5
"""The first reliable number the rogue sends: 1 to 4 never come, so every frame waits behind a gap."""


def _rss(pid: int) -> int:
    with open(f"/proc/{pid}/statm") as f:
        return int(f.read().split()[1]) * PAGE


# ---------------------------------------------------------------------------------------------- the agent process


def _agent(endpoint: str, roster: bool, lease: float, conn: Any) -> None:
    """The real agent: subscribes to ``news``, polls at 30 Hz, answers the parent's ``state`` / ``trim`` / ``stop``."""
    from alica.comm.zenoh_transport import ZenohTransport

    transport = ZenohTransport("real", listen=[endpoint], team=TEAM, lease=lease, roster=["real"] if roster else None)
    try:
        transport.subscribe(TOPIC)
        conn.send(("ready", os.getpid()))
        delivered = 0
        while True:
            delivered += len(transport.poll())
            if not conn.poll(1 / 30):
                continue
            command = conn.recv()
            if command == "stop":
                break
            if command == "trim":
                import ctypes

                ctypes.CDLL("libc.so.6").malloc_trim(0)
            inbox = transport._inbox  # (private: a bench may look)
            with transport._lock:
                state = {"held": inbox.held, "dropped": dict(inbox.dropped), "senders": len(inbox._senders)}
            state["rejected"] = dict(transport.stats.rejected)
            state["delivered"] = delivered
            conn.send(("state", state))
    finally:
        transport.close()
        conn.close()


# ---------------------------------------------------------------------------------------------- the rogue (parent)


class Agent:
    """The agent process and the pipe to it."""

    def __init__(self, endpoint: str, roster: bool, lease: float) -> None:
        self.conn, child = CTX.Pipe()
        self.proc = CTX.Process(target=_agent, args=(endpoint, roster, lease, child), daemon=True)
        self.proc.start()
        child.close()
        if not self.conn.poll(60.0):
            raise RuntimeError("the agent process did not start in 60 s")
        kind, self.pid = self.conn.recv()
        assert kind == "ready"

    def state(self, command: str = "state") -> dict[str, Any]:
        self.conn.send(command)
        if not self.conn.poll(30.0):
            raise RuntimeError("the agent process did not answer in 30 s")
        return self.conn.recv()[1]

    def rss(self) -> int:
        return _rss(self.pid)

    def stop(self) -> None:
        try:
            self.conn.send("stop")
        except OSError:
            pass
        self.proc.join(timeout=10.0)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(timeout=5.0)
        self.conn.close()


def _taken(state: dict[str, Any]) -> int:
    """The frames the agent took in so far: held, not held (a cap), dropped with a quiet sender, or rejected."""
    return state["held"] + state["dropped"]["held"] + state["dropped"]["quiet"] + sum(state["rejected"].values())


def _wait(agent: Agent, done: Any, timeout: float, every: float = 0.1) -> dict[str, Any]:
    end = time.time() + timeout
    while True:
        state = agent.state()
        if done(state) or time.time() > end:
            return state
        time.sleep(every)


def run_row(senders: int, roster: bool, per_sender: int, lease: float, payload_chars: int) -> dict[str, Any]:
    """Flood one fresh agent process from ``senders`` fake names, ``per_sender`` frames each; what it cost."""
    import zenoh

    from alica.comm.codec import encode
    from alica.comm.zenoh_transport import free_endpoints, zenoh_config

    endpoint = free_endpoints(1)[0]
    agent = Agent(endpoint, roster, lease)
    rogue = zenoh.open(zenoh_config((endpoint,), (), "peer", lease, None))
    try:
        # the link is up and the agent's subscriber known once a bad frame reaches it (rejected, no sender state)
        def reached(state: dict[str, Any]) -> bool:
            if state["rejected"]:
                return True
            rogue.put(f"{TEAM}/m/probe/{TOPIC}", b"junk")
            return False

        if not reached(_wait(agent, reached, 30.0)):
            raise RuntimeError("the rogue's frames never reached the agent")
        time.sleep(0.5)
        probe = agent.state()["rejected"]
        base_rejected = sum(probe.values())
        rss0 = agent.rss()
        names = [f"ghost{i:04d}" for i in range(senders)]
        keys = [f"{TEAM}/m/{name}/{TOPIC}" for name in names]
        data = encode("x" * payload_chars)
        incarnation = time.time_ns()
        block = zenoh.CongestionControl.BLOCK
        peak = rss0
        sent = 0
        t0 = time.time()
        for k in range(per_sender):
            rseq = FIRST_RSEQ + k
            for name, key in zip(names, keys, strict=True):
                frame = encode((incarnation, name, TOPIC, rseq, rseq, rseq, time.time(), data))
                rogue.put(key, frame, congestion_control=block)
                sent += 1
                if sent % 1000 == 0:
                    peak = max(peak, agent.rss())
        flood = time.time() - t0
        last = [-1, time.time()]

        def settled(state: dict[str, Any]) -> bool:
            nonlocal peak
            peak = max(peak, agent.rss())
            taken = _taken(state) - base_rejected
            if taken != last[0]:
                last[:] = [taken, time.time()]
            return taken >= sent or time.time() - last[1] > 2.0

        at_peak = _wait(agent, settled, 60.0, every=0.05)
        took = time.time() - t0
        peak = max(peak, agent.rss())
        quiet = 10.0 * lease
        held_peak = at_peak["held"]
        after = _wait(agent, lambda s: s["held"] == 0 and time.time() - t0 > flood + quiet, quiet + 30.0)
        time.sleep(0.5)
        rss_quiet = agent.rss()
        trimmed = agent.state("trim")
        rss_trim = agent.rss()
        return {
            "senders": senders,
            "roster": roster,
            "sent": sent,
            "flood": flood,
            "took": took,
            "rss0": rss0,
            "peak": peak,
            "quiet": rss_quiet,
            "trim": rss_trim,
            "held": held_peak,
            "state": trimmed,
            "after": after,
            "rejected": {k: v - probe.get(k, 0) for k, v in trimmed["rejected"].items() if v - probe.get(k, 0)},
            "frame_bytes": len(encode((incarnation, names[0], TOPIC, 10**5, 10**5, 10**5, time.time(), data))),
        }
    finally:
        rogue.close()
        agent.stop()


def _mb(n: float) -> str:
    return f"{n / 2**20:.1f}"


def main(argv: list[str] | None = None) -> int:
    from alica.comm.reliable import Inbox

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--senders", default="1,10,100,1000", help="fake sender counts (default 1,10,100,1000)")
    parser.add_argument(
        "--lease", type=float, default=0.5, help="the agent's zenoh lease in s; quiet = 10 x lease (default 0.5)"
    )
    parser.add_argument("--payload", type=int, default=1000, help="characters of each payload (default 1000)")
    parser.add_argument(
        "--over",
        type=float,
        default=1.1,
        help="frames per sender as a multiple of what it can have held (default 1.1: the caps are met)",
    )
    parser.add_argument("--no-roster", action="store_true", help="skip the rows with a roster")
    args = parser.parse_args(argv)
    inbox = Inbox("x")
    max_held, max_total, max_senders = inbox._max_held, inbox._max_held_total, inbox._max_senders
    counts = [int(s) for s in args.senders.split(",") if s.strip()]
    print(
        f"# Fake senders flooding one agent over zenoh on loopback ({os.cpu_count()} cores, Python {sys.version.split()[0]})"
    )
    print(
        f"\ninbox caps: max_held {max_held:,} per sender, max_held_total {max_total:,}, max_senders {max_senders:,}; "
        f"lease {args.lease:g} s, quiet {10 * args.lease:g} s; payload {args.payload} characters; "
        f"frames per sender = {args.over:g} x min(max_held, max_held_total / senders), round-robin, reliable, "
        f"numbered from {FIRST_RSEQ} (a gap)\n"
    )
    print(
        "| roster | fake senders | frames sent (each, bytes) | flood s (taken in by s) | held at peak | "
        "dropped held / quiet / senders | rejected | RSS MB before | RSS growth MB at peak | after quiet | "
        "after quiet + malloc_trim | MB per fake sender at peak | bytes per held frame |"
    )
    print("|---|---:|---|---|---:|---|---|---:|---:|---:|---:|---:|---:|")
    started = time.time()
    rows = []
    for senders in counts:
        per_sender = math.ceil(min(max_held, max_total / senders) * args.over)
        for roster in (False,) if args.no_roster else (False, True):
            try:
                r = run_row(senders, roster, per_sender, args.lease, args.payload)
            except Exception as exc:
                print(f"| {'real' if roster else 'none'} | {senders} | failed: {exc} |", flush=True)
                continue
            rows.append(r)
            s = r["state"]
            d = s["dropped"]
            rejected = r["rejected"]
            growth = r["peak"] - r["rss0"]
            per_frame = f"{growth / r['held']:,.0f}" if r["held"] else "-"
            print(
                f"| {'real' if roster else 'none'} | {senders:,} | {r['sent']:,} ({per_sender:,}, {r['frame_bytes']:,}) | "
                f"{r['flood']:.1f} ({r['took']:.1f}) | {r['held']:,} | {d['held']:,} / {d['quiet']:,} / {d['senders']:,} | "
                f"{', '.join(f'{k} {v:,}' for k, v in rejected.items()) or '-'} | {_mb(r['rss0'])} | {_mb(growth)} | "
                f"{_mb(r['quiet'] - r['rss0'])} | {_mb(r['trim'] - r['rss0'])} | {growth / senders / 2**20:.3f} | {per_frame} |",
                flush=True,
            )
    print(
        "\nRSS growth is over the agent process's RSS just before the flood; 'held at peak' is the inbox's count once "
        "the agent took every frame in; after quiet, every fake sender has been silent longer than quiet and what was "
        "held of it is dropped; malloc_trim(0) gives memory freed but kept by the C allocator back to the system."
    )
    print(f"\n(total {time.time() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
