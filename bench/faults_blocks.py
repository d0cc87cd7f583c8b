"""Fault matrix of the blocks demo: crashes and recoveries of holders, leaders and idle robots.

For each case (who crashes, when, whether it recovers, with or without
opponents) it runs the demo (3 robots, 5 blocks) for ``--seeds`` seeds, each
run in a fresh process with a wall-time bound, and prints a markdown table of
successes, tracebacks and timeouts (the time limit passed, or the process
ran over its wall bound) per case.

* ``leader``: r1, the lowest robot, which leads the planning problem;
* ``holder``: the first robot that holds a block at or after the time;
* ``idle``: the highest robot that holds nothing at the time.

A crash is a power loss (the robot stops, drops what it holds, goes
silent); a recovery restarts it 10 s later with an empty memory.

Run: ``.venv/bin/python bench/faults_blocks.py [--seeds 20] [--times 3.5,12,25] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import itertools
import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

RECOVER_AFTER = 10.0
WHO = ("leader", "holder", "idle")


@dataclass(frozen=True)
class Case:
    who: str
    at: float
    recover: bool
    opponents: int

    def label(self) -> str:
        return f"{self.who}@{self.at:g}{' +recover' if self.recover else ''}{' +opponent' if self.opponents else ''}"


def run_one(case: Case, seed: int, time_limit: float) -> dict[str, Any]:
    """One run in this process: the demo's summary and which robot crashed."""
    from alica.app.demos.blocksworld import DemoConfig, run_demo

    hit: list[str] = []

    def pick(team: Any) -> str | None:
        robots = team.world.robots
        alive = [n for n in sorted(team.engines) if n not in team.crashed]
        if case.who == "leader":
            return alive[0] if alive else None
        if case.who == "holder":
            return next((n for n in alive if robots[n].arm.held is not None), None)
        return next((n for n in reversed(alive) if robots[n].arm.held is None), None)

    def fault(team: Any) -> None:
        if hit:
            return
        name = pick(team)
        if name is None:
            return
        hit.append(name)
        team.crash(name)
        if case.recover:
            team.recover(name, at=team.now() + RECOVER_AFTER)

    tries = 60 if case.who == "holder" else 1  # a holder: the first one from the time on, every 0.5 s
    actions = [(case.at + 0.5 * i, fault) for i in range(tries)]
    config = DemoConfig(agents=3, blocks=5, seed=seed, opponents=case.opponents, time_limit=time_limit)
    result = run_demo(config, actions=actions)
    return {"success": result.success, "sim_time_s": result.sim_time_s, "crashed": hit}


def _child(case: Case, seed: int, time_limit: float, wall: float) -> dict[str, Any]:
    command = [
        sys.executable,
        __file__,
        "--one",
        json.dumps([case.who, case.at, case.recover, case.opponents, seed, time_limit]),
    ]
    try:
        run = subprocess.run(command, capture_output=True, text=True, timeout=wall)
    except subprocess.TimeoutExpired:
        return {"outcome": "timeout"}
    if "Traceback" in run.stderr or run.returncode != 0:
        return {"outcome": "traceback", "stderr": run.stderr[-1500:]}
    summary = json.loads(run.stdout.strip().splitlines()[-1])
    return {"outcome": "success" if summary["success"] else "timeout", **summary}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--times", default="3.5,12,25", help="crash times in simulated seconds")
    parser.add_argument("--who", default=",".join(WHO), help="which robots crash: leader,holder,idle")
    parser.add_argument("--opponents", default="0,1", help="opponent counts")
    parser.add_argument("--recover", default="no,yes")
    parser.add_argument("--time-limit", type=float, default=300.0)
    parser.add_argument("--wall", type=float, default=300.0, help="wall seconds per run before it counts as a timeout")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        who, at, recover, opponents, seed, limit = json.loads(args.one)
        print(json.dumps(run_one(Case(who, at, recover, opponents), seed, limit)))
        return 0
    cases = [
        Case(who, float(at), recover == "yes", int(opp))
        for opp, who, at, recover in itertools.product(
            args.opponents.split(","), args.who.split(","), args.times.split(","), args.recover.split(",")
        )
    ]
    jobs = [(case, seed) for case in cases for seed in range(args.seeds)]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        outcomes = list(pool.map(lambda job: _child(job[0], job[1], args.time_limit, args.wall), jobs))
    print("| case | runs | success | tracebacks | timeouts |\n|---|---|---|---|---|")
    totals = [0, 0, 0, 0]
    for case in cases:
        mine = [o for (c, _), o in zip(jobs, outcomes, strict=True) if c == case]
        counts = [sum(o["outcome"] == k for o in mine) for k in ("success", "traceback", "timeout")]
        totals = [totals[0] + len(mine), *(t + c for t, c in zip(totals[1:], counts, strict=True))]
        print(f"| {case.label()} | {len(mine)} | {counts[0]} | {counts[1]} | {counts[2]} |")
    print(f"| all | {totals[0]} | {totals[1]} | {totals[2]} | {totals[3]} |")
    for (case, seed), outcome in zip(jobs, outcomes, strict=True):
        if outcome["outcome"] != "success":
            print(f"- {case.label()} seed {seed}: {outcome['outcome']} {outcome.get('stderr', '')[-300:]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
