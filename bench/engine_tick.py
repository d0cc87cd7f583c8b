"""Engine tick cost per agent for teams of 5, 20 and 50 agents (goal: 50 agents at 30 Hz, <= 0.66 ms per agent tick).

Each team runs the shipped LunarMission (roles Scout, Stummel, Amparo in turn)
with scripted skills over the simulated network, at 30 Hz. After a warm-up,
the wall time of ``--ticks`` lock-step ticks is divided by the agent ticks run; the
figure includes message delivery, team-view integration, rules, allocation and
behaviour ticks. In the same run, the peer: a plain py_trees tree per agent
with as many behaviours as the agent runs, ticked as often (the cost of the
behaviour layer alone, with no team).

Run: ``.venv/bin/python bench/engine_tick.py [--ticks 300] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import py_trees

from alica.engine import EngineConfig, SimulatedTeam
from alica.io import load_library
from alica.testing import default_fallback

ROOT = Path(__file__).resolve().parent.parent
ROLES = ("Scout", "Stummel", "Amparo")


def make_team(size: int, seed: int, broadcast: float = 0.2) -> SimulatedTeam:
    library = load_library(ROOT / "plans" / "lunar" / "mission.yaml")
    agents = {f"r{i:02d}": ROLES[i % 3] for i in range(size)}
    config = EngineConfig(frequency=30.0, broadcast_interval=broadcast)
    return SimulatedTeam(
        library, "LunarMission", agents, seed=seed, config=config, fallback=default_fallback(seed, 5.0, 20.0)
    )


def behaviours_running(team: SimulatedTeam) -> int:
    count = 0
    for engine in team.engines.values():
        todo = [engine.root] if engine.root else []
        while todo:
            node = todo.pop()
            for slot in node.slots:
                if slot.runner is not None:
                    count += 1
                elif slot.node is not None:
                    todo.append(slot.node)
    return count


def _events(team: SimulatedTeam, ticks: int) -> None:
    """Work for the measured window: samples found (transports start), a tenth of the team crashes."""
    start = team.now()
    period = team.config.period

    team.set_facts([(True, "found", ("a",)), (True, "found", ("b",))], at=start + 0.2 * ticks * period)
    names = sorted(team.engines)
    for name in names[: max(1, len(names) // 10)]:
        team.crash(name, at=start + 0.5 * ticks * period)


def engine_cost(
    size: int, ticks: int, seed: int, faults: bool = False, broadcast: float = 0.2
) -> tuple[float, float, int]:
    team = make_team(size, seed, broadcast)
    team.run(ticks=30)
    if faults:
        _events(team, ticks)
    sent = team.network.stats.sent
    before = sum(e.stats["ticks"] for e in team.engines.values())
    start = time.perf_counter()
    team.run(ticks=ticks)
    elapsed = time.perf_counter() - start
    agent_ticks = sum(e.stats["ticks"] for e in team.engines.values()) - before
    per_tick_msgs = (team.network.stats.sent - sent) / ticks
    return elapsed / agent_ticks * 1000.0, per_tick_msgs, behaviours_running(team)


class _Poll(py_trees.behaviour.Behaviour):
    def update(self) -> py_trees.common.Status:
        return py_trees.common.Status.RUNNING


def pytrees_cost(size: int, per_agent: int, ticks: int) -> float:
    trees = []
    for i in range(size):
        root = py_trees.composites.Parallel(
            f"agent{i}",
            policy=py_trees.common.ParallelPolicy.SuccessOnAll(),
            children=[_Poll(f"b{j}") for j in range(max(1, per_agent))],
        )
        trees.append(py_trees.trees.BehaviourTree(root))
    start = time.perf_counter()
    for _ in range(ticks):
        for tree in trees:
            tree.tick()
    return (time.perf_counter() - start) / (ticks * size) * 1000.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(
        f"engine tick cost per agent, LunarMission at 30 Hz, {args.ticks} ticks after 30 warm-up ticks, median of {args.repeat}"
    )
    print()
    print(
        "steady: agents run their tasks, team messages every 0.2 s; with faults: the samples are found (transports start)"
    )
    print("and a tenth of the team crashes; last: the same with a team message from every agent on every tick")
    print()
    print(
        "| agents | steady, ms per agent tick | with faults | with faults, team message every tick | goal | messages per tick (steady / every tick) | behaviours running | py_trees alone, ms per agent tick |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for size in (5, 20, 50):
        runs = [engine_cost(size, args.ticks, seed) for seed in range(args.repeat)]
        faulty = [engine_cost(size, args.ticks, seed, faults=True) for seed in range(args.repeat)]
        ms = statistics.median(r[0] for r in runs)
        ms_faults = statistics.median(r[0] for r in faulty)
        loud = [engine_cost(size, args.ticks, seed, faults=True, broadcast=1 / 30) for seed in range(args.repeat)]
        ms_loud = statistics.median(r[0] for r in loud)
        msgs = statistics.median(r[1] for r in runs)
        msgs_loud = statistics.median(r[1] for r in loud)
        running = runs[0][2]
        peer = statistics.median(pytrees_cost(size, round(running / size), args.ticks) for _ in range(args.repeat))
        verdict = "ok" if max(ms, ms_faults, ms_loud) <= 0.66 else "over"
        print(
            f"| {size} | {ms:.3f} | {ms_faults:.3f} | {ms_loud:.3f} | 0.66 ({verdict}) | {msgs:.1f} / {msgs_loud:.1f} | {running} | {peer:.3f} |"
        )


if __name__ == "__main__":
    main()
