"""Plan variables solved at run time: bindings, the team's agreement, crashes, no solution, context.solve."""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from typing import Any

import pytest

from alica.testing import scripted
from tests.engine.helpers import library, team

SPREAD = """
behaviours:
  - name: Hold
    skill: Work
    variables: [spot]
    params: {duration: $spot}
plans:
  - name: Spread
    variables:
      - spot - point[-5, 5]
    constraints:
      - name: Apart
        formula: "forall a, b in agents(Work): a == b or dist(spot(a), spot(b)) >= 2.0"
      - name: East
        formula: "forall a in agents(Work): spot(a).x >= 0"
      - name: West
        utility: "0 - (sum a in agents(Work): spot(a).x)"
    entry_points:
      - {name: Work, task: Work, state: Stand, min: 1, max: "*"}
    states:
      - name: Stand
        children:
          - {ref: Hold, bind: {spot: spot}}
        transitions:
          - {to: Done, condition: "succeeded(Hold)"}
          - {to: Broken, condition: "failed(Hold)"}
      - {name: Done, kind: success}
      - {name: Broken, kind: failure}
"""

NOWHERE = """
behaviours:
  - name: Pick
    skill: Work
    variables: [target]
    params: {duration: $target}
plans:
  - name: Choose
    variables:
      - target - Frontier
    constraints:
      - name: Distinct
        formula: "forall a, b in agents(Work): a == b or target(a) != target(b)"
    entry_points:
      - {name: Work, task: Work, state: Pick, min: 1, max: "*"}
    states:
      - name: Pick
        children:
          - {ref: Pick, bind: {target: target}}
        transitions:
          - {to: Done, condition: "succeeded(Pick)"}
          - {to: NoTarget, condition: "failed(Pick)"}
      - {name: Done, kind: success}
      - {name: NoTarget, kind: failure}
"""


class Recorder:
    """A skill factory that records the parameters each instance got, and runs ``script``."""

    def __init__(self, script: tuple[str, ...] = ("running",)) -> None:
        self.inner = scripted(list(script))
        self.params: list[tuple[str, Mapping[str, object]]] = []
        self.contexts: list[Any] = []

    def __call__(self, name: str, params: Mapping[str, object], context: Any) -> Any:
        self.params.append((context.agent, dict(params)))
        self.contexts.append(context)
        return self.inner(name, params, context)


def solves(trace: Any) -> list[dict[str, Any]]:
    return [e for e in trace.events if e["event"] == "solve"]


def spots(event: dict[str, Any]) -> dict[str, tuple[float, float]]:
    return {agent: tuple(v["spot"]) for agent, v in event["values"].items() if agent}


def test_a_behaviour_bound_to_a_solved_variable_gets_this_agents_value_and_the_team_agrees(tmp_path):
    lib = library(tmp_path, SPREAD)
    work = Recorder()
    sim, trace = team(lib, "Spread", {"a": "Worker", "b": "Worker", "c": "Worker"}, {"Work": work})
    for _ in range(5):
        sim.tick()
    events = solves(trace)
    assert {e["agent"] for e in events} == {"a", "b", "c"}
    assert all(e["status"] == "solved" for e in events)
    team_values = [spots(e) for e in events]
    assert all(v == team_values[0] for v in team_values)  # the same view, the same answer
    placed = team_values[0]
    assert set(placed) == {"a", "b", "c"}
    for p in placed.values():
        assert p[0] >= 0  # the hard constraint
    names = sorted(placed)
    for i, p in enumerate(names):
        for q in names[i + 1 :]:
            assert math.dist(placed[p], placed[q]) >= 2.0 - 1e-9
    # each behaviour received its own agent's value, not the variable's name
    for agent, params in work.params:
        assert tuple(params["duration"]) == placed[agent]  # type: ignore[arg-type]


def test_a_crash_changes_the_team_and_the_survivors_solve_again(tmp_path):
    lib = library(tmp_path, SPREAD)
    work = Recorder()
    sim, trace = team(lib, "Spread", {"a": "Worker", "b": "Worker", "c": "Worker"}, {"Work": work})
    sim.run(ticks=10)
    before = spots(solves(trace)[-1])
    assert set(before) == {"a", "b", "c"}
    sim.crash("c")
    sim.run(ticks=30)  # c is taken out after the team timeout (0.5 s here)
    after = [e for e in solves(trace) if e["agent"] in ("a", "b") and e["t"] > 1.0]
    assert after, "the survivors did not solve again"
    assert all(set(spots(e)) == {"a", "b"} for e in after)
    final = {e["agent"]: spots(e) for e in after}
    assert final["a"] == final["b"]


def test_no_solution_is_a_failure_the_plan_reacts_to(tmp_path):
    lib = library(tmp_path, NOWHERE)  # no Frontier objects: the variable has no candidates
    work = Recorder(("success",))
    sim, trace = team(lib, "Choose", {"a": "Worker"}, {"Work": work})
    sim.run(ticks=10)
    assert not work.params  # the behaviour never started
    failures = [e for e in trace.events if e["event"] == "failure" and e.get("child") == "Pick"]
    assert failures and "no values for target" in failures[0]["reason"]
    transitions = [e for e in trace.events if e["event"] == "transition" and e.get("target") == "NoTarget"]
    assert transitions


def test_finite_values_from_the_world_model_and_distinct_per_agent(tmp_path):
    lib = library(tmp_path, NOWHERE)
    work = Recorder()
    sim, _ = team(lib, "Choose", {"a": "Worker", "b": "Worker"}, {"Work": work})
    for engine in sim.engines.values():
        for name in ("f1", "f2", "f3"):
            engine.own.add_object(name, "Frontier")
    sim.run(ticks=10)
    got = {agent: params["duration"] for agent, params in work.params}
    assert set(got) == {"a", "b"} and got["a"] != got["b"]
    assert set(got.values()) <= {"f1", "f2", "f3"}


def test_a_skill_asks_through_its_context(tmp_path):
    lib = library(tmp_path, SPREAD)
    work = Recorder()
    sim, _ = team(lib, "Spread", {"a": "Worker", "b": "Worker"}, {"Work": work})
    sim.run(ticks=5)
    context = next(c for c in work.contexts if c.agent == "a")
    result = context.solve("spot")
    assert result.ok and result.status == "solved"
    assert set(result.team) == {"a", "b"}
    assert result.values["spot"] == result.team["a"]["spot"]
    assert math.dist(result.team["a"]["spot"], result.team["b"]["spot"]) >= 2.0 - 1e-9


def test_the_explore_plan_gives_each_explorer_its_frontier_eq_7_8():
    """IMPERA Eq. 7-8 in the shipped Explore plan, frontier candidates and gains from a test map."""
    from alica.engine import EngineConfig, SimulatedTeam, TraceRecorder
    from alica.io import load_library
    from alica.io.loader import plans_dir
    from alica.testing import default_fallback

    lib = load_library(plans_dir() / "skills" / "explore.yaml")
    # frontier cells of a test map: a ring 8 m around the origin, one cell every 30 degrees;
    # the cells towards +x border more unknown space (a higher gain)
    cells = {f"f{k}": (8 * math.cos(math.radians(30 * k)), 8 * math.sin(math.radians(30 * k))) for k in range(12)}
    gains = {name: round(10 + 5 * math.cos(math.radians(30 * k)), 3) for k, name in enumerate(cells)}
    robots = {"scout": (0.0, 0.0), "stummel": (1.0, 1.0), "s2": (-1.0, 0.5)}
    work = Recorder()
    recorder = TraceRecorder()
    sim = SimulatedTeam(
        lib,
        "Explore",
        {"scout": "Scout", "stummel": "Stummel", "s2": "Stummel"},
        skills={"ExploreFrontier": work},
        fallback=default_fallback(),
        observers=[recorder],
        config=EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3),
    )
    for engine in sim.engines.values():
        engine.own.add("mapped")
        for name, xy in {**cells, **robots}.items():
            engine.own.set("Pos", name, value=xy)
        for name in cells:
            engine.own.add_object(name, "Frontier")
            engine.own.set("gain", name, value=gains[name])
    sim.run(ticks=60)
    # ExploreFrontier asks for its frontier through its context when it needs one
    contexts = {c.agent: c for c in work.contexts}
    assert set(contexts) == {"scout", "stummel", "s2"}, work.params
    latest = {agent: context.solve("frontier").values["frontier"] for agent, context in contexts.items()}
    chosen = list(latest.values())
    for i, f in enumerate(chosen):
        for g in chosen[i + 1 :]:
            assert math.dist(cells[f], cells[g]) > 4.0  # Eq. 7: spread, so distinct
    for agent, f in latest.items():
        assert math.dist(cells[f], robots[agent]) < 15.0  # Eq. 8

    # the utility: the summed gain less each robot's travel, best over every assignment of cells more than 4 m apart
    def value(assignment: dict[str, str]) -> float:
        return sum(gains[f] - math.dist(cells[f], robots[a]) for a, f in assignment.items())

    best = max(
        value(dict(zip(robots, combo, strict=True)))
        for combo in itertools.permutations(cells, 3)
        if all(math.dist(cells[p], cells[q]) > 4.0 for p, q in itertools.combinations(combo, 2))
    )
    assert value(latest) == pytest.approx(best)
