"""Remote robot calls through the world server on loopback: latency of a call, CPU share of the server and agents.

The world server (:class:`~alica.app.world_server.WorldServer`, the lunar
world with its three robots, 60 rocks, free-running at 30 Hz) runs in a
process of its own; agents are other processes, each with a
:class:`~alica.app.world_server.RemoteWorld` for its robot.

1. ``latency``: one agent calls back to back: ``drive(v, w)`` ``--calls``
   times, then ``lidar(360)`` as many times. p50 and p99 of each call's wall
   time (goal: p99 at most 5 ms).
2. ``load``: three agents (scout, stummel, amparo), each at 30 Hz for
   ``--seconds``: every tick a drive command, a lidar scan of 360 rays and a
   read of its pose, as a navigating agent does. The CPU share (process time
   over wall time, :func:`time.process_time`) of the server and of each agent,
   and the latency of their calls under that load (after the first :data:`WARM_UP` ticks).
3. ``lockstep``: the server in lock-step, three agents each ticking as fast as
   they can (drive, scan, ``tick_done``): steps per wall second.

The server's interpreter switches threads every 0.5 ms (``sys.setswitchinterval``, as
``alica world serve`` sets it), so a call is not held up behind the world's thread for the
default 5 ms.

Run: ``.venv/bin/python bench/remote_robot.py [--calls 2000] [--seconds 10] [--quick]``
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import multiprocessing.connection as mpc
import statistics
import time
import uuid
from typing import Any

GOAL_P99_MS = 5.0
WARM_UP = 15
"""Ticks of each agent under load left out of the figures (the connection and the first scans)."""
ROBOTS = ("scout", "stummel", "amparo")
SWITCH_INTERVAL = 0.0005


def _server(conn: mpc.Connection, endpoint: str, prefix: str, lockstep: bool) -> None:
    import sys

    from alica.app.world_server import WorldServer
    from alica.worldsim.scenarios import lunar

    sys.setswitchinterval(SWITCH_INTERVAL)
    world = lunar(seed=0)
    server = WorldServer(world, listen=[endpoint], prefix=prefix, frequency=30.0, lockstep=lockstep)
    try:
        conn.send("ready")
        while True:
            while not conn.poll():
                server.serve(duration=0.05)  # (the agents connect meanwhile)
            order = conn.recv()
            if order == "quit":
                break
            if order == "done":
                continue
            steps, cpu, wall = server.stats.steps, time.process_time(), time.monotonic()
            server.serve(duration=float(order), until=conn.poll)  # (until the agents are done)
            conn.send(
                {
                    "cpu": time.process_time() - cpu,
                    "wall": time.monotonic() - wall,
                    "steps": server.stats.steps - steps,
                    "objects": len(world.objects),
                }
            )
    finally:
        server.close()
        world.close()


def _agent(conn: mpc.Connection, endpoint: str, prefix: str, name: str, mode: str, amount: float) -> None:
    from alica.app.world_server import RemoteWorld

    world = RemoteWorld([endpoint], name, prefix=prefix, wait=10.0)
    robot = world.robots[name]
    drive: list[float] = []
    lidar: list[float] = []
    try:
        conn.send("ready")
        conn.recv()
        cpu, start = time.process_time(), time.monotonic()
        if mode == "latency":
            for k in range(int(amount)):
                t = time.perf_counter()
                robot.drive(0.0, 0.1 * math.sin(k))
                drive.append(time.perf_counter() - t)
            for _ in range(int(amount)):
                t = time.perf_counter()
                robot.lidar(360)
                lidar.append(time.perf_counter() - t)
        elif mode == "lockstep":
            for k in range(int(amount)):
                t = time.perf_counter()
                robot.drive(0.05 * math.sin(0.1 * k), 0.3 * math.cos(0.05 * k))
                robot.lidar(360)
                world.tick_done()
                drive.append(time.perf_counter() - t)  # (a whole tick: drive, scan, wait for the step)
        else:
            period, due, k = 1.0 / 30.0, start, 0
            while time.monotonic() - start < amount:
                t = time.perf_counter()
                robot.drive(0.05 * math.sin(0.1 * k), 0.3 * math.cos(0.05 * k))
                took = time.perf_counter() - t
                t = time.perf_counter()
                robot.lidar(360)
                if k >= WARM_UP:  # (the first scan is cast on request, then the lidar streams)
                    drive.append(took)
                    lidar.append(time.perf_counter() - t)
                _ = robot.pose
                k += 1
                due += period
                time.sleep(max(0.0, due - time.monotonic()))
        conn.send(
            {
                "cpu": time.process_time() - cpu,
                "wall": time.monotonic() - start,
                "drive": drive,
                "lidar": lidar,
            }
        )
    finally:
        robot.stop()
        world.close()


def _pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return 1e3 * ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def _run(
    mode: str, agents: tuple[str, ...], amount: float, seconds: float
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    from alica.comm.zenoh_transport import free_endpoints

    ctx = mp.get_context("spawn")
    endpoint = free_endpoints(1)[0]
    prefix = f"bench{uuid.uuid4().hex[:6]}"
    near, far = ctx.Pipe()
    server = ctx.Process(target=_server, args=(far, endpoint, prefix, mode == "lockstep"), daemon=True)
    server.start()
    procs: list[mp.process.BaseProcess] = [server]
    try:
        if not near.poll(60.0) or near.recv() != "ready":
            raise RuntimeError("the world server did not start within 60 s")
        pipes = []
        for name in agents:
            a, b = ctx.Pipe()
            p = ctx.Process(target=_agent, args=(b, endpoint, prefix, name, mode, amount), daemon=True)
            p.start()
            procs.append(p)
            pipes.append(a)
        for a in pipes:
            if not a.poll(60.0):
                raise RuntimeError("an agent did not connect within 60 s")
            a.recv()
        near.send(seconds)
        for a in pipes:
            a.send("go")
        results = []
        for a in pipes:
            if not a.poll(seconds + 120.0):
                raise RuntimeError("an agent did not finish")
            results.append(a.recv())
        near.send("done")
        if not near.poll(seconds + 30.0):
            raise RuntimeError("the world server did not report")
        served = near.recv()
        near.send("quit")
        return served, results
    finally:
        for p in procs:
            p.join(10.0)
            if p.is_alive():
                p.kill()
                p.join(5.0)


def _mark(p99: float) -> str:
    return "met" if p99 <= GOAL_P99_MS else "missed"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--calls", type=int, default=2000, help="back-to-back calls of each kind (default 2000)")
    parser.add_argument("--seconds", type=float, default=10.0, help="seconds of the 3-agent load (default 10)")
    parser.add_argument("--quick", action="store_true", help="500 calls, 4 s of load")
    args = parser.parse_args()
    calls, seconds = (500, 4.0) if args.quick else (args.calls, args.seconds)

    served, results = _run("latency", ("scout",), calls, 2.0 + calls * 0.004)
    r = results[0]
    print(f"## Remote robot calls on loopback (back to back, {calls} calls each; server free-running at 30 Hz)\n")
    print(f"| call | p50 ms | p99 ms | max ms | goal p99 <= {GOAL_P99_MS:g} ms |")
    print("| --- | ---: | ---: | ---: | --- |")
    for label, key in (("drive(v, w)", "drive"), ("lidar(360)", "lidar")):
        p50, p99 = _pct(r[key], 0.5), _pct(r[key], 0.99)
        print(f"| {label} | {p50:.2f} | {p99:.2f} | {1e3 * max(r[key]):.2f} | {_mark(p99)} |")

    served, results = _run("load", ROBOTS, seconds, seconds)
    print(
        f"\n## Three agents at 30 Hz for {seconds:g} s (drive + lidar(360) + pose each tick), "
        f"lunar world of {served['objects']} objects\n"
    )
    print("| process | CPU share % | drive p50 ms | drive p99 ms | lidar p50 ms | lidar p99 ms | ticks measured |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    share = 100.0 * served["cpu"] / served["wall"]
    print(f"| world server | {share:.1f} | | | | | {served['steps']} steps |")
    for name, r in zip(ROBOTS, results):
        print(
            f"| agent {name} | {100.0 * r['cpu'] / r['wall']:.1f} | {_pct(r['drive'], 0.5):.2f} | "
            f"{_pct(r['drive'], 0.99):.2f} | {_pct(r['lidar'], 0.5):.2f} | {_pct(r['lidar'], 0.99):.2f} | "
            f"{len(r['drive'])} |"
        )
    every = [x for r in results for x in r["drive"] + r["lidar"]]
    print(
        f"\nAll calls under load: p50 {_pct(every, 0.5):.2f} ms, p99 {_pct(every, 0.99):.2f} ms "
        f"(goal p99 <= {GOAL_P99_MS:g} ms: {_mark(_pct(every, 0.99))}); mean {1e3 * statistics.fmean(every):.2f} ms."
    )

    ticks = 100 if args.quick else 300
    served, results = _run("lockstep", ROBOTS, ticks, 120.0)
    wall = max(r["wall"] for r in results)
    print(f"\n## Lock-step: three agents, {ticks} ticks each (drive + lidar(360) + tick_done), 30 Hz world\n")
    print("| steps | wall s | steps per wall second | simulated / wall | tick p50 ms | tick p99 ms |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: |")
    every = [x for r in results for x in r["drive"]]
    print(
        f"| {ticks} | {wall:.2f} | {ticks / wall:.1f} | {ticks / 30.0 / wall:.2f}x | {_pct(every, 0.5):.2f} | "
        f"{_pct(every, 0.99):.2f} |"
    )


if __name__ == "__main__":
    main()
