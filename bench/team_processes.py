"""Faults in a team of agent processes over zenoh: kill -9 to reallocation, healed partition to converged world models.

Run with ``.venv/bin/python bench/team_processes.py [--repeat 5] [--quick]``.
Every run is the 3-agent lunar team with stand-ins (``plans/lunar/mission.yaml``,
scout, stummel and amparo) as ``alica agent`` processes on loopback
(:class:`alica.app.processes.ProcessTeam`, traces in a temporary folder), on the
wall clock, with the engine at 30 Hz and a team timeout of 3 s. Times are read
from the team's merged trace (``t`` = seconds since the team's start).

Scenarios:

* **kill -9**: operator fact ``found(a) and found(b)`` at 3 s; the victim
  (``--victims``, default amparo then stummel) gets ``kill -9`` at
  ``--crash-at`` (6 s) and is started again at ``--recover-at`` (10 s: later
  than the team timeout, so that the simulated reference sees the crash too).
  Per surviving agent: crash -> its ``team lost`` event for the victim;
  crash -> its *reallocation*: the first ``allocation`` event of that agent on
  the root plan (``LunarMission``) after the crash and before the restart in
  which an agent other than the victim gets an entry point (task) different
  from the one the observer's own earlier allocation events on the root plan
  gave it (``initial``, ``utility``, ``reuse`` or ``authority``; the column
  says which). Goal (issue 18): both at most the team timeout plus 2 ticks,
  3.067 s. Then recover -> each survivor's ``team back`` event for the victim,
  recover -> converged world models (below), and whether the run succeeded.
* **partition**: no common fact; ``own`` operator facts per agent:
  ``found(a)`` on scout at 5 s and ``found(b)`` on amparo at 6 s; the relays
  between scout and the others are cut at ``--cut-at`` (3.5 s) and healed at
  ``--heal-at`` (8 s). Per agent: cut -> ``team lost``, heal -> ``team back``
  (for every teammate on the other side; the slower of the two when an agent
  had two). Then heal -> converged world models: the first time at or after
  the heal at which every live agent's latest ``world`` trace event carries
  the same digest (``alica agent`` traces its world model's digest when it
  changes, at most every 0.1 s, so this figure is good to about 0.1 s).

For reference, the same scenarios in the simulated team
(:class:`alica.engine.SimulatedTeam` over ``SimNetwork``, simulated seconds,
seeds 0..N-1): there a teammate is lost when it has been silent for the team
timeout (no liveliness tokens), and the world digests are taken after every
tick.

Each run is bounded (``--time-limit`` wall seconds for the agents, plus a
guard); every process is stopped in ``finally``; a failed run is counted and
its error printed under the tables. Progress lines go to standard error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
PLAN = str(ROOT / "plans" / "lunar" / "mission.yaml")
ROOT_PLAN = "LunarMission"
NAMES = ("scout", "stummel", "amparo")
ROLES = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"}
COMMON_FACT = "found(a) and found(b)@3"
OWN_FACTS = {"scout": "found(a)@5", "amparo": "found(b)@6"}
CUT = (("scout",), ("stummel", "amparo"))
FREQUENCY = 30.0
TICK = 1.0 / FREQUENCY
TEAM_TIMEOUT = 3.0
GOAL = TEAM_TIMEOUT + 2 * TICK


@dataclass
class Run:
    """One run: its trace events, the times of its faults, its outcome."""

    kind: str  # "crash" or "partition"
    victim: str | None
    events: list[dict[str, Any]] = field(default_factory=list)
    marks: dict[str, float] = field(default_factory=dict)
    success: bool = False
    agree: bool = False
    error: str = ""
    load: float = 0.0
    wall: float = 0.0


# -- the team of processes ---------------------------------------------------------------


def process_run(kind: str, victim: str | None, args: argparse.Namespace, keep: Path | None, index: int) -> Run:
    """One run of the team of processes; never raises (an error is the run's ``error``)."""
    from alica.app.processes import ProcessTeam

    run = Run(kind, victim, load=os.getloadavg()[0])
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="team_processes_") as tmp:
        workdir = Path(tmp)
        team = None
        try:
            options = ["--stand-ins", "--time-limit", str(args.max_time)]
            if kind == "crash":
                options += ["--fact", COMMON_FACT]
                own = None
            else:
                own = {name: ["--fact", fact] for name, fact in OWN_FACTS.items()}
            team = ProcessTeam(
                PLAN, ",".join(NAMES), list(NAMES), options, workdir, relays=kind == "partition", own=own
            )
            team.launch()
            if kind == "crash":
                assert victim is not None
                _wait(team.now, args.crash_at)
                run.marks["crash"] = team.now()  # the moment SIGKILL is sent
                team.crash(victim)
                _wait(team.now, args.recover_at)
                run.marks["recover"] = team.now()
                team.recover(victim)
            else:
                _wait(team.now, args.cut_at)
                run.marks["cut"] = team.now()
                team.partition([list(g) for g in CUT], args.cut_at, args.heal_at)
                _wait(team.now, args.heal_at)
                run.marks["heal"] = team.now()
                team.heal()
            guard = args.max_time + 5.0
            while not team.done() and team.now() < guard:
                time.sleep(0.05)
        except Exception as exc:  # a failed run is a figure too
            run.error = f"{type(exc).__name__}: {exc}"
            traceback.print_exc(file=sys.stderr)
        finally:
            if team is not None:
                team.stop()
        if team is not None:
            try:
                summary = team.summary(ROOT_PLAN, 0)
                run.success = bool(summary["success"])
                run.agree = bool(summary["world_models_agree"])
                if not run.success and not run.error:
                    reasons = {n: a.get("reason") or a["status"] for n, a in summary["agents"].items()}
                    run.error = f"no success: {reasons}"
                merged = workdir / "merged.jsonl"
                team.trace(merged)
                run.events = [json.loads(line) for line in merged.read_text(encoding="utf-8").splitlines()]
                if keep is not None:
                    keep.mkdir(parents=True, exist_ok=True)
                    name = f"{kind}-{victim or 'scout'}-{index}.jsonl"
                    (keep / name).write_text(merged.read_text(encoding="utf-8"), encoding="utf-8")
            except Exception as exc:
                run.error = run.error or f"{type(exc).__name__}: {exc}"
    run.wall = time.perf_counter() - started
    return run


def _wait(now: Callable[[], float], until: float) -> None:
    while now() < until:
        time.sleep(min(0.005, max(0.0, until - now())))


# -- the simulated team -----------------------------------------------------------------


def digest(world_model: Any) -> str:
    """The world model's fingerprint, as ``alica agent`` traces it."""
    return hashlib.blake2b(world_model.dumps().encode("utf-8"), digest_size=8).hexdigest()


def sim_run(kind: str, victim: str | None, args: argparse.Namespace, seed: int) -> Run:
    """The same scenario in the simulated team (simulated seconds); never raises."""
    from alica.app.run_skills import plan_skills, skill_wiring
    from alica.engine import SimulatedTeam
    from alica.io import Loader
    from alica.lang import literals
    from alica.lang.skill_plugins import default_registry
    from alica.prophet import engine_config
    from alica.testing import default_fallback

    run = Run(kind, victim, load=os.getloadavg()[0])
    started = time.perf_counter()
    try:
        registry = default_registry([])
        library = Loader(skills=registry).load(PLAN)
        wiring = skill_wiring(registry, plan_skills(library, ROOT_PLAN), world=False, stand_ins=True, plan=ROOT_PLAN)
        events = run.events
        team = SimulatedTeam(
            library,
            ROOT_PLAN,
            ROLES,
            seed=seed,
            config=engine_config(frequency=FREQUENCY),
            skill_registry=wiring.registry,
            fallback=default_fallback(seed, registry=wiring.registry),
            observers=[events.append],
        )
        if kind == "crash":
            assert victim is not None
            what, at = COMMON_FACT.rsplit("@", 1)
            team.set_facts(literals(what), at=float(at))
            team.crash(victim, at=args.crash_at)
            team.recover(victim, at=args.recover_at)
        else:
            team.partition([list(g) for g in CUT], start=args.cut_at, end=args.heal_at)
            for name, fact in OWN_FACTS.items():
                what, at = fact.rsplit("@", 1)
                team.at(float(at), f"operator {name}", _assert_on(team, name, literals(what)))
        seen: dict[str, tuple[int, str]] = {}
        while not team.done() and team.now() < args.max_time:
            team.tick_agents()
            now = team.now()
            for name, engine in team.engines.items():
                if name in team.crashed:
                    continue
                current = (id(engine), digest(engine.world_model))
                if seen.get(name) != current:
                    seen[name] = current
                    events.append({"event": "world", "agent": name, "digest": current[1], "t": now})
            team.clock.advance(team.config.period)
        for fault in team.faults:  # a partition's record is made when it is set up: its times are start and end
            if fault["fault"] in ("crash", "recover"):
                run.marks[fault["fault"]] = float(fault["t"])
            elif fault["fault"] == "partition":
                run.marks["cut"], run.marks["heal"] = float(fault["start"]), float(fault["end"])
        summary = team.summary()
        run.success = bool(summary["success"])
        live = {digest(e.world_model) for e in team.running()}
        run.agree = len(live) <= 1
        if not run.success:
            run.error = "no success: " + ", ".join(f"{n} {a['status']}" for n, a in summary["agents"].items())
    except Exception as exc:
        run.error = f"{type(exc).__name__}: {exc}"
        traceback.print_exc(file=sys.stderr)
    run.events.sort(key=lambda e: float(e.get("t", 0.0)))
    run.wall = time.perf_counter() - started
    return run


def _assert_on(team: Any, name: str, facts: list[tuple[bool, str, tuple[object, ...]]]) -> Callable[[], None]:
    def action() -> None:
        if name in team.crashed:
            return
        model = team.engines[name].world_model
        for positive, pred, fact_args in facts:
            (model.assert_fact if positive else model.retract_fact)(pred, *fact_args)

    return action


# -- reading a trace ---------------------------------------------------------------------


def team_change(events: Iterable[dict[str, Any]], change: str, who: str, after: float) -> dict[str, float]:
    """When each agent first saw ``who`` lost or back at or after ``after``."""
    seen: dict[str, float] = {}
    for e in events:
        if e.get("event") == "team" and e.get("change") == change and e.get("who") == who and e["t"] >= after:
            seen.setdefault(e["agent"], float(e["t"]))
    return seen


def reallocations(
    events: list[dict[str, Any]], victim: str, crash: float, until: float
) -> dict[str, tuple[float, str]]:
    """Per survivor: the first root-plan allocation after the crash that moves a live agent to another task.

    The observer's view of the root plan's assignment is what its own
    allocation events on the root plan said so far (entries merged in order).
    """
    views: dict[str, dict[str, Any]] = {}
    found: dict[str, tuple[float, str]] = {}
    for e in events:
        if e.get("event") != "allocation" or e.get("key") != ROOT_PLAN or e["agent"] == victim:
            continue
        observer, entries = e["agent"], dict(e.get("entries") or {})
        view = views.setdefault(observer, {})
        if crash <= e["t"] < until and observer not in found:
            moved = sorted(a for a, ep in entries.items() if a != victim and view.get(a, "?") != ep)
            if moved:
                what = ", ".join(f"{a}->{entries[a]}" for a in moved)
                found[observer] = (float(e["t"]), f"{e.get('reason')}: {what}")
        view.update(entries)
    return found


def started_by(events: Iterable[dict[str, Any]], t: float) -> bool:
    """Whether every agent had traced something (it ticks) before ``t``."""
    return {e["agent"] for e in events if e["t"] < t and e.get("event") != "fault"} >= set(NAMES)


def converged(
    events: list[dict[str, Any]], after: float, live: Iterable[str], fresh: str | None = None
) -> float | None:
    """The first time at or after ``after`` when every live agent's latest world digest is the same.

    ``fresh``: an agent restarted at ``after``: only its world events from then
    on (a later incarnation) count.
    """
    live = list(live)
    latest: dict[str, str] = {}
    for e in events:
        if e.get("event") != "world" or e["agent"] not in live:
            continue
        t = float(e["t"])
        if e["agent"] == fresh and (t < after or int(e.get("incarnation", 2)) < 2):
            continue
        if t < after:
            latest[e["agent"]] = e["digest"]
            continue
        if len(latest) == len(live) and len(set(latest.values())) == 1:
            return after
        latest[e["agent"]] = e["digest"]
        if len(latest) == len(live) and len(set(latest.values())) == 1:
            return t
    if len(latest) == len(live) and len(set(latest.values())) == 1:
        return after  # already equal at ``after`` and no world event since
    return None


# -- tables ------------------------------------------------------------------------------


def spread(values: list[float], runs: int) -> str:
    """``median / max`` in seconds, and how many runs had no value."""
    if not values:
        return "— (none)"
    text = f"{statistics.median(values):.3f} / {max(values):.3f}"
    if len(values) < runs:
        text += f" ({runs - len(values)} missing)"
    return text


def crash_tables(runs_by_victim: dict[str, list[Run]], clock: str) -> tuple[list[str], list[str]]:
    """Rows of the kill -9 table and the lines of failures."""
    rows, failures = [], []
    for victim, runs in runs_by_victim.items():
        survivors = [n for n in NAMES if n != victim]
        n = len(runs)
        team_lost: list[float] = []  # per run: the last survivor's lost event
        team_realloc: list[float] = []  # per run: the first survivor's reallocation
        for name in survivors:
            lost, realloc, back, how = [], [], [], set()
            for run in runs:
                if "crash" not in run.marks:
                    continue
                crash, recover = run.marks["crash"], run.marks.get("recover", float("inf"))
                seen = team_change(run.events, "lost", victim, crash).get(name)
                if seen is not None:
                    lost.append(seen - crash)
                moved = reallocations(run.events, victim, crash, recover).get(name)
                if moved is not None:
                    realloc.append(moved[0] - crash)
                    how.add(moved[1])
                came = team_change(run.events, "back", victim, recover).get(name)
                if came is not None:
                    back.append(came - recover)
            rows.append(
                f"| {victim} | {name} | {spread(lost, n)} | {spread(realloc, n)} | "
                f"{'; '.join(sorted(how)) or 'none before the restart'} | {spread(back, n)} | |"
            )
        started, conv = [], []
        for run in runs:
            if "crash" not in run.marks:
                continue
            crash, recover = run.marks["crash"], run.marks.get("recover", float("inf"))
            losts = team_change(run.events, "lost", victim, crash)
            if all(name in losts for name in survivors):
                team_lost.append(max(losts.values()) - crash)
            moved = reallocations(run.events, victim, crash, recover)
            if moved:
                team_realloc.append(min(t for t, _ in moved.values()) - crash)
            if recover != float("inf"):
                first = next(
                    (
                        e["t"]
                        for e in run.events
                        if e["agent"] == victim
                        and e["event"] != "fault"
                        and e["t"] >= recover
                        and int(e.get("incarnation", 2)) >= 2
                    ),
                    None,
                )
                if first is not None:
                    started.append(first - recover)
                t = converged(run.events, recover, NAMES, fresh=victim)
                if t is not None:
                    conv.append(t - recover)
        worst = max([*team_lost, *team_realloc], default=float("inf"))
        goal = "met" if len(team_lost) == n and worst <= GOAL else "NOT met"
        goal += "" if len(team_realloc) == n else f" (reallocation in {len(team_realloc)} of {n} runs)"
        rows.append(
            f"| {victim} | **team** (last lost, first reallocation) | {spread(team_lost, n)} | "
            f"{spread(team_realloc, n)} | | | {goal} |"
        )
        ok = sum(r.success for r in runs)
        agree = sum(r.agree for r in runs)
        rows.append(
            f"| {victim} | (restart) | recover -> its first trace event: {spread(started, n)} | "
            f"recover -> converged world models: {spread(conv, n)} | | "
            f"runs {n}, succeeded {ok}, world models agree at the end {agree} | |"
        )
        failures += [f"- {clock} kill -9 {victim}: {r.error}" for r in runs if r.error]
    return rows, failures


def partition_rows(runs: list[Run], clock: str) -> tuple[list[str], list[str]]:
    """Rows of the partition table and the lines of failures."""
    rows = []
    n = len(runs)
    # a run whose agents had not all started by the cut (slow starts under load) measures the team timeout
    # for the late agent, not the cut: its cut -> lost figures are left out
    formed = [r for r in runs if "cut" in r.marks and started_by(r.events, r.marks["cut"])]
    formed_ids = {id(r) for r in formed}
    for name in NAMES:
        others = [m for m in NAMES if not any(name in g and m in g for g in CUT)]
        lost, back = [], []
        for run in runs:
            if "cut" not in run.marks or "heal" not in run.marks:
                continue
            cut, heal = run.marks["cut"], run.marks["heal"]
            losts = [team_change(run.events, "lost", m, cut).get(name) for m in others]
            backs = [team_change(run.events, "back", m, heal).get(name) for m in others]
            if id(run) in formed_ids and all(t is not None for t in losts):
                lost.append(max(t for t in losts if t is not None) - cut)
            if all(t is not None for t in backs):
                back.append(max(t for t in backs if t is not None) - heal)
        rows.append(f"| {name} | {', '.join(others)} | {spread(lost, len(formed))} | {spread(back, n)} |")
    conv, whole = [], []
    for run in runs:
        if "heal" not in run.marks:
            continue
        heal = run.marks["heal"]
        t = converged(run.events, heal, NAMES)
        if t is not None:
            conv.append(t - heal)
        backs = [team_change(run.events, "back", who, heal) for who in NAMES]
        if all(len(b) == (2 if who == "scout" else 1) for who, b in zip(NAMES, backs, strict=True)):
            whole.append(max(t for b in backs for t in b.values()) - heal)
    ok = sum(r.success for r in runs)
    agree = sum(r.agree for r in runs)
    rows.append(f"| (team) | everyone back | | {spread(whole, n)} |")
    rows.append(f"| (team) | **heal -> converged world models** | | {spread(conv, n)} |")
    rows.append(
        f"| (team) | runs {n}, succeeded {ok}, world models agree at the end {agree}, "
        f"every agent started before the cut {len(formed)} | | |"
    )
    failures = [f"- {clock} partition: {r.error}" for r in runs if r.error]
    return rows, failures


def print_crash(title: str, runs_by_victim: dict[str, list[Run]], clock: str) -> list[str]:
    rows, failures = crash_tables(runs_by_victim, clock)
    print(title + "\n")
    print(
        "| victim | survivor | crash -> lost (s) | crash -> reallocation (s) | reallocation seen "
        f"| recover -> back (s) | goal <= {GOAL:.3f} s |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- |")
    print("\n".join(rows) + "\n")
    return failures


def print_partition(title: str, runs: list[Run], clock: str) -> list[str]:
    rows, failures = partition_rows(runs, clock)
    print(title + "\n")
    print("| agent | cut off from | cut -> lost, all (s) | heal -> back, all (s) |")
    print("| --- | --- | --- | --- |")
    print("\n".join(rows) + "\n")
    return failures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per scenario (median / max)")
    parser.add_argument("--quick", action="store_true", help="one run per scenario")
    parser.add_argument("--victims", default="amparo,stummel", help="agents to kill -9, comma-separated")
    parser.add_argument("--crash-at", type=float, default=6.0)
    parser.add_argument("--recover-at", type=float, default=10.0)
    parser.add_argument("--cut-at", type=float, default=3.5)
    parser.add_argument("--heal-at", type=float, default=8.0)
    parser.add_argument("--max-time", type=float, default=45.0, help="wall (simulated) seconds per run at most")
    parser.add_argument("--no-sim", action="store_true", help="leave out the simulated reference")
    parser.add_argument("--keep", metavar="DIR", help="keep the merged traces of the process runs here")
    parser.add_argument(
        "--cpu",
        metavar="SIZES",
        default="",
        help="only measure CPU per agent process of teams of these sizes, e.g. 10,20 (the lunar mission, 30 s)",
    )
    args = parser.parse_args()
    if args.cpu:
        cpu_table([int(n) for n in args.cpu.split(",") if n.strip()], 20.0 if args.quick else 30.0)
        return
    repeat = 1 if args.quick else args.repeat
    victims = [v.strip() for v in args.victims.split(",") if v.strip()]
    unknown = [v for v in victims if v not in NAMES]
    if unknown or repeat < 1:
        parser.error(f"--victims: choose from {', '.join(NAMES)}; --repeat: at least 1")
    keep = Path(args.keep) if args.keep else None

    loads = [os.getloadavg()[0]]
    crash_runs: dict[str, list[Run]] = {v: [] for v in victims}
    partition_runs: list[Run] = []
    started = time.perf_counter()
    for i in range(repeat):
        for victim in victims:
            run = process_run("crash", victim, args, keep, i)
            crash_runs[victim].append(run)
            loads.append(run.load)
            _progress(f"kill -9 {victim} #{i + 1}", run)
        run = process_run("partition", None, args, keep, i)
        partition_runs.append(run)
        loads.append(run.load)
        _progress(f"partition #{i + 1}", run)
    loads.append(os.getloadavg()[0])
    sim_crash: dict[str, list[Run]] = {v: [] for v in victims}
    sim_partition: list[Run] = []
    if not args.no_sim:
        for seed in range(repeat):
            for victim in victims:
                sim_crash[victim].append(sim_run("crash", victim, args, seed))
            sim_partition.append(sim_run("partition", None, args, seed))

    print(
        f"Lunar team (scout, stummel, amparo; stand-ins) as `alica agent` processes over zenoh on loopback, "
        f"30 Hz, team timeout {TEAM_TIMEOUT:g} s; {repeat} run(s) per scenario, median / max; "
        f"1-min load average {min(loads):.2f}-{max(loads):.2f} on {os.cpu_count()} CPUs; "
        f"{time.perf_counter() - started:.0f} s wall.\n"
    )
    failures = print_crash(
        f"kill -9 at {args.crash_at:g} s, restart at {args.recover_at:g} s (processes, wall seconds). Reallocation: "
        "the survivor's first allocation event on LunarMission after the crash (before the restart) that moves a "
        "live agent to another task.",
        crash_runs,
        "processes",
    )
    failures += print_partition(
        f"Partition scout | stummel, amparo from {args.cut_at:g} s to {args.heal_at:g} s, found(a) on scout at 5 s, "
        "found(b) on amparo at 6 s (processes, wall seconds). 'all': the slower of an agent's teammates across the cut. "
        "Converged: every agent's latest world digest equal (traced at most every 0.1 s).",
        partition_runs,
        "processes",
    )
    if not args.no_sim:
        failures += print_crash(
            "Reference: the simulated team (SimNetwork, no liveliness: a teammate is lost after the team timeout), "
            f"same kill -9 and restart, simulated seconds, seeds 0-{repeat - 1}.",
            sim_crash,
            "simulated",
        )
        failures += print_partition(
            "Reference: the simulated team, same partition, simulated seconds (world digests after every tick).",
            sim_partition,
            "simulated",
        )
    if failures:
        print("Runs with an error or without success:\n")
        print("\n".join(failures))


def cpu_table(sizes: list[int], seconds: float) -> None:
    """CPU per ``alica agent`` process of lunar teams of ``sizes`` agents, each run ``seconds`` on the wall clock."""
    import subprocess

    print(
        f"CPU per `alica agent` process at 30 Hz, the lunar mission with stand-ins (no operator: the team explores), "
        f"{seconds:g} s per team; % of one core while ticking (start-up left out), {os.cpu_count()} CPUs.\n"
    )
    print(
        "| agents | CPU per process, mean / max | ticks | ticks that overran the period | messages sent / delivered |"
    )
    print("|---:|---|---:|---:|---|")
    for n in sizes:
        roster = ",".join(f"r{i}:{('Scout', 'Stummel', 'Amparo')[i % 3]}" for i in range(n))
        argv = [sys.executable, "-m", "alica.app.cli", "run", PLAN, "--stand-ins", "--agents", roster]
        out = subprocess.run(
            [*argv, "--processes", "--time-limit", str(seconds), "--json"], capture_output=True, text=True, check=False
        ).stdout
        try:
            summary = json.loads(out)
        except json.JSONDecodeError:
            print(f"| {n} | run failed | | | |")
            continue
        cpu = [a["cpu_percent"] for a in summary["agents"].values() if a.get("cpu_percent") is not None]
        overruns = sum(a.get("overruns", 0) for a in summary["agents"].values())
        m = summary["messages"]
        mean = statistics.mean(cpu) if cpu else float("nan")
        print(
            f"| {n} | {mean:.1f} % / {max(cpu, default=float('nan')):.1f} % | {summary['ticks']} | {overruns} "
            f"| {m['sent']} / {m['delivered']} |"
        )
    print()


def _progress(label: str, run: Run) -> None:
    state = "ok" if run.success and not run.error else f"FAILED ({run.error})"
    print(f"{label}: {state}, {run.wall:.1f} s wall, load {run.load:.2f}", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
