"""What ``--ros2`` costs: CPU per agent at 30 Hz, and the publish latency on loopback.

**CPU.** The lunar demo (seed 1, the small field) runs three times, each in a process of its own:
without ROS 2, with ``--ros2`` (a live node per robot publishing to a subscriber in
another process, which decodes every message), and with ``--record`` (a rosbag2
folder). Every run of one seed does the same work, so the difference in the
run's CPU time (all threads: zenoh's too) is what ROS 2 adds. It is given per
agent and per simulated second at 30 Hz, which is the share of one core an agent
at 30 Hz in real time spends on it. The time spent inside the publishing hook is
measured separately.

**Latency.** A node publishes ``PoseStamped`` (about 60 bytes), a 200 x 200
``OccupancyGrid`` (40 kB) and a ``MarkerArray`` of 20 samples at 30 Hz to a
subscriber in another process over TCP on loopback. The latency of a message is
its arrival time minus the source time in its attachment. The peer is a plain
zenoh put of the same bytes with no rmw_zenoh framing (the floor).

Run: ``.venv/bin/python bench/ros2.py [--messages 300] [--time-limit 60]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from alica.app.ros2_bridge import MAP, MARKERS, POSE, Place, marker_array, occupancy_grid, pose_stamped
from alica.app.ros2_output import Ros2Output
from alica.comm.ros2 import dds_name, encode, type_hash
from alica.comm.ros2.rmw import Ros2Node, open_session
from alica.comm.zenoh_transport import free_endpoints

_SUBSCRIBER = """
import sys, time, zenoh
from alica.comm.ros2 import decode
from alica.comm.ros2.rmw import open_session, parse_attachment
endpoint, mode = sys.argv[1], sys.argv[2]
session = open_session(None, listen=[endpoint])
types = {"pose": "geometry_msgs/msg/PoseStamped", "team_map": "nav_msgs/msg/OccupancyGrid",
         "markers": "visualization_msgs/msg/MarkerArray", "tf": "tf2_msgs/msg/TFMessage",
         "diagnostics": "diagnostic_msgs/msg/DiagnosticArray", "clock": "rosgraph_msgs/msg/Clock"}
def on_sample(sample):
    now = time.time_ns()
    key = str(sample.key_expr)
    data = sample.payload.to_bytes()
    if mode == "latency":
        raw = sample.attachment.to_bytes() if sample.attachment is not None else None
        sent = parse_attachment(raw)[1] if raw else int.from_bytes(data[-8:], "little")
        print(key.split("/")[2], now - sent, flush=True)
    else:
        topic = key.split("/")[-3] if key.count("/") >= 4 else ""
        if topic in types:
            decode(types[topic], data)
sub = session.declare_subscriber("**", on_sample)
print("ready", flush=True)
sys.stdin.read()
sys.stdout.flush()
import os
os._exit(0)  # at once: the interpreter's exit otherwise waits on zenoh's threads
"""


def _subscriber(endpoint: str, mode: str) -> subprocess.Popen[str]:
    process = subprocess.Popen(
        [sys.executable, "-c", _SUBSCRIBER, endpoint, mode], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert process.stdout is not None
    if process.stdout.readline().strip() != "ready":
        raise RuntimeError("the subscriber did not start")
    return process


def _cpu() -> float:
    user, system = os.times()[:2]
    return user + system


def _lunar_run(mode: str, time_limit: float, endpoint: str, bag: str) -> dict[str, float]:
    """One lunar run (in a process of its own, see :func:`cpu_table`): CPU, wall and the hook's CPU."""
    from alica.app.demos.lunar import LunarConfig, run_lunar

    config = LunarConfig(size=16.0, rocks=6, samples=2, seed=1, time_limit=time_limit)
    output = None
    if mode == "ros2":
        output = Ros2Output(live=True, router=endpoint)
    elif mode == "record":
        output = Ros2Output(record=Path(bag))
    hook = [0.0]
    if output is not None:
        attach = output.attach_team

        def timed_attach(team: Any, library: Any, **_kw: Any) -> Any:
            inner = attach(team, library, hook=False)

            def after(now: float) -> None:
                began = time.thread_time()
                inner(now)
                hook[0] += time.thread_time() - began

            team.after_tick(after)
            return after

        output.attach_team = timed_attach  # type: ignore[method-assign]
    cpu, wall = _cpu(), time.perf_counter()
    result = run_lunar(config, ros2=output)
    if output is not None:
        output.close()
    cpu, wall = _cpu() - cpu, time.perf_counter() - wall
    return {"sim": result.sim_time_s, "wall": wall, "cpu": cpu, "hook": hook[0], "found": float(len(result.found))}


def cpu_table(time_limit: float) -> None:
    """The lunar demo without ROS 2, with --ros2 and with --record: CPU per agent per simulated second at 30 Hz.

    Each run is a process of its own: OMPL seeds its generator once per process, so only runs in fresh
    processes repeat a seed's work exactly (the summary's found samples and simulated time say whether they did).
    """
    rows = []
    base = None
    for mode in ("none", "ros2", "record"):
        (endpoint,) = free_endpoints(1)
        listener = _subscriber(endpoint, "decode") if mode == "ros2" else None
        with tempfile.TemporaryDirectory() as tmp:
            bag = Path(tmp) / "bag"
            argv = [sys.executable, __file__, "--child", mode, "--time-limit", str(time_limit)]
            done = subprocess.run([*argv, "--router", endpoint, "--bag", str(bag)], capture_output=True, text=True)
            if done.returncode != 0:
                raise RuntimeError(f"the {mode} run failed: {done.stderr[-2000:]}")
            run = json.loads(done.stdout.splitlines()[-1])
            size = sum(f.stat().st_size for f in bag.glob("*")) if mode == "record" else 0
        if listener is not None:
            listener.communicate("", timeout=30)
        agent_seconds = 3 * run["sim"]
        if base is None:
            base = run["cpu"] / agent_seconds
        extra = run["cpu"] / agent_seconds - base
        in_hook = 100 * run["hook"] / agent_seconds
        rows.append((mode, run["sim"], int(run["found"]), run["wall"], run["cpu"], 100 * extra, in_hook, size))
    print("\n## CPU of --ros2 per agent (lunar demo, seed 1, 16 m field, 3 agents at 30 Hz)\n")
    print("| output | sim s | found | wall s | CPU s | extra CPU per agent, % of a core | in the hook, % | bag bytes |")
    print("|---|---|---|---|---|---|---|---|")
    for mode, sim, found, wall, cpu, extra, hook_share, size in rows:
        print(
            f"| {mode} | {sim:.1f} | {found} | {wall:.1f} | {cpu:.1f} | {extra:.2f} | {hook_share:.2f} | {size or '-'} |"
        )


def _builders() -> dict[str, tuple[str, Callable[[], dict[str, Any]]]]:
    """The benched messages: a pose, a 200 x 200 map and 20 sample markers, as (type, build the fields)."""
    rng = np.random.default_rng(0)
    logodds = rng.normal(0.0, 2.0, (200, 200)).astype(np.float32)
    places = [Place(f"s{i}", float(i), float(-i), "red-black-red") for i in range(20)]
    return {
        "pose": (POSE.typename, lambda: pose_stamped(1.0, 2.0, 3.0, 0.5)),
        "grid": (MAP.typename, lambda: occupancy_grid(1.0, (0.0, 0.0), 0.1, logodds)),
        "markers": (MARKERS.typename, lambda: marker_array(1.0, "scout", places)),
    }


def latency_table(count: int) -> None:
    """Publish latency on loopback: rmw_zenoh framing against a plain zenoh put, at 30 Hz."""
    rows = []
    for way in ("rmw_zenoh", "plain zenoh"):
        (endpoint,) = free_endpoints(1)
        listener = _subscriber(endpoint, "latency")
        session = open_session(endpoint)
        node = Ros2Node(session, "bench", namespace="/bench")
        publishers = {
            name: node.publisher(name, dds_name(typename), type_hash(typename, "jazzy"))
            for name, (typename, _) in _MESSAGES.items()
        }
        time.sleep(0.5)  # the bench (not a test): the subscriber's interest reaches the publisher
        encode_s: dict[str, list[float]] = {name: [] for name in publishers}
        next_at = time.perf_counter()
        for _ in range(count):
            for name, (_typename, data) in _MESSAGES.items():
                began = time.perf_counter()
                if way == "rmw_zenoh":
                    publishers[name].put(data, time.time_ns())
                else:
                    session.put(f"0/bench/{name}/plain", data + time.time_ns().to_bytes(8, "little"))
                encode_s[name].append(time.perf_counter() - began)
            next_at += 1 / 30
            time.sleep(max(0.0, next_at - time.perf_counter()))
        time.sleep(0.5)
        node.close()
        session.close()
        out, _ = listener.communicate("", timeout=30)
        seen: dict[str, list[float]] = {}
        for line in out.splitlines():
            name, ns = line.split()
            seen.setdefault(name, []).append(int(ns) / 1e6)
        for name, (_typename, data) in _MESSAGES.items():
            values = sorted(seen.get(name, []))
            if not values:
                rows.append((way, name, len(data), 0, float("nan"), float("nan"), float("nan")))
                continue
            p99 = values[min(len(values) - 1, int(0.99 * len(values)))]
            put_us = 1e6 * statistics.median(encode_s[name])
            rows.append((way, name, len(data), len(values), statistics.median(values), p99, put_us))
    print("\n## Publish latency on loopback (30 Hz, another process subscribes)\n")
    print("| way | message | bytes | received | p50 ms | p99 ms | put µs (median) |")
    print("|---|---|---|---|---|---|---|")
    for way, name, size, received, p50, p99, put_us in rows:
        print(f"| {way} | {name} | {size} | {received} | {p50:.3f} | {p99:.3f} | {put_us:.1f} |")


_MESSAGES = {name: (typename, encode(typename, build())) for name, (typename, build) in _builders().items()}


def encode_table() -> None:
    """The cost of building and encoding each message once."""
    print("\n## Building and encoding a message (median of 200)\n")
    print("| message | µs |")
    print("|---|---|")
    for name, (typename, build) in _builders().items():
        times = []
        for _ in range(200):
            began = time.perf_counter()
            encode(typename, build())
            times.append(time.perf_counter() - began)
        print(f"| {name} | {1e6 * statistics.median(times):.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--messages", type=int, default=300, help="messages of each kind for the latency (default 300)")
    parser.add_argument("--time-limit", type=float, default=60.0, help="simulated seconds of the lunar runs")
    parser.add_argument("--skip-cpu", action="store_true", help="only the latency and encoding tables")
    parser.add_argument("--child", choices=("none", "ros2", "record"), help=argparse.SUPPRESS)
    parser.add_argument("--router", help=argparse.SUPPRESS)
    parser.add_argument("--bag", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(_lunar_run(args.child, args.time_limit, args.router, args.bag)))
        return
    encode_table()
    latency_table(args.messages)
    if not args.skip_cpu:
        cpu_table(args.time_limit)


if __name__ == "__main__":
    main()
