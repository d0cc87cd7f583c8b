"""Benchmark of the lunar mission end to end (issue 17's figures).

Run with ``.venv/bin/python bench/lunar.py`` (10 seeds by default; ``--seeds 2
--scenarios nominal`` for a quick look). Every run is ``alica demo lunar``'s
:func:`alica.app.demos.lunar.run_lunar` in a fresh process (pybullet and OMPL
keep state per process; the process's peak memory is the run's).

Scenarios, on the 40 x 40 m field with 60 rocks and 6 samples, the operator
picking the first two samples found:

* ``nominal``: scout, stummel and amparo;
* ``scout-crash``: Scout crashes at 20 s, Stummel explores;
* ``amparo-crash``: Amparo crashes at ``--amparo-crash`` s, Stummel takes its transport;
* ``amparo-grasp``: Amparo crashes when it first lifts a sample it grasped (the sample falls; the team finds it again);
* ``loss30``: 30 % of the messages are lost;
* ``partition20``: Scout is cut off from the others from 10 s to 30 s;
* ``robots1``, ``robots2``: stummel alone; scout and stummel (no faults).

Prints a markdown table (success rate, median simulated and wall time, peak
memory) with the goals (at least 9 of 10 successes per fault scenario, at
most 60 s wall per run, median) and writes ``build/lunar_bench.png``.
"""

from __future__ import annotations

import argparse
import multiprocessing
import resource
import statistics
import time
from pathlib import Path
from typing import Any

SCENARIOS = ("nominal", "scout-crash", "amparo-crash", "amparo-grasp", "loss30", "partition20", "robots1", "robots2")


def config_for(scenario: str, seed: int, args: argparse.Namespace) -> Any:
    """The run's configuration."""
    from alica.app.demos.lunar import Crash, LunarConfig, Partition

    base: dict[str, Any] = {
        "seed": seed,
        "samples": args.samples,
        "rocks": args.rocks,
        "size": args.size,
        "time_limit": args.time_limit,
    }
    if scenario == "scout-crash":
        base["crashes"] = (Crash("scout", 20.0),)
    elif scenario == "amparo-crash":
        base["crashes"] = (Crash("amparo", args.amparo_crash),)
    elif scenario == "amparo-grasp":
        base["crashes"] = (Crash("amparo", None),)
    elif scenario == "loss30":
        base["loss"] = 0.3
    elif scenario == "partition20":
        base["partitions"] = (Partition((("scout",), ("stummel", "amparo")), 10.0, 30.0),)
    elif scenario == "robots1":
        base["robots"] = ("stummel",)
    elif scenario == "robots2":
        base["robots"] = ("scout", "stummel")
    return LunarConfig(**base)


def _one(scenario: str, seed: int, args: argparse.Namespace, queue: Any) -> None:
    from alica.app.demos.lunar import run_lunar

    try:
        result = run_lunar(config_for(scenario, seed, args))
        row = result.as_json()
    except Exception as exc:  # a crash of a run is a figure too
        row = {
            "success": False,
            "reason": f"{type(exc).__name__}: {exc}",
            "sim_time_s": float("nan"),
            "wall_time_s": 0.0,
        }
    row["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    queue.put(row)


def run_one(scenario: str, seed: int, args: argparse.Namespace) -> dict[str, Any]:
    """One run in a fresh process."""
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    process = context.Process(target=_one, args=(scenario, seed, args, queue))
    start = time.perf_counter()
    process.start()
    row: dict[str, Any] = queue.get()
    process.join()
    row["process_s"] = time.perf_counter() - start
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument(
        "--scenarios", default=",".join(SCENARIOS), help="comma-separated, from " + ", ".join(SCENARIOS)
    )
    parser.add_argument("--samples", type=int, default=6)
    parser.add_argument("--rocks", type=int, default=60)
    parser.add_argument("--size", type=float, default=40.0)
    parser.add_argument("--time-limit", type=float, default=900.0)
    parser.add_argument("--amparo-crash", type=float, default=45.0, help="when Amparo crashes in amparo-crash (s)")
    parser.add_argument("--out", default="build/lunar_bench.png")
    args = parser.parse_args()
    scenarios = [s.strip() for s in args.scenarios.split(",") if s.strip()]
    unknown = [s for s in scenarios if s not in SCENARIOS]
    if unknown:
        parser.error(f"unknown scenario(s) {', '.join(unknown)}; choose from {', '.join(SCENARIOS)}")
    rows: dict[str, list[dict[str, Any]]] = {}
    for scenario in scenarios:
        rows[scenario] = []
        for seed in range(args.seeds):
            row = run_one(scenario, seed, args)
            rows[scenario].append(row)
            state = "ok" if row["success"] else f"FAILED ({row.get('reason', '')})"
            print(
                f"{scenario} seed {seed}: {state}, {row['sim_time_s']:.0f} s simulated, {row['wall_time_s']:.1f} s wall",
                flush=True,
            )
    print()
    print(
        f"## Lunar mission: {args.seeds} seeds per scenario, {args.size:g} x {args.size:g} m, {args.rocks} rocks, "
        f"{args.samples} samples, the first 2 found brought back\n"
    )
    print("| scenario | successes | median simulated s | median wall s | max wall s | peak memory MB | goal met |")
    print("|---|---|---|---|---|---|---|")
    for scenario, runs in rows.items():
        ok = sum(r["success"] for r in runs)
        sims = [r["sim_time_s"] for r in runs if r["success"]]
        walls = [r["wall_time_s"] for r in runs]
        peak = max(r["peak_mb"] for r in runs)
        wall = statistics.median(walls)
        goal = ok >= 0.9 * len(runs) and wall <= 60.0
        print(
            f"| {scenario} | {ok}/{len(runs)} | {statistics.median(sims) if sims else float('nan'):.0f} | {wall:.1f} | "
            f"{max(walls):.1f} | {peak:.0f} | {'yes' if goal else 'no'} |"
        )
    print("\nGoals: at least 9 of 10 successes in each scenario; at most 60 s wall per run (median).")
    _plot(rows, Path(args.out))
    print(f"plot: {args.out}")


def _plot(rows: dict[str, list[dict[str, Any]]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(rows)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    left.bar(names, [sum(r["success"] for r in rows[n]) / len(rows[n]) for n in names], color="tab:green")
    left.axhline(0.9, color="black", linestyle="--", linewidth=1)
    left.set_ylabel("success rate")
    left.set_ylim(0, 1.05)
    left.tick_params(axis="x", rotation=45)
    right.boxplot([[r["wall_time_s"] for r in rows[n]] for n in names])
    right.set_xticks(range(1, len(names) + 1), names)
    right.axhline(60.0, color="black", linestyle="--", linewidth=1)
    right.set_ylabel("wall time per run (s)")
    right.tick_params(axis="x", rotation=45)
    fig.suptitle("lunar mission: success and wall time per scenario")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
