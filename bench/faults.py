"""Fault matrix of the lunar team run: loss, delay, partitions, crashes, recoveries and mixes.

Run with ``.venv/bin/python bench/faults.py [--seeds 10] [--jobs 2] [--case NAME]``.
Every run is ``alica run plans/lunar/mission.yaml --agents scout,stummel,amparo
--stand-ins --fact "found(a) and found(b)@5"`` plus the case's faults, in its
own process (``python -m alica.app.cli``), up to ``--time-limit`` simulated
seconds (and a wall-clock guard). From its ``--json`` summary and its trace,
each run is classified:

* **success**: exit 0;
* **stated reason**: the run ended (every live agent done) without success and
  the summary gives a reason for every agent that did not succeed;
* **traceback**: an internal error (exit 70), a Python traceback on stderr, or
  a run killed by the wall-clock guard;
* **livelock**: the run had not ended at its time limit;
* **disagreement**: an agent reported the root plan's success while a
  success-required entry point had no agent that reached one of its success
  states (from the trace), or live agents ended with different outcomes;
* **duplicate claims**: the longest time two live agents that can reach each
  other held the same one-robot (``max: 1``) task of the root plan in a
  non-terminal state (from each agent's own allocations and transitions in
  the trace). Two agents on different sides of a partition cannot know of
  each other's claims, so that time is not counted; the time it takes them to
  settle after the partition heals is. A second column counts only the time
  while neither of the two took the other for lost: a duplicate while both
  know of each other is the engine's own disagreement; one after a teammate
  fell silent for longer than the team timeout (a real crash, or heavy loss)
  is what the team timeout allows.

It prints a markdown table per case: runs, successes, stated reasons,
tracebacks, livelocks, disagreements, runs with a duplicate claim over 1 s,
the longest duplicate claim, and the same two for duplicates while both
agents believed each other alive.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
PLAN = "plans/lunar/mission.yaml"
BASE = ["run", PLAN, "--agents", "scout,stummel,amparo", "--stand-ins", "--fact", "found(a) and found(b)@5"]

#: case name -> extra options of ``alica run``.
CASES: dict[str, list[str]] = {
    "loss 0.3": ["--loss", "0.3"],
    "loss 0.5": ["--loss", "0.5"],
    "loss 0.8": ["--loss", "0.8"],
    "delay 50+-100 ms": ["--delay", "50", "--jitter", "100"],
    "partition scout 20 s": ["--partition", "scout|stummel,amparo@3-23"],
    "partition amparo 20 s": ["--partition", "amparo|scout,stummel@6-26"],
    "crash scout@2": ["--crash", "scout@2"],
    "crash stummel@8": ["--crash", "stummel@8"],
    "crash amparo@8": ["--crash", "amparo@8"],
    "crash+recover scout 3-10": ["--crash", "scout@3", "--recover", "scout@10"],
    "crash+recover stummel 6-12": ["--crash", "stummel@6", "--recover", "stummel@12"],
    "crash+recover amparo 8-20": ["--crash", "amparo@8", "--recover", "amparo@20"],
    "crash+recover amparo 15-25": ["--crash", "amparo@15", "--recover", "amparo@25"],
    "loss 0.5 + crash scout@2": ["--loss", "0.5", "--crash", "scout@2"],
    "loss 0.8 + crash scout@2": ["--loss", "0.8", "--crash", "scout@2"],
    "loss 0.3 + jitter + partition": [
        "--loss",
        "0.3",
        "--delay",
        "20",
        "--jitter",
        "80",
        "--partition",
        "amparo|scout,stummel@4-24",
    ],
    "loss 0.5 + crash+recover stummel": ["--loss", "0.5", "--crash", "stummel@6", "--recover", "stummel@14"],
    "crash scout@12": ["--crash", "scout@12"],
    "crash stummel@20": ["--crash", "stummel@20"],
    "crash amparo@20": ["--crash", "amparo@20"],
    "crash amparo@30": ["--crash", "amparo@30"],
    "crash scout@2 + stummel@20": ["--crash", "scout@2", "--crash", "stummel@20"],
    "crash+recover amparo 2-6": ["--crash", "amparo@2", "--recover", "amparo@6"],
    "crash+recover scout 12-20": ["--crash", "scout@12", "--recover", "scout@20"],
    "crash+recover stummel 20-30": ["--crash", "stummel@20", "--recover", "stummel@30"],
    "crash+recover amparo twice": [
        *("--crash", "amparo@8", "--recover", "amparo@14"),
        *("--crash", "amparo@20", "--recover", "amparo@26"),
    ],
    "partition scout + crash amparo@10": ["--partition", "scout|stummel,amparo@3-23", "--crash", "amparo@10"],
    "loss 0.8 + partition amparo": ["--loss", "0.8", "--partition", "amparo|scout,stummel@6-26"],
    "delay + crash+recover amparo 8-20": [
        *("--delay", "50", "--jitter", "100"),
        *("--crash", "amparo@8", "--recover", "amparo@20"),
    ],
    "loss 0.3 + crash amparo@20": ["--loss", "0.3", "--crash", "amparo@20"],
}


@dataclass
class Outcome:
    """One run, classified."""

    success: bool = False
    stated: bool = False
    traceback: bool = False
    livelock: bool = False
    disagreement: bool = False
    duplicate: float = 0.0
    aware_duplicate: float = 0.0


def _plan_facts() -> tuple[str, dict[str, str], dict[str, int], set[str]]:
    """The root plan's name, success state -> entry point, entry point -> max, success-required entry points."""
    sys.path.insert(0, str(ROOT))
    from alica.io import load_library
    from alica.model import StateKind

    library = load_library(str(ROOT / PLAN))
    plan = library.plans["LunarMission"]
    success_of: dict[str, str] = {}
    for ep in plan.entry_points:
        for state in plan.reachable_states(ep.name):
            if plan.state(state).kind is StateKind.SUCCESS:
                success_of[state] = ep.name
    maxima = {ep.name: ep.max for ep in plan.entry_points if ep.max is not None}
    required = {ep.name for ep in plan.entry_points if ep.success_required}
    return plan.name, success_of, maxima, required


Partition = tuple[float, float, list[list[str]]]


def _separated(a: str, b: str, t: float, partitions: list[Partition]) -> bool:
    """Whether a partition keeps ``a`` and ``b`` apart at time ``t``."""
    for start, end, groups in partitions:
        if start <= t < end and not any(a in g and b in g for g in groups):
            return True
    return False


def _duplicate_time(
    events: list[dict[str, Any]], root: str, maxima: dict[str, int], success_of: dict[str, str]
) -> tuple[float, float]:
    """The longest times two live agents that can reach each other held the same one-robot task.

    Returns:
        The longest such time overall, and the longest while neither agent took
        the other for lost (silent for longer than the team timeout): a duplicate
        of the second kind is the engine's own disagreement, not loss.
    """
    partitions: list[Partition] = [
        (float(e["start"]), float(e["end"]), e["groups"])
        for e in events
        if e.get("event") == "fault" and e.get("fault") == "partition"
    ]
    # the partitions' edges are moments too: a pair's duplicate time starts when it heals
    edges = [{"t": t} for start, end, _ in partitions for t in (start, end)]
    timeline = sorted([*events, *edges], key=lambda e: float(e.get("t", 0.0)))
    holding: dict[str, str | None] = {}
    lost: set[tuple[str, str]] = set()
    since: dict[tuple[str, str, str, bool], float] = {}
    longest = {False: 0.0, True: 0.0}
    one_robot = {ep for ep, m in maxima.items() if m == 1}
    for e in timeline:
        agent, kind, t = e.get("agent"), e.get("event"), float(e.get("t", 0.0))
        if kind == "allocation" and e.get("key") == root and isinstance(e.get("entries"), dict):
            if agent in e["entries"]:
                holding[agent] = e["entries"][agent]
        elif kind == "transition" and e.get("key") == root:
            target = e.get("target")
            if target in success_of or str(target).endswith("Failed") or target == "SamplesMissing":
                holding[agent] = None
        elif kind in ("failure", "success") and e.get("key") == root:
            holding[agent] = None
        elif kind == "fault" and e.get("fault") in ("crash", "recover"):
            holding[agent] = None
        elif kind == "team":
            (lost.add if e.get("change") == "lost" else lost.discard)((str(agent), str(e.get("who"))))
        pairs = set()
        agents = sorted(a for a, ep in holding.items() if ep in one_robot)
        for i, a in enumerate(agents):
            for b in agents[i + 1 :]:
                if holding[a] == holding[b] and not _separated(a, b, t, partitions):
                    aware = (a, b) not in lost and (b, a) not in lost
                    pairs.add((a, b, str(holding[a]), aware))
        for pair in list(since):
            if pair not in pairs:
                longest[pair[3]] = max(longest[pair[3]], t - since.pop(pair))
        for pair in pairs:
            since.setdefault(pair, t)
    end = float(events[-1]["t"]) if events else 0.0
    for pair, start in since.items():
        longest[pair[3]] = max(longest[pair[3]], end - start)
    return max(longest.values()), longest[True]


def run_one(case: str, seed: int, max_time: float, wall: float) -> Outcome:
    """Run one case with one seed in its own process and classify it."""
    root, success_of, maxima, required = _plan_facts()
    with tempfile.TemporaryDirectory() as tmp:
        trace = os.path.join(tmp, "run.jsonl")
        args = [*BASE, *CASES[case], "--seed", str(seed), "--time-limit", str(max_time), "--json", "--trace", trace]
        try:
            proc = subprocess.run(
                [sys.executable, "-m", "alica.app.cli", *args],
                cwd=ROOT,
                capture_output=True,
                text=True,
                timeout=wall,
                check=False,
            )
        except subprocess.TimeoutExpired:
            return Outcome(traceback=True)
        if proc.returncode not in (0, 1) or "Traceback" in proc.stderr:
            return Outcome(traceback=True)
        try:
            summary = json.loads(proc.stdout)
        except json.JSONDecodeError:
            return Outcome(traceback=True)
        events = [json.loads(line) for line in Path(trace).read_text().splitlines() if line.strip()]
    out = Outcome(success=proc.returncode == 0)
    agents = summary["agents"]
    live = {n: a for n, a in agents.items() if a["status"] != "crashed"}
    if not out.success:
        if not summary["done"]:
            out.livelock = True
        else:
            out.stated = all(a["reason"] for a in live.values() if a["status"] != "success")
    done_eps = {
        success_of[e["target"]]
        for e in events
        if e.get("event") == "transition" and e.get("key") == root and e.get("target") in success_of
    }
    reported = {e["agent"] for e in events if e.get("event") == "success" and e.get("key") == root}
    if reported and not required <= done_eps:
        out.disagreement = True
    outcomes = {a["status"] for a in live.values()} - {"running"}
    if {"success", "failure"} <= outcomes:
        out.disagreement = True
    out.duplicate, out.aware_duplicate = _duplicate_time(events, root, maxima, success_of)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds per case (0..N-1)")
    parser.add_argument("--jobs", type=int, default=2, help="runs in parallel")
    parser.add_argument("--max-time", type=float, default=150.0, help="simulated time limit per run (s)")
    parser.add_argument("--wall", type=float, default=300.0, help="wall-clock guard per run (s)")
    parser.add_argument("--case", action="append", help="only these cases (repeatable)")
    args = parser.parse_args()
    cases = args.case or list(CASES)
    for case in cases:
        if case not in CASES:
            parser.error(f"no case named {case!r}; cases: {', '.join(CASES)}")
    jobs = [(c, s) for c in cases for s in range(args.seeds)]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(lambda job: run_one(job[0], job[1], args.max_time, args.wall), jobs))
    print(f"lunar team run, {args.seeds} seeds per case, limit {args.max_time:g} s simulated")
    print(
        "| case | runs | success | stated reason | tracebacks | livelocks | disagreements"
        " | dup > 1 s | longest dup (s) | aware dup > 1 s | longest aware dup (s) |"
    )
    print("| --- " * 11 + "|")
    total = Outcome()
    counts = [0] * 7
    aware_count = 0
    for case in cases:
        rows = [r for (c, _), r in zip(jobs, results, strict=True) if c == case]
        row = [
            len(rows),
            sum(r.success for r in rows),
            sum(r.stated for r in rows),
            sum(r.traceback for r in rows),
            sum(r.livelock for r in rows),
            sum(r.disagreement for r in rows),
            sum(r.duplicate > 1.0 for r in rows),
        ]
        longest = max((r.duplicate for r in rows), default=0.0)
        aware = [sum(r.aware_duplicate > 1.0 for r in rows), max((r.aware_duplicate for r in rows), default=0.0)]
        total.duplicate = max(total.duplicate, longest)
        total.aware_duplicate = max(total.aware_duplicate, aware[1])
        counts = [a + b for a, b in zip(counts, row, strict=True)]
        aware_count += int(aware[0])
        print(f"| {case} | " + " | ".join(map(str, row)) + f" | {longest:.2f} | {aware[0]} | {aware[1]:.2f} |")
    print(
        "| **all** | "
        + " | ".join(map(str, counts))
        + f" | {total.duplicate:.2f} | {aware_count} | {total.aware_duplicate:.2f} |"
    )


if __name__ == "__main__":
    main()
