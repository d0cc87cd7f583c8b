"""Hot reload: wall time from a saved plan file to the switch of the whole team, with 3 and 10 agents.

Two ways a team runs, each with the code ``--watch`` runs:

* **simulated**: one process, a :class:`SimulatedTeam` at 30 Hz paced on the wall
  clock (``alica run --watch``: :class:`PlanWatch`, :class:`TeamReloads`, :class:`WallPace`);
* **processes**: one ``alica agent --watch`` per agent over zenoh on loopback
  (``alica run --processes --watch``: :class:`ProcessTeam`), each watching the file.

A thread saves an edited plan file (the condition of a transition the agents
wait on, in another form that never holds each time) at a random moment every
1.5 to 2.5 s; the latency of an edit is the time from the save to the tick at
which the last agent adopted the new plans. The spread is the time between the
first and the last agent's adoption of one edit (0 in lock step; within a tick
for processes, whose clocks tick unaligned). The floor: one look at the files
(``POLL_S``, 0.1 s) plus the time the file must stay the same (one more look), plus the
leader's lead (``EngineConfig.reload_lead``, 0.5 s) so that every agent has the
announcement before the switch.

No peer does this: BehaviorTree.CPP, py_trees and the C++ ALICA engine rebuild a
tree to change it, losing its state (see docs/reload.md).

Run: ``.venv/bin/python bench/reload.py [--edits 20] [--sizes 3,10] [--modes simulated,processes]``
"""

from __future__ import annotations

import argparse
import contextlib
import io
import random
import statistics
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from alica.app.pacing import WallPace
from alica.app.plan_watch import PlanWatch, TeamReloads
from alica.engine import EngineConfig, SimulatedTeam
from alica.io import Loader, load_library
from alica.io.loader import plans_dir
from alica.model.digest import library_digest

PLAN = (plans_dir() / "examples" / "gate.yaml").read_text(encoding="utf-8")  # the hot-reload example
WAIT = 'condition: "go"}'


class Editor(threading.Thread):
    """Saves the plan file ``edits`` times, each with another condition, at random moments; keeps when."""

    def __init__(self, plan: Path, edits: int, seed: int, clock: Any = time.monotonic, first: float = 2.0) -> None:
        super().__init__(daemon=True)
        self.plan, self.edits, self.clock, self.first = plan, edits, clock, first
        self.rng = random.Random(seed)
        self.saved: list[tuple[float, str]] = []  # (when, the text's form index)
        self.stop = threading.Event()

    def run(self) -> None:
        original = self.plan.read_text(encoding="utf-8")
        if self.stop.wait(self.first):
            return
        for edit in range(1, self.edits + 1):
            if self.stop.wait(self.rng.uniform(1.5, 2.5)):
                return
            # a condition that never holds, different in every edit (every edit is a library of its own)
            text = original.replace(WAIT, f'condition: "go or 0 > {edit}"}}')
            self.plan.write_text(text, encoding="utf-8")
            self.saved.append((self.clock(), text))


def _percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def simulated(size: int, edits: int, seed: int) -> dict[str, Any]:
    """Latencies of ``edits`` saves for a simulated team of ``size`` paced on the wall clock."""
    with tempfile.TemporaryDirectory() as tmp:
        plan = Path(tmp) / "team.yaml"
        plan.write_text(PLAN, encoding="utf-8")
        library = load_library(plan)
        config = EngineConfig(frequency=30.0)
        team = SimulatedTeam(library, "Top", {f"r{i:02d}": "Worker" for i in range(size)}, config=config, seed=seed)
        reloads = TeamReloads(PlanWatch(plan, library, lambda: Loader().load(plan)), team, [])
        pace = WallPace(1.0)
        editor = Editor(plan, edits, seed)
        digests: dict[str, float] = {}  # digest -> when every agent ran it
        overran = 0
        editor.start()
        try:
            while editor.is_alive() or (editor.saved and time.monotonic() < editor.saved[-1][0] + 3.0):
                began = time.monotonic()
                team.tick()
                reloads.look()
                running = {e.reloads.digest for e in team.running()}
                if len(running) == 1:
                    digests.setdefault(running.pop(), time.monotonic())
                if time.monotonic() - began > config.period:
                    overran += 1
                pace(team.now())
                if team.now() > 3.0 * edits + 30.0:
                    break
        finally:
            editor.stop.set()
        return _latencies(editor, digests, {}, team.ticks, overran)


def processes(size: int, edits: int, seed: int) -> dict[str, Any]:
    """Latencies of ``edits`` saves for ``size`` agent processes over zenoh, each watching the file."""
    from alica.app.processes import ProcessTeam

    with tempfile.TemporaryDirectory() as tmp:
        plan = Path(tmp) / "team.yaml"
        plan.write_text(PLAN, encoding="utf-8")
        names = [f"r{i:02d}" for i in range(size)]
        roster = ",".join(f"{n}:Worker" for n in names)
        team = ProcessTeam(str(plan), roster, names, ["--watch", "--seed", str(seed)], Path(tmp))
        limit = 6.0 + 2.6 * edits + 10.0
        started = threading.Event()
        with contextlib.redirect_stderr(io.StringIO()):  # the agents' reload lines
            team.launch()
            editor = Editor(plan, edits, seed, clock=lambda: time.time() - team.start, first=1e9)
            runner = threading.Thread(
                target=team.run, args=([], limit), kwargs={"on_started": lambda *_: started.set()}, daemon=True
            )
            runner.start()
            started.wait(60.0)
            editor.first = 2.0  # (after every agent process started)
            editor.start()
            editor.join()
            time.sleep(3.0)  # the last edit's switch (a bench, not a test)
            team.stop()
            runner.join(10.0)
        summary = team.summary("Top", seed)
        digests: dict[str, float] = {}
        spread: dict[str, float] = {}
        for record in summary["reloads"]:
            if record.get("status") == "adopted":
                digest, t = str(record["adopted"]), float(record["t"])
                first = spread.setdefault(digest, t)
                spread[digest] = min(first, t)
                digests[digest] = max(digests.get(digest, t), t)
        counts = {d: sum(1 for r in summary["reloads"] if r.get("adopted") == d) for d in digests}
        complete = {d: t for d, t in digests.items() if counts[d] == size}
        overruns = sum(int(a.get("overruns") or 0) for a in summary["agents"].values())
        ticks = sum(int(a.get("ticks") or 0) for a in summary["agents"].values())
        return _latencies(editor, complete, {d: digests[d] - spread[d] for d in complete}, ticks, overruns)


def _latencies(
    editor: Editor, switched: dict[str, float], spreads: dict[str, float], ticks: int, overruns: int
) -> dict[str, Any]:
    latencies = []
    missed = 0
    for when, text in editor.saved:
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "team.yaml"
            path.write_text(text, encoding="utf-8")
            digest = library_digest(Loader().load(path))
        at = switched.get(digest)
        if at is None or at < when:
            missed += 1
            continue
        latencies.append(at - when)
    return {
        "edits": len(editor.saved),
        "switched": len(latencies),
        "missed": missed,
        "median_s": statistics.median(latencies) if latencies else float("nan"),
        "p99_s": _percentile(latencies, 0.99) if latencies else float("nan"),
        "max_spread_s": max(spreads.values(), default=0.0),
        "ticks": ticks,
        "overruns": overruns,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edits", type=int, default=20)
    parser.add_argument("--sizes", default="3,10")
    parser.add_argument("--modes", default="simulated,processes")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rows = []
    for mode in args.modes.split(","):
        for size in (int(s) for s in args.sizes.split(",")):
            result = (simulated if mode == "simulated" else processes)(size, args.edits, args.seed)
            rows.append((mode, size, result))
            print(f"({mode}, {size} agents done)", flush=True)
    print()
    print(
        f"{'mode':<10} {'agents':>6} {'edits':>5} {'switched':>8} {'median s':>9} {'p99 s':>7} {'spread s':>9} {'overruns':>9}"
    )
    for mode, size, r in rows:
        print(
            f"{mode:<10} {size:>6} {r['edits']:>5} {r['switched']:>8} {r['median_s']:>9.3f} {r['p99_s']:>7.3f} "
            f"{r['max_spread_s']:>9.3f} {r['overruns']:>5}/{r['ticks']}"
        )


if __name__ == "__main__":
    main()
