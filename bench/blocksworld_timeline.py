"""Where the simulated time of a blocks-world run goes, per agent (issue 19: more robots should finish sooner).

Each run is ``alica demo blocksworld`` without opponents, run through the
demo's Python API in a fresh process (a run is repeatable in a fresh
process), with the trace written to ``DIR/trace.jsonl``. A read-only sampler
looks at every agent once per engine tick (0.1 s simulated): which state of
the generated plan it is in, which skill phase its behaviour is in, whether
the step_done facts its wait state needs are there, whether its hand holds a
block. The sampler only reads; the runs' simulated times are those of
``alica demo blocksworld --json`` for the same seed.

Every tick of every agent goes to one category:

- ``planning``: in the WaitPlan before the team's first plan exists;
- ``waitplan``: in the WaitPlan later (a replan) or in the generated plan's Standby;
- ``drive``: a manipulation skill's approach to its stand-off point (and the
  turn to the work site), or Putdown's drive to a free spot;
- ``sideblock``: a manipulation skill waiting because every side of its work site is taken;
- ``manip``: arm planning, arm motion, grip and release, the check after it;
- ``wait_task``: a wait state whose step waits for a step_done of another task;
- ``wait_pre``: a wait state whose step_done facts are there but whose
  precondition does not hold yet in the agent's world model (the perception's lag);
- ``between``: in a task's success or failure state, before the next task is allocated;
- ``idle_after``: after the agent's last step, until the run ends (any state);
- ``other``: anything else (ticks without a behaviour, between states).

Per run it also derives, from the first generated plan, the dependency DAG
the plan encodes (``alica.prophet.tasks``: the steps of a task run one after
the other; a step waits for the latest earlier step of another task on each
of its blocks, ``_predecessors``), its longest chain in steps (``cp``), the
same chain weighted by the step durations measured in the run (``cp_s``),
the work (sum of the measured step durations), ``lb_s = max(cp_s, work / N)``
and ``sched_s``: the makespan of the plan's task chains on N robots with the
measured step durations and no overhead (tasks taken in task order by the
first robot free, as the engine's reuse rule does).

Run:
``.venv/bin/python bench/blocksworld_timeline.py [--agents 1-5] [--blocks 8] [--seeds 0-3] [--jobs 2]``
prints a table per block count (means over seeds; shares in % of the agents'
time N x makespan) and writes ``build/bench/timeline/`` (one folder per run,
``runs.tsv``). ``--detail DIR`` prints one run's plan steps and agent
timelines; ``--one A B S DIR`` runs one run in this process.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
from collections import defaultdict
from collections.abc import Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "build" / "bench" / "timeline"
CATEGORIES = (
    "planning",
    "waitplan",
    "drive",
    "sideblock",
    "manip",
    "wait_task",
    "wait_pre",
    "between",
    "idle_after",
    "other",
)
#: Simulated seconds of a step without other robots around: the mean over the 1-agent runs with 8 blocks, seeds 0-3.
NOMINAL_STEP_S = 8.0
#: The plan metrics of ``runs.tsv``.
METRICS = (
    "steps",
    "tasks",
    "cp",
    "cp_s",
    "work_s",
    "lb_s",
    "sched_s",
    "ep_cp",
    "ep_cp_s",
    "ep_sched_s",
    "sched_nom_s",
    "ep_sched_nom_s",
    "step_s",
    "drive_per_step",
    "manip_per_step",
    "first_plan_s",
    "executed",
    "failed",
    "bound",
    "tallest",
    "near",
    "near_idle",
    "complete",
)
_WAIT = re.compile(r"^T(\d+)_Wait(\d+)$")
_RUN = re.compile(r"^T(\d+)_S(\d+)_(\w+)$")
_DONE = re.compile(r"^T(\d+)_(Done|Failed)$")
_TOKEN = re.compile(r"step_done\((\w+)\)")


# -- one run, in this process ---------------------------------------------------------------------------------------


def _leaf(engine: Any) -> tuple[list[tuple[str, str | None]], Any, Any]:
    """The agent's plan path (plan, state) root first, the deepest generated-plan node, and its running behaviour."""
    path: list[tuple[str, str | None]] = []
    node = engine.root
    generated = None
    bt = None
    while node is not None:
        path.append((node.plan.name, node.state))
        if node.plan.name.startswith("StackBlocks_"):
            generated = node
        following = None
        for slot in node.slots:
            if slot.runner is not None and slot.runner.bt is not None:
                bt = slot.runner.bt
            if slot.node is not None:
                following = slot.node
        node = following
    return path, generated, bt


def _sample(engine: Any, robot: Any) -> dict[str, Any]:
    """What one agent does now (read only)."""
    path, generated, bt = _leaf(engine)
    row: dict[str, Any] = {"path": [p for p, _ in path], "state": path[-1][1] if path else None}
    if generated is not None:
        row["gen"] = generated.plan.name
        row["gstate"] = generated.state
        state = generated.state or ""
        if _WAIT.match(state):
            missing = []
            for tr in generated.plan.transitions:
                if tr.source == state and tr.condition is not None:
                    missing = [
                        t for t in _TOKEN.findall(tr.condition.text) if not engine.world_model.holds("step_done", t)
                    ]
            row["missing"] = missing
    if bt is not None:
        row["bt"] = bt.name
        phase = getattr(bt, "phase", None)
        if phase is not None:
            row["phase"] = phase
        row["fb"] = (bt.feedback_message or "")[:160]
    if robot is not None:
        row["xy"] = [round(float(robot.pose[0]), 3), round(float(robot.pose[1]), 3)]
        arm = getattr(robot, "arm", None)
        row["held"] = arm.held.name if arm is not None and arm.held is not None else None
    return row


def run_one(agents: int, blocks: int, seed: int, out: Path, time_limit: float, opponents: int = 0) -> dict[str, Any]:
    """Run the demo once with the sampler; write ``run.json`` and ``samples.jsonl`` to ``out``."""
    from alica.app.demos.blocksworld import DemoConfig, run_demo
    from alica.prophet import made_plans
    from alica.prophet.tasks import _objects, _predecessors

    out.mkdir(parents=True, exist_ok=True)
    held: dict[str, Any] = {}
    samples = (out / "samples.jsonl").open("w", encoding="utf-8")

    def tick(team: Any) -> None:
        held["team"] = team
        now = round(team.now(), 3)
        robots = getattr(team.world, "robots", {})
        for name, engine in sorted(team.engines.items()):
            row = _sample(engine, robots.get(name))
            row["t"], row["agent"] = now, name
            samples.write(json.dumps(row, separators=(",", ":")) + "\n")
        team.at(team.now() + team.config.period * 0.5, "timeline sampler", lambda: tick(team))

    config = DemoConfig(agents=agents, opponents=opponents, blocks=blocks, seed=seed, time_limit=time_limit)
    try:
        result = run_demo(config, actions=[(0.0, tick)], out=out)
    finally:
        samples.close()
    plans = []
    team = held.get("team")
    seen: set[str] = set()
    for engine in team.engines.values() if team is not None else ():
        for generation, version, created in made_plans(engine):
            name = created.plan.name
            if name in seen:
                continue
            seen.add(name)
            plans.append(
                {
                    "name": name,
                    "generation": generation,
                    "version": version,
                    "tasks": [
                        [
                            {"index": s.index, "label": s.label, "robot": s.robot, "objects": sorted(_objects(s))}
                            for s in t
                        ]
                        for t in created.tasks
                    ],
                    "preds": {str(k): v for k, v in _predecessors(created.tasks).items()},
                }
            )
    summary = {"agents": agents, "blocks": blocks, "seed": seed, "result": result.as_json(), "plans": plans}
    (out / "run.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")
    return summary


# -- analysis ---------------------------------------------------------------------------------------------------------


def _classify(row: dict[str, Any]) -> str:
    gstate = row.get("gstate")
    if gstate:
        if _WAIT.match(gstate):
            return "wait_task" if row.get("missing") else "wait_pre"
        if _RUN.match(gstate):
            phase = row.get("phase")
            if row.get("bt") == "FindFreeSpot":
                return "drive"
            if phase in ("check", "approach"):
                return "sideblock" if str(row.get("fb", "")).startswith("waiting: every side") else "drive"
            if phase in ("plan", "execute", "verify"):
                return "manip"
            return "other"
        if gstate == "Standby":
            return "waitplan"
        if _DONE.match(gstate):
            return "between"
    if "DriveToFreePosition" in row.get("path", ()):
        return "waitplan"  # "planning" before the first plan: decided by the caller
    if row.get("path") and row["path"][0] == "BlocksWorldMission" and row.get("state") == "Done":
        return "idle_after"
    return "other"


def _step_times(trace: Iterable[dict[str, Any]]) -> dict[tuple[str, int, int], list[Any]]:
    """(plan, task, step) -> [agent, start, end] of the run states, from the trace's transitions."""
    out: dict[tuple[str, int, int], list[Any]] = {}
    for ev in trace:
        if ev.get("event") != "transition" or not str(ev.get("plan", "")).startswith("StackBlocks_"):
            continue
        target, source = str(ev.get("target", "")), str(ev.get("source", ""))
        m = _RUN.match(target)
        if m:
            out[(ev["plan"], int(m.group(1)), int(m.group(2)))] = [ev["agent"], float(ev["t"]), None]
        m = _RUN.match(source)
        if m:
            key = (ev["plan"], int(m.group(1)), int(m.group(2)))
            if key in out and out[key][0] == ev["agent"]:
                out[key][2] = float(ev["t"])
    return out


def _dag(plan: dict[str, Any]) -> dict[int, list[int]]:
    """Step index -> the steps it waits for: the previous step of its task and the step_done predecessors."""
    deps: dict[int, list[int]] = {}
    for task in plan["tasks"]:
        for k, step in enumerate(task):
            deps[step["index"]] = sorted({*([task[k - 1]["index"]] if k else []), *plan["preds"][str(step["index"])]})
    return deps


def _episode_dag(plan: dict[str, Any]) -> dict[int, list[int]]:
    """The DAG if every hand episode (a Pickup or Unstack and the steps up to the next one) were a task of its own.

    The same rule as ``_predecessors``: a step waits for the previous step of its episode and for the latest earlier
    step of another episode on each of its blocks. That is the plan deordered as far as the hand allows.
    """
    episode: dict[int, int] = {}
    previous: dict[int, int] = {}
    count = -1
    for task in plan["tasks"]:
        for k, step in enumerate(task):
            if k == 0 or step["label"].startswith(("Pickup", "Unstack")):
                count += 1
            else:
                previous[step["index"]] = task[k - 1]["index"]
            episode[step["index"]] = count
    ordered = sorted((s for task in plan["tasks"] for s in task), key=lambda s: s["index"])
    last: dict[str, int] = {}
    deps: dict[int, list[int]] = {}
    for step in ordered:
        i = step["index"]
        before = {previous[i]} if i in previous else set()
        for obj in step["objects"]:
            h = last.get(obj)
            if h is not None and episode[h] != episode[i]:
                before.add(h)
            last[obj] = i
        deps[i] = sorted(before)
    return deps


def problem_bound(start: Sequence[Sequence[str]], goal: Sequence[Sequence[str]]) -> int:
    """Steps that must happen one after another in any plan, with as many robots as wanted.

    Per goal tower: the blocks over the top of its well-placed part are unstacked one by one (or, without a
    well-placed part, the bottom block is dug out, unstacked and put down); a block is held at the earliest after
    the blocks over it and its own pick; the tower's blocks are stacked one after the other. The largest over the
    towers; robots getting in each other's way and blocks shared by two towers are left out, so it is a bound.
    """
    below: dict[str, str] = {}
    above_count: dict[str, int] = {}
    for stack in start:
        for k, block in enumerate(stack):
            below[block] = stack[k - 1] if k else ""
            above_count[block] = len(stack) - k - 1
    best = 0
    for tower in goal:
        placed = 0
        while placed < len(tower) and below.get(tower[placed]) == (tower[placed - 1] if placed else ""):
            placed += 1
        if placed == len(tower):
            continue
        if placed:
            ready, first = above_count[tower[placed - 1]], placed
        else:
            ready, first = above_count[tower[0]] + 2, 1  # dig the bottom block out, unstack it, put it down
        for block in tower[first:]:
            ready = max(ready, above_count[block] + 1) + 1  # held (after its digging and pick), then stacked
        best = max(best, ready)
    return best


def _crowding(rows: dict[str, list[tuple[float, str, dict[str, Any]]]], radius: float = 1.2) -> dict[str, float]:
    """While an agent drives to a step: the mean number of other robots within ``radius`` m, and of those how many idle."""
    at: dict[float, dict[str, tuple[str, list[float]]]] = defaultdict(dict)
    for agent, seq in rows.items():
        for t, cat, row in seq:
            if row.get("xy") is not None:
                at[t][agent] = (cat, row["xy"])
    near = idle = samples = 0
    for snapshot in at.values():
        for agent, (cat, xy) in snapshot.items():
            if cat not in ("drive", "sideblock"):
                continue
            samples += 1
            for other, (ocat, oxy) in snapshot.items():
                if other != agent and (xy[0] - oxy[0]) ** 2 + (xy[1] - oxy[1]) ** 2 < radius**2:
                    near += 1
                    idle += ocat not in ("drive", "sideblock", "manip")
    return {"near": near / samples if samples else 0.0, "near_idle": idle / samples if samples else 0.0}


def _longest(deps: dict[int, list[int]], weight: dict[int, float]) -> tuple[float, list[int]]:
    best: dict[int, tuple[float, list[int]]] = {}
    for i in sorted(deps):  # plan order is a topological order
        before = max((best[d] for d in deps[i]), key=lambda b: b[0], default=(0.0, []))
        best[i] = (before[0] + weight.get(i, 0.0), [*before[1], i])
    return max(best.values(), key=lambda b: b[0], default=(0.0, []))


def _simulate(
    chains: Sequence[Sequence[int]], deps: dict[int, list[int]], dur: dict[int, float], agents: int
) -> float | None:
    """The makespan of ``chains`` (tasks: steps one after the other) on ``agents`` robots, no overhead.

    A robot without a chain takes the next one in order when it is free (the engine's reuse rule); a step starts
    when its robot is free and the steps it waits for are done. ``None``: the robots all wait for chains nobody holds.
    """
    free = [0.0] * agents
    holding: list[list[int] | None] = [None] * agents
    queue = [list(c) for c in chains]
    done: dict[int, float] = {}
    total = sum(len(c) for c in chains)
    while len(done) < total:
        idle = [a for a in range(agents) if holding[a] is None]
        ready = [
            (max([free[a], *(done[d] for d in deps[chain[0]])]), a)
            for a in range(agents)
            if (chain := holding[a]) and all(d in done for d in deps[chain[0]])
        ]
        take = min(((free[a], a) for a in idle), default=None) if queue else None
        if take is not None and (not ready or take[0] <= min(ready)[0]):
            holding[take[1]] = queue.pop(0)
            continue
        if not ready:
            return None
        start, a = min(ready)
        chain = holding[a]
        assert chain is not None
        i = chain.pop(0)
        done[i] = free[a] = start + dur.get(i, 0.0)
        if not chain:
            holding[a] = None
    return max(done.values(), default=0.0)


def _chains(plan: dict[str, Any], episodes: bool) -> list[list[int]]:
    """The plan's tasks as chains of step indices, or its hand episodes (in plan order)."""
    if not episodes:
        return [[s["index"] for s in task] for task in plan["tasks"]]
    chains: list[list[int]] = []
    for task in plan["tasks"]:
        for k, step in enumerate(task):
            if k == 0 or step["label"].startswith(("Pickup", "Unstack")):
                chains.append([])
            chains[-1].append(step["index"])
    return sorted(chains, key=lambda c: c[0])


def analyse(folder: Path) -> dict[str, Any]:
    """The categories, plan metrics and step timeline of one run folder."""
    summary = json.loads((folder / "run.json").read_text(encoding="utf-8"))
    result = summary["result"]
    makespan = float(result["sim_time_s"])
    agents = int(summary["agents"])
    trace = [json.loads(line) for line in (folder / "trace.jsonl").read_text(encoding="utf-8").splitlines() if line]
    first_plan = min(
        (float(ev["t"]) for ev in trace if ev.get("event") == "problem" and ev.get("phase") == "plan"), default=makespan
    )
    rows: dict[str, list[tuple[float, str, dict[str, Any]]]] = defaultdict(list)
    for line in (folder / "samples.jsonl").read_text(encoding="utf-8").splitlines():
        row = json.loads(line)
        if row["t"] >= makespan:
            continue
        cat = _classify(row)
        if cat == "waitplan" and row["t"] < first_plan and "DriveToFreePosition" in row.get("path", ()):
            cat = "planning"
        rows[row["agent"]].append((row["t"], cat, row))
    per_agent: dict[str, dict[str, float]] = {}
    holding_wait: dict[str, float] = {}
    for agent, seq in rows.items():
        seq.sort(key=lambda r: r[0])
        last_run = max((t for t, cat, _ in seq if cat in ("drive", "sideblock", "manip")), default=-1.0)
        times: dict[str, float] = dict.fromkeys(CATEGORIES, 0.0)
        hold = 0.0
        for k, (t, cat, row) in enumerate(seq):
            dt = (seq[k + 1][0] if k + 1 < len(seq) else makespan) - t
            if t > last_run and cat != "planning":
                cat = "idle_after"
            times[cat] += dt
            if cat in ("wait_task", "wait_pre") and row.get("held"):
                hold += dt
        per_agent[agent] = times
        holding_wait[agent] = hold
    total = {c: sum(a[c] for a in per_agent.values()) for c in CATEGORIES}
    share = {c: 100.0 * v / (agents * makespan) if makespan else 0.0 for c, v in total.items()}
    metrics_problem = {
        "bound": problem_bound(result["start"], result["goal"]),
        "tallest": max(map(len, result["goal"])),
    }
    steps = _step_times(trace)
    for span in steps.values():
        if span[2] is None and result["success"]:
            span[2] = max(makespan, span[1])  # the run ends (goal reached) before the last steps leave their run state
    plans = summary["plans"]
    failed = sum(1 for ev in trace if ev.get("event") == "transition" and str(ev.get("target", "")).endswith("_Failed"))
    metrics: dict[str, Any] = {"plans": len(plans), "failed": failed, "executed": len(steps), **metrics_problem}
    timeline = []
    if plans:
        plan = plans[0]
        deps = _dag(plan)
        dur: dict[int, float] = {}
        for i, task in enumerate(plan["tasks"]):
            for k, step in enumerate(task):
                got: list[Any] | None = steps.get((plan["name"], i, k))
                if got is not None and got[2] is not None:
                    dur[step["index"]] = got[2] - got[1]
                timeline.append(
                    {
                        "index": step["index"],
                        "task": i,
                        "label": step["label"],
                        "planned": step["robot"],
                        "agent": got[0] if got else None,
                        "start": got[1] if got else None,
                        "end": got[2] if got else None,
                        "deps": deps[step["index"]],
                    }
                )
        measured = [e - b for _, b, e in steps.values() if e is not None]
        fill = statistics.fmean(measured) if measured else 0.0
        complete = len(dur) == len(deps)
        for i in deps:
            dur.setdefault(i, fill)  # a step of the first plan not run (replanned): the run's mean step time
        cp_steps = _longest(deps, dict.fromkeys(deps, 1.0))
        ep_deps = _episode_dag(plan)
        nominal = dict.fromkeys(deps, NOMINAL_STEP_S)
        work = sum(dur.values())
        runs = max(1, len(steps))
        metrics.update(
            steps=len(deps),
            tasks=len(plan["tasks"]),
            cp=int(cp_steps[0]),
            cp_chain=cp_steps[1],
            ep_cp=int(_longest(ep_deps, dict.fromkeys(ep_deps, 1.0))[0]),
            sched_nom_s=_simulate(_chains(plan, False), deps, nominal, agents),
            ep_sched_nom_s=_simulate(_chains(plan, True), ep_deps, nominal, agents),
            step_s=sum(e - b for _, b, e in steps.values() if e is not None) / runs,
            drive_per_step=(total["drive"] + total["sideblock"]) / runs,
            manip_per_step=total["manip"] / runs,
            first_plan_s=first_plan,
            complete=complete,
            **_crowding(rows),
        )
        if complete:  # measured step times of the first plan: only when the run carried it out whole
            cp_time = _longest(deps, dur)
            metrics.update(
                cp_s=cp_time[0],
                work_s=work,
                lb_s=max(cp_time[0], work / agents),
                sched_s=_simulate(_chains(plan, False), deps, dur, agents),
                ep_cp_s=_longest(ep_deps, dur)[0],
                ep_sched_s=_simulate(_chains(plan, True), ep_deps, dur, agents),
            )
    timeline.sort(key=lambda s: s["index"])
    return {
        "agents": agents,
        "blocks": summary["blocks"],
        "seed": summary["seed"],
        "success": result["success"],
        "sim_s": makespan,
        "replans": result["replans"],
        "share": share,
        "per_agent": per_agent,
        "holding_wait": holding_wait,
        "metrics": metrics,
        "timeline": timeline,
        "segments": {a: _segments(seq, makespan) for a, seq in rows.items()},
    }


def _segments(seq: Sequence[tuple[float, str, dict[str, Any]]], end: float) -> list[tuple[float, float, str, str]]:
    """Runs of one category and state: (start, end, category, generated-plan state or plan)."""
    out: list[tuple[float, float, str, str]] = []
    last_run = max((t for t, cat, _ in seq if cat in ("drive", "sideblock", "manip")), default=-1.0)
    for t, cat, row in seq:
        if t > last_run and cat != "planning":
            cat = "idle_after"
        where = str(row.get("gstate") or (row.get("path") or ["?"])[-1])
        if out and out[-1][2] == cat and out[-1][3] == where:
            out[-1] = (out[-1][0], t, cat, where)
        else:
            out.append((t, t, cat, where))
    return [(a, round(b + 0.1, 2) if b + 0.1 < end else end, c, w) for a, b, c, w in out]


# -- the experiment ---------------------------------------------------------------------------------------------------


def _spawn(agents: int, blocks: int, seed: int, folder: Path, time_limit: float) -> Path:
    argv = [sys.executable, str(Path(__file__).resolve()), "--one", str(agents), str(blocks), str(seed), str(folder)]
    argv += ["--time-limit", str(time_limit)]
    done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, check=False, timeout=time_limit * 4 + 300)
    if done.returncode != 0 or not (folder / "run.json").exists():
        tail = done.stderr.strip().splitlines()[-1:] or [f"exit {done.returncode}"]
        print(f"run a{agents} b{blocks} s{seed} failed: {tail[0]}", file=sys.stderr)
    return folder


def _range(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        low, _, high = part.partition("-")
        out.extend(range(int(low), int(high or low) + 1))
    return out


def _mean(values: Iterable[float | None]) -> float | None:
    got = [v for v in values if v is not None]
    return statistics.fmean(got) if got else None


def _fmt(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _cells(results: Sequence[dict[str, Any]]) -> list[tuple[int, int, list[dict[str, Any]], list[dict[str, Any]]]]:
    cells: dict[tuple[int, int], list[dict[str, Any]]] = defaultdict(list)
    for r in results:
        cells[(r["blocks"], r["agents"])].append(r)
    return [(b, a, runs, [r for r in runs if r["success"]]) for (b, a), runs in sorted(cells.items())]


def table(results: Sequence[dict[str, Any]]) -> str:
    """Two markdown tables per (blocks, agents), means over the successful seeds: where the time goes; the plans."""
    head = ["blocks", "agents", "ok", "sim s", "replans", "failed steps", *CATEGORIES, "hold-wait s"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for blocks, agents, runs, ok in _cells(results):
        row = [str(blocks), str(agents), f"{len(ok)}/{len(runs)}", _fmt(_mean(r["sim_s"] for r in ok))]
        row += [_fmt(_mean(r["replans"] for r in ok)), _fmt(_mean(r["metrics"].get("failed") for r in ok))]
        row += [_fmt(_mean(r["share"][c] for r in ok)) for c in CATEGORIES]
        row += [_fmt(_mean(sum(r["holding_wait"].values()) for r in ok))]
        lines.append("| " + " | ".join(row) + " |")
    head = ["blocks", "agents", "bound", "steps", "tasks", "cp", "ep_cp", "sched_nom_s", "ep_sched_nom_s", "step_s"]
    head += [
        "drive/step",
        "manip/step",
        "near",
        "near idle",
        "complete",
        "cp_s",
        "work_s",
        "lb_s",
        "sched_s",
        "ep_cp_s",
        "ep_sched_s",
    ]
    lines += ["", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for blocks, agents, _, ok in _cells(results):
        m = [r["metrics"] for r in ok]
        row = [str(blocks), str(agents)]
        row += [_fmt(_mean(x.get(k) for x in m)) for k in ("bound", "steps", "tasks", "cp", "ep_cp", "sched_nom_s")]
        row += [_fmt(_mean(x.get(k) for x in m)) for k in ("ep_sched_nom_s", "step_s", "drive_per_step")]
        row += [_fmt(_mean(x.get("manip_per_step") for x in m))]
        row += [_fmt(_mean(x.get(k) for x in m), 2) for k in ("near", "near_idle")]
        row += [f"{sum(1 for x in m if x.get('complete'))}/{len(m)}"]
        row += [_fmt(_mean(x.get(k) for x in m)) for k in ("cp_s", "work_s", "lb_s", "sched_s", "ep_cp_s")]
        row += [_fmt(_mean(x.get("ep_sched_s") for x in m))]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def detail(folder: Path) -> str:
    """One run's plan steps (task, agent, start, end, what it waited for) and each agent's timeline."""
    a = analyse(folder)
    m = a["metrics"]
    lines = [
        f"agents {a['agents']}, blocks {a['blocks']}, seed {a['seed']}: sim {a['sim_s']:.1f} s, "
        f"plans {m.get('plans')}, steps {m.get('steps')}, tasks {m.get('tasks')}, critical path {m.get('cp')} steps "
        f"({_fmt(m.get('cp_s'))} s of measured step time; chain {m.get('cp_chain')}), work {_fmt(m.get('work_s'))} s, "
        f"lower bound {_fmt(m.get('lb_s'))} s, plan schedule {_fmt(m.get('sched_s'))} s; hand episodes as tasks: "
        f"critical path {m.get('ep_cp')} steps, {_fmt(m.get('ep_cp_s'))} s, schedule {_fmt(m.get('ep_sched_s'))} s",
        "",
        "| step | task | label | planned for | agent | start | end | dur | waits for |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for s in a["timeline"]:
        dur = s["end"] - s["start"] if s["start"] is not None and s["end"] is not None else None
        lines.append(
            f"| {s['index']} | T{s['task']} | {s['label']} | {s['planned']} | {s['agent']} | {_fmt(s['start'])} | "
            f"{_fmt(s['end'])} | {_fmt(dur)} | {', '.join(map(str, s['deps']))} |"
        )
    lines.append("")
    for agent in sorted(a["per_agent"]):
        t = a["per_agent"][agent]
        lines.append(f"{agent}: " + ", ".join(f"{c} {v:.1f}" for c, v in t.items() if v > 0.05))
        lines.append(
            "  " + "; ".join(f"{s:.1f}-{e:.1f} {c}[{w}]" for s, e, c, w in a["segments"][agent] if e - s >= 0.25)
        )
    return "\n".join(lines)


def main() -> int:
    """Run the experiment (or one run, or one run's detail) and print the tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", default="1-5", help="team sizes (default 1-5)")
    parser.add_argument("--blocks", default="8", help="block counts (default 8; e.g. 8,12)")
    parser.add_argument("--seeds", default="0-3", help="seeds (default 0-3)")
    parser.add_argument("--time-limit", type=float, default=600.0, help="simulated seconds per run (default 600)")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    parser.add_argument("--out", type=Path, default=OUT, help="where the run folders go")
    parser.add_argument("--reuse", action="store_true", help="analyse run folders that exist instead of running again")
    parser.add_argument("--one", nargs=4, metavar=("A", "B", "S", "DIR"), help="run one run in this process")
    parser.add_argument("--opponents", type=int, default=0, help="opponents in the --one run (default 0)")
    parser.add_argument("--detail", type=Path, metavar="DIR", help="print one run folder's steps and timelines")
    args = parser.parse_args()
    if args.one:
        a, b, s, d = args.one
        run_one(int(a), int(b), int(s), Path(d), args.time_limit, args.opponents)
        return 0
    if args.detail:
        print(detail(args.detail))
        return 0
    todo = [(a, b, s) for b in _range(args.blocks) for a in _range(args.agents) for s in _range(args.seeds)]
    folders = {key: args.out / f"b{key[1]}_a{key[0]}_s{key[2]}" for key in todo}
    missing = [k for k in todo if not (args.reuse and (folders[k] / "run.json").exists())]
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        list(pool.map(lambda k: _spawn(k[0], k[1], k[2], folders[k], args.time_limit), missing))
    results = [analyse(folders[k]) for k in todo if (folders[k] / "run.json").exists()]
    with (args.out / "runs.tsv").open("w", encoding="utf-8") as f:
        f.write("\t".join(["blocks", "agents", "seed", "success", "sim_s", "replans", *CATEGORIES]) + "\t")
        f.write("\t".join(METRICS) + "\n")
        for r in results:
            m = r["metrics"]
            f.write("\t".join(str(x) for x in (r["blocks"], r["agents"], r["seed"], r["success"], r["sim_s"])))
            f.write("\t" + str(r["replans"]) + "\t" + "\t".join(f"{r['share'][c]:.2f}" for c in CATEGORIES) + "\t")
            f.write("\t".join(str(m.get(k)) for k in METRICS))
            f.write("\n")
    print(table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
