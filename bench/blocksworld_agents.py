"""The Fig. 22 experiment of the IMPERA paper: blocks-world execution time against the number of agents.

For 1 to 5 agents, without and with opponents, over several seeds, this runs
``alica demo blocksworld --json`` (each run in a fresh process, so each is
repeatable on its own). It prints a markdown table of simulated execution
time (mean, min, max over the successful runs), success count, replans and
wall time. It writes the table as TSV, every run as TSV, and a PNG plot of
simulated time against agents to ``build/bench/``.

The paper's trends are the bar. Without opponents the time falls as agents
are added. With opponents it is higher, because the team has to replan.

Several block counts run in one go (``--blocks 8,12``); the plot of each
shows, beside the curves measured now, the curve recorded before issue 19
(``bench/blocksworld_before.tsv``: the mean simulated times at commit
5405f13, seeds 0-9: without opponents measured with
``bench/blocksworld_timeline.py``, with 2 opponents (8 blocks) with this
script at that commit).

Run: ``.venv/bin/python bench/blocksworld_agents.py [--agents 1-5] [--opponents 2] [--blocks 8,12] [--seeds 10] [--time-limit 600] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import itertools
import json
import statistics
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "build" / "bench"


def demo_argv(agents: int, opponents: int, blocks: int, seed: int, time_limit: float) -> list[str]:
    """The command of one ``alica demo blocksworld`` run with a JSON summary, in a fresh interpreter."""
    return [
        sys.executable,
        "-m",
        "alica.app.cli",
        "demo",
        "blocksworld",
        "--robots",
        str(agents),
        "--opponents",
        str(opponents),
        "--blocks",
        str(blocks),
        "--seed",
        str(seed),
        "--time-limit",
        str(time_limit),
        "--json",
        "--no-progress",
    ]


def run_one(agents: int, opponents: int, blocks: int, seed: int, time_limit: float) -> dict[str, object]:
    """One demo run in a fresh process; its JSON summary (``error`` set when it did not run)."""
    argv = demo_argv(agents, opponents, blocks, seed, time_limit)
    started = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=time_limit * 4 + 120)
    line = next((row for row in reversed(done.stdout.splitlines()) if row.startswith("{")), None)
    if line is None:
        return {
            "error": done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}",
            "process_s": time.perf_counter() - started,
        }
    result = json.loads(line)
    result["process_s"] = time.perf_counter() - started
    return result


def _range(text: str) -> list[int]:
    low, _, high = text.partition("-")
    return list(range(int(low), int(high or low) + 1))


def main() -> int:
    """Run the experiment and print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", default="1-5", help="range of team sizes (default 1-5)")
    parser.add_argument("--opponents", type=int, default=2, help="opponents in the runs with opponents (default 2)")
    parser.add_argument("--blocks", default="8", help="block counts, comma-separated (default 8)")
    parser.add_argument("--seeds", type=int, default=3, help="seeds per cell (default 3)")
    parser.add_argument("--time-limit", type=float, default=900.0, help="simulated seconds per run (default 900)")
    parser.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="runs at once, each in its own process (default 1; wall times are then shared-machine figures)",
    )
    parser.add_argument(
        "--replot", action="store_true", help="draw the plots again from the tables written before (no runs)"
    )
    args = parser.parse_args()
    counts = [int(b) for b in str(args.blocks).split(",")]
    if args.replot:
        for blocks in counts:
            rows = _read_table(OUT / f"blocksworld_agents_b{blocks}.tsv")
            args.agents = f"{min(int(r['agents']) for r in rows)}-{max(int(r['agents']) for r in rows)}"  # type: ignore[call-overload]
            _plot(rows, OUT / f"blocksworld_agents_b{blocks}.png", args, blocks)
        return 0
    cells = [(opponents, agents) for opponents in (0, args.opponents) for agents in _range(args.agents)]
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {
            (blocks, o, a, seed): pool.submit(run_one, a, o, blocks, seed, args.time_limit)
            for blocks in counts
            for o, a in cells
            for seed in range(args.seeds)
        }
        every = {key: future.result() for key, future in futures.items()}
    OUT.mkdir(parents=True, exist_ok=True)
    for blocks in counts:
        results = {key[1:]: r for key, r in every.items() if key[0] == blocks}
        _report(args, blocks, cells, results)
    return 0


def _report(
    args: argparse.Namespace,
    blocks: int,
    cells: list[tuple[int, int]],
    results: dict[tuple[int, int, int], dict[str, object]],
) -> None:
    """Print the table of one block count, write its TSVs and its plot."""
    rows = []
    for opponents, agents in cells:
        runs = [results[(opponents, agents, seed)] for seed in range(args.seeds)]
        ok = [r for r in runs if r.get("success")]
        times = [float(r["sim_time_s"]) for r in ok]  # type: ignore[arg-type]
        rows.append(
            {
                "agents": agents,
                "opponents": opponents,
                "success": f"{len(ok)}/{len(runs)}",
                "sim_mean": statistics.mean(times) if times else float("nan"),
                "sim_min": min(times) if times else float("nan"),
                "sim_max": max(times) if times else float("nan"),
                "replans": statistics.mean(float(r.get("replans", 0)) for r in runs if "error" not in r)
                if any("error" not in r for r in runs)
                else float("nan"),  # type: ignore[arg-type]
                "wall_mean": statistics.mean(float(r["wall_time_s"]) for r in runs if "wall_time_s" in r)
                if any("wall_time_s" in r for r in runs)
                else float("nan"),  # type: ignore[arg-type]
                "errors": "; ".join(str(r["error"]) for r in runs if "error" in r),
            }
        )
    header = ["agents", "opponents", "success", "sim time mean s", "min", "max", "replans mean", "wall mean s"]
    print(
        f"\nBlocks world, {blocks} blocks, {args.seeds} seeds per cell, time limit {args.time_limit:.0f} s simulated\n"
    )
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        print(
            f"| {r['agents']} | {r['opponents']} | {r['success']} | {r['sim_mean']:.1f} | {r['sim_min']:.1f} | {r['sim_max']:.1f} | {r['replans']:.1f} | {r['wall_mean']:.1f} |"
        )
    free = [r for r in rows if r["opponents"] == 0]
    falls = all(float(b["sim_mean"]) < float(a["sim_mean"]) for a, b in itertools.pairwise(free))  # type: ignore[arg-type]
    if len(free) >= 2:
        ratio = float(free[-1]["sim_mean"]) / float(free[0]["sim_mean"])  # type: ignore[arg-type]
        print(
            f"\nwithout opponents: the mean falls at every added agent: {'yes' if falls else 'no'}; "
            f"{free[-1]['agents']} agents take {ratio:.2f}x the time of {free[0]['agents']}"
        )
    errors = [f"agents {r['agents']} opponents {r['opponents']}: {r['errors']}" for r in rows if r["errors"]]
    if errors:
        print("\nruns that did not finish: " + " | ".join(errors))
    with (OUT / f"blocksworld_agents_b{blocks}.tsv").open("w", encoding="utf-8") as f:
        f.write(
            "\t".join(["agents", "opponents", "success", "sim_mean", "sim_min", "sim_max", "replans", "wall_mean"])
            + "\n"
        )
        for r in rows:
            f.write(
                "\t".join(
                    str(r[k])
                    for k in (
                        "agents",
                        "opponents",
                        "success",
                        "sim_mean",
                        "sim_min",
                        "sim_max",
                        "replans",
                        "wall_mean",
                    )
                )
                + "\n"
            )
    with (OUT / f"blocksworld_runs_b{blocks}.tsv").open("w", encoding="utf-8") as f:
        f.write("agents\topponents\tseed\tsuccess\tsim_time_s\twall_time_s\treplans\terror\n")
        for (opponents, agents, seed), r in sorted(results.items()):
            f.write(
                f"{agents}\t{opponents}\t{seed}\t{r.get('success', '')}\t{r.get('sim_time_s', '')}\t{r.get('wall_time_s', '')}\t{r.get('replans', '')}\t{r.get('error', '')}\n"
            )
    _plot(rows, OUT / f"blocksworld_agents_b{blocks}.png", args, blocks)
    print(f"\nwrote blocksworld_agents_b{blocks}.tsv, blocksworld_runs_b{blocks}.tsv (every run) and the plot to {OUT}")


def _read_table(path: Path) -> list[dict[str, object]]:
    """The rows of a table this script wrote."""
    lines = path.read_text(encoding="utf-8").splitlines()
    keys = lines[0].split("\t")
    rows: list[dict[str, object]] = []
    for line in lines[1:]:
        row: dict[str, object] = dict(zip(keys, line.split("\t"), strict=True))
        for key in ("agents", "opponents"):
            row[key] = int(str(row[key]))
        for key in ("sim_mean", "sim_min", "sim_max"):
            row[key] = float(str(row[key]))
        rows.append(row)
    return rows


#: The mean simulated times recorded before issue 19: blocks, opponents, agents, seconds.
BEFORE = Path(__file__).resolve().parent / "blocksworld_before.tsv"


def _before(blocks: int) -> dict[int, dict[int, float]]:
    """Opponents -> agents -> the mean simulated time recorded before, for ``blocks``."""
    if not BEFORE.exists():
        return {}
    out: dict[int, dict[int, float]] = {}
    for line in BEFORE.read_text(encoding="utf-8").splitlines()[1:]:
        b, o, a, sim = line.split("\t")[:4]
        if int(b) == blocks:
            out.setdefault(int(o), {})[int(a)] = float(sim)
    return out


def _plot(rows: list[dict[str, object]], path: Path, args: argparse.Namespace, blocks: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for opponents, style in ((0, "o-"), (args.opponents, "s--")):
        mine = [r for r in rows if r["opponents"] == opponents]
        xs = [r["agents"] for r in mine]
        ys = [r["sim_mean"] for r in mine]
        low = [float(r["sim_mean"]) - float(r["sim_min"]) for r in mine]  # type: ignore[arg-type]
        high = [float(r["sim_max"]) - float(r["sim_mean"]) for r in mine]  # type: ignore[arg-type]
        ax.errorbar(xs, ys, yerr=[low, high], fmt=style, capsize=3, label=f"{opponents} opponents")
    for opponents, curve in sorted(_before(blocks).items()):
        xs = sorted(curve)
        colour = "grey" if opponents == 0 else "peru"
        label = f"{opponents} opponents, before (5405f13)"
        ax.plot(xs, [curve[a] for a in xs], ":", color=colour, marker="x", label=label)
    ax.set_xticks(_range(args.agents))
    ax.set_xlabel("agents")
    ax.set_ylabel("execution time (simulated s)")
    ax.set_title(f"Blocks world, {blocks} blocks (cf. IMPERA Fig. 22)")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
