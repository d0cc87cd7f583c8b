"""The lunar demo as one process per robot against the in-process demo, on the same seeds in the same run.

For each seed and case, ``alica demo lunar --seed S --json`` runs once in one
process (the peer: the team and the world in one Python process, simulated
time) and once with ``--processes`` (a world server in lock-step and one
``alica agent`` process per robot over zenoh on loopback). The cases are
``nominal`` and ``stummel@40`` (Stummel crashes at simulated second 40: in the
process team its agent is killed with ``kill -9``). Each run is its own
``alica`` process, ``--jobs`` of them at a time.

Printed: a row per seed and case (success, simulated and wall seconds of
each, found and delivered samples), then per case the successes out of the
seeds and the median wall time of the process team against the in-process
demo's (goal: at least 9 of 10 succeed with processes; median wall at most
2x), and the CPU shares of the world server (the demo's own process: the
world, its server and the operator) and of each agent (its process, of one
core, while ticking), median over the process runs.

Run: ``.venv/bin/python bench/lunar_processes.py [--seeds 0-9] [--jobs 2] [--cases nominal,stummel@40]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        first, _, last = part.partition("-")
        out.extend(range(int(first), int(last or first) + 1))
    return out


def _run(seed: int, case: str, processes: bool, limit: float) -> dict[str, Any]:
    argv = [sys.executable, "-m", "alica.app.cli", "demo", "lunar", "--seed", str(seed), "--json", "--no-progress"]
    if case != "nominal":
        argv += ["--crash", case]
    if processes:
        argv.append("--processes")
    began = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, timeout=limit, check=False)
    wall = time.perf_counter() - began
    line = next((x for x in reversed(done.stdout.splitlines()) if x.startswith("{")), None)
    if line is None:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {"success": False, "reason": tail[:120], "wall": wall, "sim": float("nan"), "found": 0, "delivered": 0}
    result = json.loads(line)
    return {
        "success": bool(result["success"]),
        "reason": result["reason"],
        "wall": wall,
        "sim": float(result["sim_time_s"]),
        "found": len(result["found"]),
        "delivered": len(result["delivered"]),
        "server_cpu": (result.get("world_server") or {}).get("cpu_percent"),
        "agent_cpu": [r.get("cpu_percent") for r in result["robots"].values() if r.get("cpu_percent") is not None],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-9", help="seeds, e.g. 0-9 or 1,3 (default 0-9)")
    parser.add_argument("--cases", default="nominal,stummel@40", help="nominal and/or NAME@T crashes")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    parser.add_argument("--limit", type=float, default=1800.0, help="wall seconds a run may take (default 1800)")
    args = parser.parse_args()
    seeds = _seeds(args.seeds)
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    jobs = [(seed, case, processes) for case in cases for seed in seeds for processes in (False, True)]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {job: pool.submit(_run, *job, args.limit) for job in jobs}
        results = {job: future.result() for job, future in futures.items()}
    print(f"{'case':<12} {'seed':>4}  {'in-process':<28}  {'processes':<28}  reason (processes)")
    for case in cases:
        for seed in seeds:
            cells = []
            for processes in (False, True):
                r = results[(seed, case, processes)]
                ok = "ok  " if r["success"] else "FAIL"
                cells.append(f"{ok} {r['sim']:6.1f} s sim {r['wall']:6.1f} s wall {r['delivered']}/{r['found']}")
            reason = results[(seed, case, True)]["reason"] if not results[(seed, case, True)]["success"] else ""
            print(f"{case:<12} {seed:>4}  {cells[0]:<28}  {cells[1]:<28}  {reason[:70]}")
    print()
    print(f"{'case':<12} {'in-process ok':>13} {'processes ok':>12} {'median wall in/proc':>22} {'ratio':>6}")
    for case in cases:
        inproc = [results[(s, case, False)] for s in seeds]
        procs = [results[(s, case, True)] for s in seeds]
        w_in = statistics.median(r["wall"] for r in inproc)
        w_pr = statistics.median(r["wall"] for r in procs)
        print(
            f"{case:<12} {sum(r['success'] for r in inproc):>10}/{len(seeds)} {sum(r['success'] for r in procs):>9}/"
            f"{len(seeds)} {w_in:>10.1f} / {w_pr:>7.1f} s {w_pr / w_in:>6.2f}"
        )
    server = [r["server_cpu"] for r in results.values() if r.get("server_cpu") is not None]
    agents = [c for r in results.values() for c in r.get("agent_cpu") or []]
    if server and agents:
        print()
        print("CPU share of one core, median over the process runs (3 robots, 30 Hz, lock-step):")
        print(f"  world server process (world, server, operator): {statistics.median(server):5.1f} %")
        print(f"  each agent process (while ticking):             {statistics.median(agents):5.1f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
