"""The IMPERA role set on the shipped lunar mission: who explores, who transports, and after crashes."""

from __future__ import annotations

import pytest

from alica.engine import EngineConfig, SimulatedTeam, TraceRecorder
from alica.io import load_library
from alica.testing import default_fallback
from tests.conftest import PLANS

TEAM = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"}


@pytest.fixture(scope="module")
def lunar():
    return load_library(PLANS / "lunar" / "mission.yaml")


def _team(lunar, seed=0):
    recorder = TraceRecorder()
    sim = SimulatedTeam(
        lunar,
        "LunarMission",
        TEAM,
        seed=seed,
        fallback=default_fallback(seed, 0.5, 1.5),
        observers=[recorder],
        config=EngineConfig(frequency=10.0, team_timeout=0.5),
    )
    return sim, recorder


def _task(sim, agent):
    root = sim.engines[agent].root
    return root.plan.entry_point(root.ep).task if root.ep else None


def _found(sim, at):
    sim.set_facts([(True, "found", ("a",)), (True, "found", ("b",))], at=at)


def test_scout_explores_and_amparo_transports(lunar):
    sim, _ = _team(lunar)
    sim.run(ticks=2)
    assert {a: _task(sim, a) for a in TEAM} == {"scout": "Explore", "amparo": "Transport1", "stummel": "Transport2"}
    _found(sim, 3.0)
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"], summary
    root = sim.engines["stummel"].root
    assert root.succeeded["Transport1"] == {"amparo"} and root.succeeded["Transport2"] == {"stummel"}
    # done with its task, Stummel goes to the free Explore entry point, which succeeds at once;
    # Amparo cannot explore (priority -1) and stays where its task succeeded
    assert sim.engines["stummel"].root.state == "SamplesFound"
    assert sim.engines["amparo"].root.state == "DeliveredA"


def test_scout_crashes_and_stummel_explores(lunar):
    sim, trace = _team(lunar)
    sim.run(ticks=5)
    sim.crash("scout")
    sim.run(ticks=10)
    assert _task(sim, "stummel") == "Explore"
    assert _task(sim, "amparo") == "Transport1"
    # Stummel, exploring, runs the Explore plan and takes the map-building task of Scout
    explore = sim.engines["stummel"].root.slots[0].node
    assert explore.plan.name == "Explore" and explore.plan.entry_point(explore.ep).task == "GetMap"
    _found(sim, 4.0)
    summary = sim.run(until_done=True, max_time=200)
    # when its exploration succeeded, Stummel brings in the second sample, which nobody had taken
    assert summary["success"], summary
    assert trace.of("allocation", agent="stummel", reason="reuse")
    assert sim.engines["stummel"].root.state == "DeliveredB"


def test_amparo_crashes_and_stummel_takes_its_transport(lunar):
    sim, _ = _team(lunar)
    sim.run(ticks=5)
    sim.crash("amparo")
    sim.run(ticks=10)
    assert _task(sim, "stummel") == "Transport1"
    assert _task(sim, "scout") == "Explore"
    _found(sim, 4.0)
    summary = sim.run(until_done=True, max_time=300)
    assert summary["success"], summary
    assert sim.engines["stummel"].root.state == "DeliveredB"


def test_crashed_robot_back_explores_and_hysteresis_keeps_the_rest(lunar):
    sim, trace = _team(lunar)
    sim.run(ticks=5)
    sim.crash("scout")
    sim.run(ticks=10)
    assert _task(sim, "stummel") == "Explore"
    sim.recover("scout")
    sim.run(ticks=10)
    # Scout is taken back and explores. Moving Stummel back to Transport2 would gain priority
    # (0.55 vs 0.5) but lose similarity (weight 0.2): less than the threshold 0.1, so it stays.
    assert {a: _task(sim, a) for a in TEAM} == {"scout": "Explore", "amparo": "Transport1", "stummel": "Explore"}
    assert trace.of("team", agent="stummel", change="back", who="scout")
