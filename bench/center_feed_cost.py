"""What the control center's feed costs an agent process: with no center listening, and with one.

Run with ``.venv/bin/python bench/center_feed_cost.py [--repeat 3] [--seconds 12]``.
Each run is the 3-agent lunar team with stand-ins (``plans/lunar/mission.yaml``,
operator fact ``found(a) and found(b)`` at 3 s) as ``alica agent`` processes on
loopback (:class:`alica.app.processes.ProcessTeam`) for ``--seconds`` wall
seconds at 30 Hz, in three variants, interleaved run by run:

* ``off``: ``alica agent --no-center-feed`` (no feed at all);
* ``on, no center``: the default: every event is serialised and kept, nothing is
  published (no subscriber matches);
* ``on, center``: a :class:`alica.comm.center_feed.CenterLink` (what ``alica
  center --team`` opens) is connected from the start, so events are published.

Then it times :meth:`CenterFeed.__call__` alone in this process (a typical
``allocation`` event, 100,000 calls), with no subscriber and with one.

Per variant it prints the median over runs and agents of each agent's CPU
(percent of one core while ticking, the agent's own summary), its ticks, its
overruns (ticks that started late), and the events the center received.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
PLAN = str(ROOT / "plans" / "lunar" / "mission.yaml")
NAMES = ("scout", "stummel", "amparo")
VARIANTS = ("off", "on, no center", "on, center")


def one_run(variant: str, seconds: float) -> tuple[list[dict[str, Any]], int]:
    from alica.app.processes import ProcessTeam
    from alica.comm.center_feed import CenterLink

    options = ["--stand-ins", "--fact", "found(a) and found(b)@3", "--time-limit", str(seconds)]
    if variant == "off":
        options.append("--no-center-feed")
    received = [0]
    with tempfile.TemporaryDirectory(prefix="center_feed_cost_") as tmp:
        team = ProcessTeam(PLAN, ",".join(NAMES), list(NAMES), options, Path(tmp))
        link = None
        try:
            team.launch()

            def connect(_count: int, _at: float) -> None:
                nonlocal link
                if variant == "on, center":
                    link = CenterLink(
                        [a.listen for a in team.agents.values()],
                        "alica",
                        lambda answer: received.__setitem__(0, received[0] + len(answer["events"])),
                        lambda _name, _event: received.__setitem__(0, received[0] + 1),
                    )

            team.run([], seconds + 5.0, on_started=connect)
            while team.now() < seconds + 5.0 and not team.all_down():
                team.exited()
                time.sleep(0.1)  # the agents stop by themselves at --time-limit
        finally:
            team.stop()
            if link is not None:
                link.close()
        return [agent.summaries[-1] for agent in team.agents.values() if agent.summaries], received[0]


def per_event(listened: bool, calls: int = 100_000) -> float:
    """Microseconds one event costs the feed, with or without a center subscribed."""
    import zenoh

    from alica.comm.center_feed import CenterFeed
    from alica.comm.zenoh_transport import ZenohTransport, free_endpoints, zenoh_config

    endpoint = free_endpoints(1)
    transport = ZenohTransport("a1", listen=endpoint, team="bench")
    center = zenoh.open(zenoh_config(tuple(endpoint), (), "client", 2.0, None)) if listened else None
    try:
        if center is not None:
            center.declare_subscriber("bench/center/events/*", lambda _sample: None)
        feed = CenterFeed(transport, {"event": "trace"}, time.time())
        deadline = time.monotonic() + 5.0
        while listened and not feed.listened and time.monotonic() < deadline:
            time.sleep(0.01)  # the subscriber's declaration reaches the agent
        event = {
            "t": 1.234567,
            "agent": "a1",
            "event": "allocation",
            "key": "LunarMission/Explore/Explore",
            "plan": "Explore",
            "entries": {"scout": "GetMap", "stummel": "Explore"},
            "reason": "utility",
        }
        began = time.perf_counter()
        for _ in range(calls):
            feed(event)
        spent = (time.perf_counter() - began) / calls * 1e6
        feed.close()
        return spent
    finally:
        if center is not None:
            center.close()
        transport.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=12.0)
    args = parser.parse_args()
    rows: dict[str, dict[str, list[float]]] = {
        v: {"cpu": [], "ticks": [], "overruns": [], "events": []} for v in VARIANTS
    }
    for _ in range(args.repeat):
        for variant in VARIANTS:
            summaries, received = one_run(variant, args.seconds)
            for summary in summaries:
                rows[variant]["cpu"].append(float(summary.get("cpu_percent") or 0.0))
                rows[variant]["ticks"].append(float(summary.get("ticks") or 0))
                rows[variant]["overruns"].append(float(summary.get("overruns") or 0))
            rows[variant]["events"].append(received)
    print(
        f"| feed ({args.repeat} runs x 3 agents, {args.seconds:g} s) | CPU % of a core | ticks | overruns | events at the center |"
    )
    print("|---|---|---|---|---|")
    for variant, row in rows.items():
        print(
            f"| {variant} | {statistics.median(row['cpu']):.1f} (min {min(row['cpu']):.1f}, max {max(row['cpu']):.1f}) "
            f"| {statistics.median(row['ticks']):.0f} | {statistics.median(row['overruns']):.0f} "
            f"| {statistics.median(row['events']):.0f} |"
        )
    print()
    print(f"one event: {per_event(False):.1f} us with no center, {per_event(True):.1f} us with one subscribed")


if __name__ == "__main__":
    main()
