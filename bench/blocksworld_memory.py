"""Peak memory of the blocks-world demo: peak RSS of one ``alica demo blocksworld`` process per row.

Each run is a fresh process (``alica demo blocksworld --json``); its peak
resident set size is the ``ru_maxrss`` that ``os.wait4`` reports for that
child alone, so other processes on the machine do not change it (wall times
would). It prints a markdown table (agents, opponents, blocks, seed, success,
peak RSS in MB, simulated time) and writes it as TSV to
``build/bench/blocksworld_memory.tsv``.

Run: ``.venv/bin/python bench/blocksworld_memory.py [--runs 1:0,3:0,5:0,1:2,3:2,5:2] [--blocks 8] [--seeds 0] [--time-limit 600]``
(``--runs`` lists ``agents:opponents`` pairs; ``--seeds 0-3`` runs seeds 0 to 3 of each.)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from blocksworld_agents import demo_argv  # bench/ is on the path when this script runs

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "build" / "bench"
COLUMNS = ("agents", "opponents", "blocks", "seed", "success", "peak_rss_mb", "sim_time_s", "replans")


def run_one(agents: int, opponents: int, blocks: int, seed: int, time_limit: float) -> dict[str, object]:
    """One demo run in a fresh process: its JSON summary with ``peak_rss_mb`` (``error`` when it did not run)."""
    argv = demo_argv(agents, opponents, blocks, seed, time_limit)
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(argv, cwd=ROOT, stdout=out, stderr=err, text=True)
        _, status, usage = os.wait4(proc.pid, 0)  # reaps the child: its own rusage, not the sum of all children
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read(), err.read()
    row: dict[str, object] = {"agents": agents, "opponents": opponents, "blocks": blocks, "seed": seed}
    row["peak_rss_mb"] = round(usage.ru_maxrss / 1024.0, 1)  # kilobytes on Linux
    line = next((text for text in reversed(stdout.splitlines()) if text.startswith("{")), None)
    if line is None:
        row["error"] = stderr.strip().splitlines()[-1] if stderr.strip() else f"exit {proc.returncode}"
        return row
    row.update(json.loads(line))
    return row


def _seeds(text: str) -> list[int]:
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def _runs(text: str) -> list[tuple[int, int]]:
    pairs = []
    for item in text.split(","):
        agents, _, opponents = item.strip().partition(":")
        pairs.append((int(agents), int(opponents or 0)))
    return pairs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="1:0,3:0,5:0,1:2,3:2,5:2", help="agents:opponents pairs, comma separated")
    parser.add_argument("--blocks", type=int, default=8)
    parser.add_argument("--seeds", default="0", help="a seed or a range such as 0-3")
    parser.add_argument("--time-limit", type=float, default=600.0)
    args = parser.parse_args(argv)
    rows = []
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---|" * len(COLUMNS))
    for agents, opponents in _runs(args.runs):
        for seed in _seeds(args.seeds):
            row = run_one(agents, opponents, args.blocks, seed, args.time_limit)
            rows.append(row)
            cells = [str(row.get(col, "error" if col == "success" else "")) for col in COLUMNS]
            print("| " + " | ".join(cells) + " |", flush=True)
    OUT.mkdir(parents=True, exist_ok=True)
    lines = ["\t".join(COLUMNS)] + ["\t".join(str(row.get(col, "")) for col in COLUMNS) for row in rows]
    (OUT / "blocksworld_memory.tsv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return 0 if all("error" not in row for row in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
