"""Imported designer plans run on our engine: scripted skills, conditions set as facts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from alica.app.cli import main
from alica.engine import EngineConfig, SimulatedTeam, TraceRecorder
from alica.io import Loader
from alica.io.designer import import_designer, write_result
from alica.testing import scripted
from tests.io.test_designer_helpers import designer_folder


@pytest.fixture(scope="module")
def out(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shared designer folder imported once."""
    folder = tmp_path_factory.mktemp("designer") / "out"
    result = import_designer(designer_folder())
    assert result.complete
    write_result(result, folder)
    return folder


def test_simple_test_plan_runs_its_behaviour_and_moves_on_when_the_condition_holds(out: Path) -> None:
    library = Loader(search_path=[out]).load(out / "plans" / "SimpleTestPlan.yaml", out / "roles" / "Roleset.yaml")
    midfield, attack = scripted(["running"]), scripted(["running"])
    recorder = TraceRecorder()
    sim = SimulatedTeam(
        library,
        "SimpleTestPlan",
        {"a": "Attacker"},
        skills={"MidFieldStandard": midfield, "Attack": attack},
        observers=[recorder],
        config=EngineConfig(frequency=10.0),
    )
    engine = sim.engines["a"]
    # the plan's runtime condition is C++ in the designer (marked disabled there, evaluated all the same):
    # a predicate here, which must hold for the plan to keep running
    engine.world_model.assert_fact("SimpleTestPlanRuntimeCondition")
    # 1. the agent enters TestState1 and its behaviour MidFieldStandard runs
    sim.run(ticks=5)
    assert engine.root is not None and (engine.root.ep, engine.root.state) == ("DefaultTask", "TestState1")
    assert len(midfield.instances) == 1 and midfield.instances[0].ticks > 1
    assert not attack.instances and not recorder.of("transition")
    # 2. the C++ condition IsAnyChildStatus is a predicate: once the fact holds, the transition fires
    engine.world_model.assert_fact("IsAnyChildStatus")
    sim.run(ticks=3)
    assert (engine.root.ep, engine.root.state) == ("DefaultTask", "TestState2")
    (fired,) = recorder.of("transition")
    assert (fired["source"], fired["target"]) == ("TestState1", "TestState2")
    assert len(attack.instances) == 1  # TestState2 runs Attack


def test_alica_run_with_stand_ins_and_facts(out: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # alica run takes one file: a two-line mission file imports the plan and a role set
    mission = out / "adjacent_mission.yaml"
    mission.write_text("imports: [plans/AdjacentSuccessSubPlan.yaml, roles/Roleset.yaml]\n", encoding="utf-8")
    argv = ["run", str(mission), "--name", "AdjacentSuccessSubPlan", "--agents", "a:Attacker", "--stand-ins", "--json"]
    try:
        # without the conditions' facts the agent waits in its first state
        assert main([*argv, "--time-limit", "3"]) == 1
        waiting = json.loads(capsys.readouterr().out)
        assert waiting["agents"]["a"]["path"] == "AdjacentSuccessSubPlan:EntryState"
        # Entry2Wait at 1 s, Wait2Suc at 2 s: the plan reaches its success state
        assert main([*argv, "--fact", "Entry2Wait@1", "--fact", "Wait2Suc@2"]) == 0
        done = json.loads(capsys.readouterr().out)
        assert done["success"] and done["agents"]["a"]["path"] == "AdjacentSuccessSubPlan:SucState"
        assert done["agents"]["a"]["transitions"] == 2
    finally:
        mission.unlink()


def _team(out: Path, plan: str, roleset: str, agents: dict[str, str]) -> tuple[SimulatedTeam, TraceRecorder]:
    library = Loader(search_path=[out]).load(out / "plans" / f"{plan}.yaml", out / "roles" / f"{roleset}.yaml")
    recorder = TraceRecorder()
    config = EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3)
    skills = {"Attack": scripted(["running"]), "AttackOpp": scripted(["running"])}
    sim = SimulatedTeam(library, plan, agents, skills=skills, observers=[recorder], config=config)
    return sim, recorder


def _set(sim: SimulatedTeam, *names: str) -> None:
    sim.set_facts([(True, name, ()) for name in names])


def _in_child(sim: SimulatedTeam, agent: str) -> tuple[str | None, str | None]:
    root = sim.engines[agent].root
    assert root is not None
    node = next(s.node for s in root.slots if s.node is not None)
    return node.ep, node.state


def test_multi_agent_plan_as_the_cpp_test_runs_it(out: Path) -> None:
    """runMultiAgentPlan on the imported files: nase (Defender) and hairy (Attacker), as Alica.yaml sets them."""
    sim, _ = _team(out, "MultiAgentTestMaster", "RolesetTA", {"nase": "Defender", "hairy": "Attacker"})
    sim.run(ticks=10)
    assert all(sim.engines[a].root.state == "Init" for a in ("nase", "hairy"))  # type: ignore[union-attr]
    _set(sim, "Init2Start")
    sim.run(ticks=3)
    # the Attacker prefers AttackTask (0.6 against 0.5): hairy attacks, nase takes the other task
    assert _in_child(sim, "hairy") == ("AttackTask", "OtherState")
    assert _in_child(sim, "nase") == ("DefaultTask", "State1")
    _set(sim, "StateOne2StateTwo", "Other2NewSuccessStateOne")
    sim.run(ticks=2)
    # hairy's task succeeded and its entry point is full: it takes the free Idle entry point
    assert _in_child(sim, "hairy") == ("NewEntryPoint", "Idle")
    assert _in_child(sim, "nase") == ("DefaultTask", "State2")
    _set(sim, "Start2Finish")
    sim.run(ticks=2)
    assert all(sim.engines[a].root.state == "Finished" for a in ("nase", "hairy"))  # type: ignore[union-attr]


def test_synchronised_transitions_fire_together_once_both_hold(out: Path) -> None:
    """syncTransitionTest on the imported files: not before both conditions hold, then in the same step."""
    sim, recorder = _team(out, "RealMasterPlanForSyncTest", "RolesetTA", {"nase": "Defender", "hairy": "Attacker"})
    sim.run(ticks=5)
    assert _in_child(sim, "hairy") == ("AttackTask", "FirstTaskFirstState")
    assert _in_child(sim, "nase") == ("DefaultTask", "SecondTaskFirstState")
    _set(sim, "FirstTaskFirstState2FirstTaskSecondState")
    sim.run(ticks=10)
    assert _in_child(sim, "hairy") == ("AttackTask", "FirstTaskFirstState")  # waits for its partner
    _set(sim, "SecondTaskFirstState2SecondTaskSecondState")
    sim.run(ticks=5)
    assert _in_child(sim, "hairy") == ("AttackTask", "FirstTaskSecondState")
    assert _in_child(sim, "nase") == ("DefaultTask", "SecondTaskSecondState")
    fired = [e for e in recorder.of("transition") if e["name"] in ("FirstTaskTran", "SecondTaskTran")]
    assert len(fired) == 2 and fired[0]["t"] == fired[1]["t"]
