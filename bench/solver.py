"""Benchmark of the constraint solver (issue 15's figures).

Run with ``.venv/bin/python bench/solver.py``. Two tables:

* **Frontier assignment, IMPERA Eq. 7-8.** Robots and frontier candidates at random
  in a square (``--size`` m), random gains in [0, 10]; constraints
  ``forall a, b in agents(Explore): a == b or MaximalDist(frontier(a), frontier(b), 4.0)``
  and ``forall a in agents(Explore): MinimalDist(frontier(a), a, 15.0)``, utility
  ``sum a in agents(Explore): gain(frontier(a))``. For each size, ``--instances``
  random problems (5 x 200 also in a square of 0.6 times the side: denser, harder) solved by ``solve()`` (branch and bound), by exhaustive
  enumeration with the evaluator where the product of domains is small enough,
  and by a greedy assignment (each robot in turn takes the best frontier that
  still fits): times (median, p90, ms), how many were proven optimal, how many
  optima the enumeration confirmed, and the greedy's gap to the optimum.
* **Formation of 10 robots** (continuous): points in [-5, 5]^2, each pair at least
  1 m apart, each robot at most 3 m from the centre. ``solve()`` with 100 restarts
  at once (one seed per run), then RProp alone and scipy SLSQP from each of the
  same 100 starts: median time to a feasible point and the share of starts that
  end feasible (checked by the evaluator).

* **Inside the engine**, at 30 Hz: a team of 5 agents runs a plan whose behaviour
  is bound to a per-agent point variable (pairs at least 1.5 m apart, all within
  4 m of a centre, as tight as possible), for 20 simulated seconds; one agent
  crashes at 5 s and comes back at 12 s, so the team solves again twice. The same
  run without variables and constraints is the baseline. Wall time of every
  agent's tick (median, p99, max), the solves and their median time, and whether
  the agents ended with the same values.

Each time is one run on a shared machine; they vary by some 20 %.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from itertools import product

import numpy as np
from scipy.optimize import minimize

from alica.lang import FactBase, evaluate, holds, parse
from alica.solver import Finite, Point, Problem, Term, Var, solve
from alica.solver.continuous import MARGIN, Continuous
from alica.solver.ground import Reading, Variables

SPREAD = "forall a, b in agents(Explore): a == b or MaximalDist(frontier(a), frontier(b), 4.0)"
NEAR = "forall a in agents(Explore): MinimalDist(frontier(a), a, 15.0)"
GAIN = "sum a in agents(Explore): gain(frontier(a))"
APART = "forall a, b in agents(Form): a == b or dist(pos(a), pos(b)) >= 1.0"
CENTRE = "forall a in agents(Form): dist(pos(a), centre) <= 3.0"
#: Largest product of domains the enumeration is run on.
ENUMERATION_LIMIT = 20_000


def term(name: str, text: str) -> Term:
    return Term(name, parse(text), text)


def exploration(seed: int, agents: int, frontiers: int, size: float) -> Problem:
    rng = np.random.default_rng(seed)
    fb = FactBase()
    for i in range(agents):
        fb.add_object(f"r{i}", "agents(Explore)")
        fb.set("Pos", f"r{i}", value=tuple(rng.uniform(0, size, 2).tolist()))
    names = [f"f{i}" for i in range(frontiers)]
    for name in names:
        fb.set("Pos", name, value=tuple(rng.uniform(0, size, 2).tolist()))
        fb.set("gain", name, value=float(rng.uniform(0, 10)))
    variables = tuple(Var("frontier", f"r{i}", Finite(tuple(names))) for i in range(agents))
    return Problem(variables, (term("spread", SPREAD), term("near", NEAR)), (term("gain", GAIN),), fb, seed=seed)


def enumerate_all(problem: Problem) -> float | None:
    """The optimum by trying every assignment with the plain evaluator (None: infeasible)."""
    best = None
    for combination in product(*(v.domain.values for v in problem.variables)):  # type: ignore[union-attr]
        reading = Reading(problem.belief, dict(zip(problem.variables, combination)))
        env = reading.env()
        if all(holds(c.node, reading, env) for c in problem.constraints):
            total = float(evaluate(problem.utilities[0].node, reading, env))  # type: ignore[arg-type]
            best = total if best is None else max(best, total)
    return best


def greedy(problem: Problem) -> float | None:
    """Each robot in turn takes the highest-gain frontier that keeps every constraint (None: stuck)."""
    chosen: dict[Var, object] = {}
    fb = problem.belief
    for var in problem.variables:
        ranked = sorted(var.domain.values, key=lambda f: -float(fb.lookup("gain", (f,))))  # type: ignore[union-attr, arg-type]
        for value in ranked:
            trial = {**chosen, var: value}
            reading = Reading(fb, trial)
            if all(_partial_ok(problem, reading, trial)):
                chosen = trial
                break
        else:
            return None
    return sum(float(fb.lookup("gain", (v,))) for v in chosen.values())  # type: ignore[arg-type]


def _partial_ok(problem: Problem, reading: Reading, chosen: dict[Var, object]):
    agents = [v.agent for v in chosen]
    for a in agents:
        yield holds("MinimalDist(frontier(a), a, 15.0)", reading, {"a": a})
        for b in agents:
            if a != b:
                yield holds("MaximalDist(frontier(a), frontier(b), 4.0)", reading, {"a": a, "b": b})


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else math.nan


def frontier_table(instances: int, size: float) -> None:
    print(f"### Frontier assignment, IMPERA Eq. 7-8 ({instances} random instances each)\n")
    print(
        "| robots x frontiers | ours median ms | ours p90 ms | proven optimal | enumeration median ms "
        "| optima equal | greedy gap median % | greedy gap max % | greedy stuck |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for agents, frontiers, area in ((3, 12, size / 3), (3, 25, size / 2), (5, 200, size), (5, 200, size * 0.6)):
        ours, enum_times, gaps = [], [], []
        optimal = equal = enumerated = stuck = 0
        for seed in range(instances):
            problem = exploration(seed, agents, frontiers, area)
            start = time.perf_counter()
            solution = solve(problem, time_limit=5.0)
            ours.append((time.perf_counter() - start) * 1000)
            optimal += solution.optimal
            best = solution.utility if solution.status == "solved" else None
            if frontiers**agents <= ENUMERATION_LIMIT:
                start = time.perf_counter()
                reference = enumerate_all(problem)
                enum_times.append((time.perf_counter() - start) * 1000)
                enumerated += 1
                equal += (reference is None and best is None) or (
                    reference is not None and best is not None and abs(reference - best) <= 1e-9
                )
            found = greedy(problem)
            if found is None:
                stuck += best is not None
            elif best:
                gaps.append(100 * (best - found) / best)
        enum_median = f"{statistics.median(enum_times):.1f}" if enum_times else "too large"
        equal_text = f"{equal}/{enumerated}" if enumerated else "-"
        print(
            f"| {agents} x {frontiers} in {area:.0f} m | {statistics.median(ours):.1f} | {percentile(ours, 90):.1f} "
            f"| {optimal}/{instances} | {enum_median} | {equal_text} "
            f"| {statistics.median(gaps) if gaps else math.nan:.1f} | {max(gaps) if gaps else math.nan:.1f} | {stuck} |"
        )
    print()


def formation(n: int, seed: int) -> Problem:
    fb = FactBase()
    for i in range(n):
        fb.add_object(f"r{i}", "agents(Form)")
    fb.set("Pos", "centre", value=(0.0, 0.0))
    variables = tuple(Var("pos", f"r{i}", Point(-5, 5)) for i in range(n))
    return Problem(variables, (term("apart", APART), term("centre", CENTRE)), (), fb, seed=seed)


def _feasible(problem: Problem, row: np.ndarray) -> bool:
    values = {v: (float(row[2 * i]), float(row[2 * i + 1])) for i, v in enumerate(problem.variables)}
    reading = Reading(problem.belief, values)
    return all(holds(c.node, reading, reading.env()) for c in problem.constraints)


def formation_table(runs: int, starts: int, n: int = 10) -> None:
    print(f"### Formation of {n} robots (pairs >= 1 m apart, <= 3 m from the centre), {starts} random starts\n")
    batch, ok = [], 0
    for seed in range(runs):
        problem = formation(n, seed)
        begin = time.perf_counter()
        solution = solve(problem, time_limit=2.0, restarts=starts)
        batch.append((time.perf_counter() - begin) * 1000)
        ok += solution.status == "solved"
    problem = formation(n, 0)
    engine = Continuous(problem, Variables(problem), Reading(problem.belief, {}), None)
    x0 = engine.starts(starts, None)
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]

    def constraints(x: np.ndarray) -> np.ndarray:
        p = x.reshape(n, 2)
        # with the margin our smooth form keeps (MARGIN): without it SLSQP stops on the boundary, a hair outside
        apart = [np.sum((p[i] - p[j]) ** 2) - (1.0 + MARGIN) ** 2 for i, j in pairs]
        near = [(3.0 - MARGIN) ** 2 - np.sum(p[i] ** 2) for i in range(n)]
        return np.array(apart + near)

    rprop_ms, rprop_ok, slsqp_ms, slsqp_ok = [], 0, [], 0
    for k in range(starts):
        begin = time.perf_counter()
        result = engine.run(time.perf_counter() + 2.0, time.perf_counter, x0=x0[k : k + 1])
        rprop_ms.append((time.perf_counter() - begin) * 1000)
        rprop_ok += result.values is not None
        begin = time.perf_counter()
        found = minimize(
            lambda x: 0.0,
            x0[k],
            jac=np.zeros_like,
            method="SLSQP",
            bounds=[(-5, 5)] * (2 * n),
            constraints=[{"type": "ineq", "fun": constraints}],
            options={"maxiter": 300},
        )
        slsqp_ms.append((time.perf_counter() - begin) * 1000)
        slsqp_ok += _feasible(problem, found.x)
    print("| method | median ms | p90 ms | feasible |")
    print("|---|---|---|---|")
    print(
        f"| ours: solve(), {starts} restarts at once ({runs} seeds) | {statistics.median(batch):.1f} "
        f"| {percentile(batch, 90):.1f} | {ok}/{runs} runs |"
    )
    print(
        f"| ours: RProp from each start alone | {statistics.median(rprop_ms):.1f} | {percentile(rprop_ms, 90):.1f} "
        f"| {rprop_ok}/{starts} starts |"
    )
    print(
        f"| scipy SLSQP from each start | {statistics.median(slsqp_ms):.1f} | {percentile(slsqp_ms, 90):.1f} "
        f"| {slsqp_ok}/{starts} starts |"
    )
    print()


ENGINE_PLAN = """
alica: 1
tasks: [Default, Hold]
rolesets:
  - name: Bench
    roles:
      - name: Robot
        priorities: {Default: 0.5, Hold: 0.5}
behaviours:
  - name: Stay
    skill: Stay
    variables: [spot]
    params: {spot: SPOT}
plans:
  - name: Team
    VARIABLES
    entry_points:
      - {name: Hold, task: Hold, state: Standing, min: 1, max: "*"}
    states:
      - name: Standing
        children: [BINDING]
"""
ENGINE_VARIABLES = """variables: ["spot - point[-5, 5]", "centre - point[-5, 5]"]
    constraints:
      - name: Apart
        formula: "forall a, b in agents(Hold): a == b or dist(spot(a), spot(b)) >= 1.5"
      - name: Near
        formula: "forall a in agents(Hold): dist(spot(a), centre) <= 4.0"
      - name: Tight
        utility: "0 - (sum a in agents(Hold): dist(spot(a), centre))"
"""


def engine_run(solved: bool, agents: int = 5, seconds: float = 20.0) -> dict[str, object]:
    """One team run at 30 Hz; the wall time of every agent step (rules, allocation, solving, behaviours), and the solves."""
    import tempfile
    from pathlib import Path

    from alica.engine import EngineConfig, SimulatedTeam, TraceRecorder
    from alica.engine.agent import AgentEngine
    from alica.io import load_library
    from alica.lang.skill_plugins import default_registry
    from alica.lang.skills import ParamSpec
    from alica.testing import TimedSkill

    text = ENGINE_PLAN.replace("VARIABLES", ENGINE_VARIABLES if solved else "")
    text = text.replace("SPOT", "$spot" if solved else "[0, 0]")
    text = text.replace("BINDING", "{ref: Stay, bind: {spot: spot}}" if solved else "Stay")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "team.yaml"
        path.write_text(text, encoding="utf-8")
        skills = default_registry()
        skills.declare("Stay", ParamSpec("spot", "any", required=False), doc="stand still")
        library = load_library(path, skills=skills)
    recorder = TraceRecorder()
    names = {f"r{i}": "Robot" for i in range(1, agents + 1)}
    team = SimulatedTeam(
        library,
        "Team",
        names,
        skills={"Stay": lambda name, params, context: TimedSkill(name, None)},
        observers=[recorder],
        config=EngineConfig(frequency=30.0),
    )
    ticks: list[float] = []
    original = AgentEngine.step

    def timed(engine: AgentEngine) -> None:
        began = time.perf_counter()
        original(engine)
        ticks.append(time.perf_counter() - began)

    AgentEngine.step = timed  # type: ignore[method-assign]
    try:
        team.crash("r5", at=5.0)
        team.recover("r5", at=12.0)
        team.run(ticks=int(seconds * 30))
    finally:
        AgentEngine.step = original  # type: ignore[method-assign]
    solves = [e for e in recorder.events if e["event"] == "solve"]
    last = {}
    for e in solves:
        last[e["agent"]] = e["values"]
    alive = [n for n in names if n not in team.crashed]
    agree = len({json_key(last.get(n)) for n in alive}) == 1 if solved else True
    return {
        "ticks": ticks,
        "solves": [e["time_ms"] for e in solves if e["how"] == "solved"],
        "adopted": sum(e["how"] == "shared" for e in solves),
        "agree": agree,
    }


def json_key(value: object) -> str:
    import json

    return json.dumps(value, sort_keys=True)


def engine_table(agents: int = 5) -> None:
    """The cost of solving inside the engine tick (see the module docstring)."""
    print(f"\n### Inside the engine: {agents} agents at 30 Hz, 20 s, one crash and one recovery\n")
    print(
        "| run | agent ticks | tick median ms | tick p99 ms | tick max ms | solves | solve median ms | adopted | agree |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for solved in (False, True):
        out = engine_run(solved, agents)
        ticks = [t * 1000 for t in out["ticks"]]  # type: ignore[attr-defined]
        solves = out["solves"]
        median_solve = f"{statistics.median(solves):.1f}" if solves else "-"  # type: ignore[arg-type]
        print(
            f"| {'with constraints' if solved else 'baseline'} | {len(ticks)} | {statistics.median(ticks):.3f} | "
            f"{percentile(ticks, 99):.2f} | {max(ticks):.1f} | {len(solves)} | {median_solve} | "  # type: ignore[arg-type]
            f"{out['adopted']} | {'yes' if out['agree'] else 'no'} |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--instances", type=int, default=20, help="random instances per frontier size")
    parser.add_argument("--size", type=float, default=50.0, help="side of the square of the 5 x 200 instances (m)")
    parser.add_argument("--runs", type=int, default=20, help="solve() runs (seeds) of the formation")
    parser.add_argument("--starts", type=int, default=100, help="random starts of the formation")
    args = parser.parse_args()
    frontier_table(args.instances, args.size)
    formation_table(args.runs, args.starts)
    engine_table()


if __name__ == "__main__":
    main()
