"""The C++ ALICA engine's own test scenarios, as plans in our format run on our engine.

Each test names the scenario of ``alica_tests/src/test`` it follows, from the
descriptions in ``../shared/reference/alica_designer/SOURCE.md`` ("What the C++
tests assert"). The differences the engine keeps on purpose are stated in
docs/engine.md, "Differences from the C++ engine", and tested here too.
"""

from __future__ import annotations

import json

import pytest

from alica.engine import EngineConfig
from alica.engine.status import ChildStatus
from alica.testing import scripted
from tests.engine.helpers import library, team, where

FAST = EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3)


def _fact(sim, name, positive=True):
    sim.set_facts([(positive, name, ())])


def _child_plan(sim, agent, depth=1):
    node = sim.engines[agent].root
    for _ in range(depth):
        assert node is not None
        node = next((s.node for s in node.slots if s.node is not None), None)
    return node.plan.name if node is not None else None


# -- runBehaviourInSimplePlan ----------------------------------------------------

SIMPLE = """
predicates: [go/0]
behaviours:
  - {name: MidFieldStandard, skill: Work}
  - {name: Attack, skill: Check}
  - {name: Slow, skill: Wait, frequency: 5}
plans:
  - name: SimpleTestPlan
    entry_points: [{task: Default, state: TestState1}]
    states:
      - name: TestState1
        children: [MidFieldStandard, Slow]
        transitions: [{to: TestState2, condition: "succeeded(MidFieldStandard)"}]
      - {name: TestState2, children: [Attack]}
"""


def test_run_behaviour_in_simple_plan(tmp_path):
    """A behaviour that succeeds moves the plan on; a running behaviour is ticked at its frequency."""
    lib = library(tmp_path, SIMPLE)
    work, slow, attack = scripted(["running"] * 5 + ["success"]), scripted(["running"]), scripted(["running"])
    config = EngineConfig(frequency=20.0, broadcast_interval=0.1, team_timeout=0.5)
    sim, _ = team(lib, "SimpleTestPlan", {"w": "Worker"}, {"Work": work, "Check": attack, "Wait": slow}, config=config)
    sim.run(ticks=5)
    assert where(sim, "w") == ("Default", "TestState1")
    sim.run(ticks=2)
    assert where(sim, "w") == ("Default", "TestState2")
    assert work.instances[0].ticks == 6
    # 5 Hz under a 20 Hz engine: every fourth tick of the 6 spent in TestState1
    assert slow.instances[0].ticks == 2
    assert len(attack.instances) == 1 and attack.instances[0].ticks >= 1


# -- runMultiAgentPlan -----------------------------------------------------------

MULTI = """
predicates: [Init2Start/0, StateOne2StateTwo/0, Other2NewSuccessStateOne/0, StateTwo2NewSuccessStateTwo/0]
behaviours:
  - {name: Attack, skill: Work}
  - {name: AttackOpp, skill: Check}
plans:
  - name: MultiAgentTestPlan
    entry_points:
      - {name: AttackTask, task: Work, state: OtherState, min: 1, max: 1, success_required: true}
      - {name: DefaultTask, task: Help, state: State1, min: 1, max: 1, success_required: true}
      - {name: NewEntryPoint, task: Watch, state: Idle, min: 0, max: "*"}
    states:
      - name: OtherState
        children: [Attack]
        transitions: [{to: NewSuccessState1, condition: "Other2NewSuccessStateOne"}]
      - name: State1
        children: [Attack]
        transitions: [{to: State2, condition: "StateOne2StateTwo"}]
      - name: State2
        children: [Attack]
        transitions: [{to: NewSuccessState2, condition: "StateTwo2NewSuccessStateTwo"}]
      - {name: NewSuccessState1, kind: success}
      - {name: NewSuccessState2, kind: success}
      - {name: Idle, children: [AttackOpp]}
  - name: MultiAgentTestMaster
    entry_points: [{task: Default, state: Init}]
    states:
      - name: Init
        transitions: [{to: Start, condition: "Init2Start"}]
      - name: Start
        children: [MultiAgentTestPlan]
        transitions: [{to: Finished, condition: "succeeded(MultiAgentTestPlan)"}]
      - {name: Finished, children: [Attack]}
"""


def test_run_multi_agent_plan_moves_a_succeeded_agent_to_a_free_entry_point(tmp_path):
    """runMultiAgentPlan: the agent whose task succeeded goes to the free Idle entry point of the same plan."""
    lib = library(tmp_path, MULTI)
    skills = {"Work": scripted(["running"]), "Check": scripted(["running"])}
    sim, trace = team(lib, "MultiAgentTestMaster", {"nase": "Worker", "hairy": "Helper"}, skills, config=FAST)
    sim.run(ticks=10)
    assert where(sim, "nase") == where(sim, "hairy") == ("Default", "Init")
    _fact(sim, "Init2Start")
    sim.run(ticks=3)
    assert _child_plan(sim, "nase") == _child_plan(sim, "hairy") == "MultiAgentTestPlan"
    assert where(sim, "nase", 1) == ("AttackTask", "OtherState")
    assert where(sim, "hairy", 1) == ("DefaultTask", "State1")
    _fact(sim, "StateOne2StateTwo")
    _fact(sim, "Other2NewSuccessStateOne")
    sim.run(ticks=2)
    # the attacker's task succeeded; its entry point is full (max 1, one success): it takes the free Idle
    assert where(sim, "nase", 1) == ("NewEntryPoint", "Idle")
    assert where(sim, "hairy", 1) == ("DefaultTask", "State2")
    moves = trace.of("allocation", agent="nase", reason="reuse")
    assert moves and moves[-1]["entries"] == {"nase": "NewEntryPoint"}
    # both agree, and the success stays counted: the plan is not done until State2 succeeds too
    for name in ("nase", "hairy"):
        node = sim.engines[name].root.slots[0].node
        assert node.believed["nase"][0] == "NewEntryPoint"
        assert node.status is ChildStatus.RUNNING
    _fact(sim, "Init2Start", positive=False)
    _fact(sim, "StateOne2StateTwo", positive=False)
    sim.run(ticks=3)
    assert where(sim, "hairy", 1) == ("DefaultTask", "State2")  # stays although the transition's cause is gone
    _fact(sim, "StateTwo2NewSuccessStateTwo")
    sim.run(ticks=3)
    assert where(sim, "nase") == where(sim, "hairy") == ("Default", "Finished")


def test_a_succeeded_agent_stays_when_no_entry_point_has_room(tmp_path):
    """Without a free entry point the agent waits in its success state, as before."""
    plans = MULTI.replace('      - {name: NewEntryPoint, task: Watch, state: Idle, min: 0, max: "*"}\n', "")
    plans = plans.replace("      - {name: Idle, children: [AttackOpp]}\n", "")
    lib = library(tmp_path, plans)
    skills = {"Work": scripted(["running"]), "Check": scripted(["running"])}
    sim, trace = team(lib, "MultiAgentTestMaster", {"nase": "Worker", "hairy": "Helper"}, skills, config=FAST)
    _fact(sim, "Init2Start")
    sim.run(ticks=3)
    _fact(sim, "Other2NewSuccessStateOne")
    sim.run(ticks=5)
    assert where(sim, "nase", 1) == ("AttackTask", "NewSuccessState1")
    assert not trace.of("allocation", reason="reuse")


# -- conditionPlanTypeTest ---------------------------------------------------------

PLAN_TYPE = """
predicates: [preOK/0, runOK/0, go/0]
behaviours:
  - {name: Hold, skill: Wait}
plantypes:
  - {name: TestPlanType, plans: [OtherPlan, RuntimeConditionPlan, PreConditionPlan]}
plans:
  - name: PreConditionPlan
    pre: "preOK"
    entry_points: [{task: Work, state: PreConditionTest}]
    states: [{name: PreConditionTest, children: [Hold]}]
  - name: RuntimeConditionPlan
    run: "runOK"
    entry_points: [{task: Help, state: RuntimeConditionTest}]
    states: [{name: RuntimeConditionTest, children: [Hold]}]
  - name: OtherPlan
    entry_points: [{task: Watch, state: OtherPlanTest}]
    states: [{name: OtherPlanTest, children: [Hold]}]
  - name: MasterPlanTestConditionPlanType
    entry_points: [{task: Default, state: Start}]
    states:
      - name: Start
        transitions: [{to: Plantype}]
      - {name: Plantype, children: [TestPlanType]}
"""


def test_plan_type_chooses_among_plans_whose_conditions_hold(tmp_path):
    """conditionPlanTypeTest: utility Pre > Runtime > Other (Work 0.9, Help 0.4, Watch 0.1 for a Worker)."""
    lib = library(tmp_path, PLAN_TYPE)
    sim, trace = team(lib, "MasterPlanTestConditionPlanType", {"w": "Worker"}, {"Wait": scripted(["running"])})
    sim.run(ticks=5)
    assert _child_plan(sim, "w") == "OtherPlan"  # the other two's conditions are false
    _fact(sim, "runOK")
    sim.run(ticks=2)
    assert _child_plan(sim, "w") == "RuntimeConditionPlan"
    _fact(sim, "runOK", positive=False)
    sim.run(ticks=2)
    assert _child_plan(sim, "w") == "OtherPlan"
    _fact(sim, "runOK")
    sim.run(ticks=2)
    assert _child_plan(sim, "w") == "RuntimeConditionPlan"  # chosen again: switching is not a failure
    _fact(sim, "preOK")
    sim.run(ticks=2)
    assert _child_plan(sim, "w") == "PreConditionPlan"
    assert not trace.of("repair")
    assert not trace.of("failure")


def test_a_plan_whose_run_condition_fails_without_alternative_fails(tmp_path):
    """A plain plan child (no plan type) whose run-time condition stops holding still fails and is repaired."""
    plans = PLAN_TYPE.replace("children: [TestPlanType]", "children: [RuntimeConditionPlan]")
    lib = library(tmp_path, plans)
    sim, trace = team(lib, "MasterPlanTestConditionPlanType", {"w": "Worker"}, {"Wait": scripted(["running"])})
    _fact(sim, "runOK")
    sim.run(ticks=3)
    assert _child_plan(sim, "w") == "RuntimeConditionPlan"
    _fact(sim, "runOK", positive=False)
    sim.run(ticks=3)
    assert [e["stage"] for e in trace.of("repair")][:1] == ["retry"]
    assert _child_plan(sim, "w") is None  # waits until the plan may run again
    _fact(sim, "runOK")
    sim.run(ticks=3)
    assert _child_plan(sim, "w") == "RuntimeConditionPlan"


# -- continueOnFailure and AutoFailureHandling -----------------------------------------

FAILURE = """
predicates: [Init2Fail/0, Fail2Failed/0, go/0]
behaviours:
  - {name: Hold, skill: Wait}
plans:
  - name: FailurePlan
    entry_points: [{task: Default, state: Init, success_required: true}]
    states:
      - name: Init
        children: [Hold]
        transitions: [{to: Fail, condition: "Init2Fail"}]
      - name: Fail
        children: [Hold]
        transitions: [{to: Failed, condition: "Fail2Failed"}]
      - {name: Failed, kind: failure}
  - name: FailureHandlingMaster
    entry_points: [{task: Default, state: Running, success_required: true}]
    states:
      - name: Running
        children: [FailurePlan]
"""


def _failure_library(tmp_path, handler: str | None):
    """The failure plans; the master handles its child's failure with a transition on ``handler`` (None: none)."""
    if handler is None:
        return library(tmp_path, FAILURE)
    text = (
        FAILURE
        + f"""        transitions: [{{to: FailureHandled, condition: "{handler}"}}]
      - {{name: FailureHandled, kind: success}}
"""
    )
    return library(tmp_path, text)


def test_continue_on_failure_the_parent_sees_the_failure_before_any_repair(tmp_path):
    """continueOnFailure: the parent's explicit failure transition fires in the step the child fails."""
    lib = _failure_library(tmp_path, "failed(FailurePlan)")
    sim, trace = team(lib, "FailureHandlingMaster", {"w": "Worker"}, {"Wait": scripted(["running"])})
    _fact(sim, "Init2Fail")
    _fact(sim, "Fail2Failed")
    sim.run(until_done=True, max_time=5)
    assert where(sim, "w") == ("Default", "FailureHandled")
    assert not trace.of("repair")  # a retry would have put the agent back in Init, where it fails again


def test_automatic_failure_handling_redoes_a_failed_plan(tmp_path):
    """Failure handling: the failed plan is redone, the failing agent back in its initial state."""
    lib = _failure_library(tmp_path, None)
    sim, trace = team(lib, "FailureHandlingMaster", {"w": "Worker"}, {"Wait": scripted(["running"])})
    _fact(sim, "Init2Fail")
    sim.run(ticks=2)
    assert where(sim, "w", 1) == ("Default", "Fail")
    _fact(sim, "Init2Fail", positive=False)
    _fact(sim, "Fail2Failed")
    sim.run(ticks=1)
    assert [e["stage"] for e in trace.of("repair")] == ["retry"]
    assert where(sim, "w", 1) == ("Default", "Init")


def test_without_automatic_failure_handling_a_failed_plan_stays_failed(tmp_path):
    """AutoFailureHandling: false: no retry, no propagation; the parent's failure transition handles it."""
    lib = _failure_library(tmp_path, "failed(FailurePlan) and go")
    config = EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, auto_failure_handling=False)
    sim, trace = team(lib, "FailureHandlingMaster", {"w": "Worker"}, {"Wait": scripted(["running"])}, config=config)
    _fact(sim, "Init2Fail")
    _fact(sim, "Fail2Failed")
    sim.run(ticks=10)
    engine = sim.engines["w"]
    assert not trace.of("repair")
    assert where(sim, "w") == ("Default", "Running")  # the parent does not fail for its failed child
    assert engine.root.slots[0].status is ChildStatus.FAILURE
    assert engine.root.status is ChildStatus.RUNNING
    sim.set_facts([(True, "go", ())])
    sim.run(until_done=True, max_time=5)
    assert where(sim, "w") == ("Default", "FailureHandled")
    assert not trace.of("repair")


def test_without_automatic_failure_handling_a_failed_root_stays_failed(tmp_path):
    lib = _failure_library(tmp_path, None)
    config = EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, auto_failure_handling=False)
    sim, trace = team(lib, "FailurePlan", {"w": "Worker"}, {"Wait": scripted(["running"])}, config=config)
    _fact(sim, "Init2Fail")
    _fact(sim, "Fail2Failed")
    sim.run(until_done=True, max_time=5)
    assert sim.engines["w"].root.status is ChildStatus.FAILURE
    assert not trace.of("repair")


# -- AgentIsRemoved: allocation retried every step ---------------------------------------

PAIR = """
behaviours:
  - {name: Hold, skill: Wait}
plans:
  - name: Together
    entry_points: [{task: Work, state: W, min: 1, max: 1}, {task: Help, state: H, min: 1, max: 1}]
    states: [{name: W, children: [Hold]}, {name: H, children: [Hold]}]
  - name: Top
    entry_points: [{task: Default, state: S, min: 1, max: "*"}]
    states: [{name: S, children: [Together]}]
"""


def test_allocation_that_failed_for_want_of_teammates_is_retried_in_the_next_step(tmp_path):
    """AgentIsRemoved: a crashed teammate is taken out; when it is heard again, the sub-plan starts within a step."""
    lib = library(tmp_path, PAIR)
    config = EngineConfig(frequency=30.0, broadcast_interval=0.2, team_timeout=0.6, assignment_protection=0.3)
    sim, trace = team(lib, "Top", {"a": "Worker", "b": "Helper"}, {"Wait": scripted(["running"])}, config=config)
    sim.crash("b", at=0.5)
    sim.recover("b", at=3.0)
    sim.run(ticks=80)
    assert trace.of("team", agent="a", change="lost")
    assert _child_plan(sim, "a") is None  # Together needs b
    sim.run(ticks=30)
    back = trace.of("team", agent="a", change="back")[0]["t"]
    started = [e["t"] for e in trace.of("allocation", agent="a", plan="Together") if e["t"] >= back]
    assert started, "Together was not allocated again"
    assert started[0] - back <= config.period + 1e-6, f"took {(started[0] - back) / config.period:.0f} steps"


# -- authority: kept difference ----------------------------------------------------------


def test_authority_goes_to_the_lowest_id_a_kept_difference():
    """The C++ engine gives authority to the highest agent id; ours to the lowest (docs/engine.md says why).

    The behaviour itself is tested in tests/engine/test_authority.py; this checks the docs state the difference.
    """
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "engine.md").read_text(encoding="utf-8")
    section = text.split("## Differences from the C++ engine", 1)
    assert len(section) == 2, "docs/engine.md needs its 'Differences from the C++ engine' section"
    assert "highest" in section[1] and "lowest" in section[1]


# -- the setting on the command line ------------------------------------------------------


def _failing_plan_file(tmp_path):
    text = """alica: 1
imports: [roles.yaml]
predicates: [Init2Fail/0, Fail2Failed/0]
plans:
  - name: FailurePlan
    entry_points: [{task: Default, state: Init, success_required: true}]
    states:
      - {name: Init, transitions: [{to: Fail, condition: "Init2Fail"}]}
      - {name: Fail, transitions: [{to: Failed, condition: "Fail2Failed"}]}
      - {name: Failed, kind: failure}
  - name: Master
    entry_points: [{task: Default, state: Running, success_required: true}]
    states:
      - {name: Running, children: [FailurePlan]}
"""
    library(tmp_path, "")  # writes roles.yaml
    path = tmp_path / "failing.yaml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(("setting", "repaired"), [("on", True), ("off", False)])
def test_alica_run_auto_failure_handling(tmp_path, capsys, setting, repaired):
    from alica.app.cli import main

    trace = tmp_path / "run.jsonl"
    argv = ["run", str(_failing_plan_file(tmp_path)), "--agents", "w:Worker", "--ticks", "20"]
    argv += ["--fact", "Init2Fail and Fail2Failed@0", "--trace", str(trace), "--auto-failure-handling", setting]
    assert main(argv) == 1  # never succeeds either way
    capsys.readouterr()
    events = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()[1:]]
    assert any(e["event"] == "repair" for e in events) is repaired


def test_alica_agent_takes_the_setting():
    from alica.app.cli import build_parser

    args = build_parser().parse_args(["agent", "plans/x.yaml", "--name", "a", "--auto-failure-handling", "off"])
    assert args.auto_failure_handling == "off"


# -- successes claimed after leaving an instance ---------------------------------------------

AGAIN = """
predicates: [doneA/0, again/1]
behaviours:
  - {name: Hold, skill: Wait}
plans:
  - name: X
    entry_points:
      - {name: A, task: Work, state: Working, min: 1, max: 1, success_required: true}
      - {name: B, task: Help, state: Helping, min: 0, max: "*"}
    states:
      - {name: Working, children: [Hold], transitions: [{to: Done, condition: "doneA"}]}
      - {name: Helping, children: [Hold]}
      - {name: Done, kind: success}
  - name: P
    entry_points: [{task: Default, state: S, min: 1, max: "*"}]
    states:
      - {name: S, children: [X], transitions: [{to: T, condition: "succeeded(X)"}]}
      - {name: T, transitions: [{to: S, condition: "again(self)"}]}
"""


def test_a_success_claimed_after_leaving_counts_once_and_not_in_a_new_instance(tmp_path):
    lib = library(tmp_path, AGAIN)
    agents = {"a": "Worker", "b": "Helper", "c": "Helper"}
    sim, trace = team(lib, "P", agents, {"Wait": scripted(["running"])}, config=FAST)
    sim.run(ticks=3)
    assert where(sim, "a", 1) == ("A", "Working") and where(sim, "b", 1) == ("B", "Helping")
    _fact(sim, "doneA")
    sim.run(ticks=3)
    # a succeeded and left X in the same step (its parent moved on); b and c learn it from a's claim
    assert where(sim, "a") == where(sim, "b") == where(sim, "c") == ("Default", "T")
    sim.set_facts([(False, "doneA", ()), (True, "again", ("b",)), (True, "again", ("c",))])
    sim.run(ticks=1)
    sim.set_facts([(False, "again", ("b",)), (False, "again", ("c",))])
    sim.run(ticks=10)
    # b and c in a new instance of X (the same key): a's old success does not count there
    assert where(sim, "a") == ("Default", "T") and where(sim, "b") == where(sim, "c") == ("Default", "S")
    assert {where(sim, "b", 1)[0], where(sim, "c", 1)[0]} == {"A", "B"}
    assert len(trace.of("success", agent="b", plan="X")) == 1


# -- testing (back and forth) ----------------------------------------------------------------

BACK_FORTH = """
behaviours:
  - {name: CountIndefinitely, skill: Work}
plans:
  - name: BackForth
    entry_points: [{task: Default, state: First}]
    states:
      - {name: First, children: [CountIndefinitely], transitions: [{to: Second, condition: "true"}]}
      - {name: Second, children: [CountIndefinitely], transitions: [{to: First, condition: "true"}]}
"""


def test_back_and_forth_keeps_switching_and_its_behaviour_keeps_running(tmp_path):
    """testing: two states whose transitions both hold keep switching, a bounded number of times a step."""
    lib = library(tmp_path, BACK_FORTH)
    count = scripted(["running"])
    sim, trace = team(lib, "BackForth", {"w": "Worker"}, {"Work": count})
    sim.run(ticks=10)
    config = sim.config
    assert len(trace.of("transition")) == 10 * config.max_rule_applications  # every step, never stuck in a loop
    assert sum(instance.ticks for instance in count.instances) == 10  # a CountIndefinitely runs in every step
    assert sim.engines["w"].root.status is ChildStatus.RUNNING


# -- success tests ---------------------------------------------------------------------------

SUCCESS = """
predicates: [go/1]
plans:
  - name: SuccessOnCondPlan
    variables: [x]
    entry_points: [{task: Default, state: Entry}]
    states:
      - {name: Entry, transitions: [{to: Suc, condition: "go(x)"}]}
      - {name: Suc, kind: success}
  - name: WrapperA
    entry_points: [{task: Default, state: Run}]
    states:
      - {name: Run, children: [{ref: SuccessOnCondPlan, bind: {x: a}}], transitions: [{to: Done, condition: "succeeded"}]}
      - {name: Done, kind: success}
  - name: WrapperB
    entry_points: [{task: Default, state: Run}]
    states:
      - {name: Run, children: [{ref: SuccessOnCondPlan, bind: {x: b}}], transitions: [{to: Done, condition: "succeeded"}]}
      - {name: Done, kind: success}
  - name: MultiPlanInstanceSuccessTestPlan
    entry_points: [{task: Default, state: ParallelExec}]
    states:
      - {name: ParallelExec, children: [WrapperA, WrapperB], transitions: [{to: Success, condition: "succeeded"}]}
      - {name: Success, kind: success}
  - name: AdjacentSuccessTestPlan
    entry_points: [{task: Default, state: StateA}]
    states:
      - name: StateA
        children: [{ref: SuccessOnCondPlan, bind: {x: a}}]
        transitions: [{to: StateB, condition: "succeeded(SuccessOnCondPlan)"}]
      - name: StateB
        children: [{ref: SuccessOnCondPlan, bind: {x: a}}]
        transitions: [{to: StateA, condition: "succeeded(SuccessOnCondPlan)"}]
"""


def test_two_instances_of_one_plan_succeed_separately(tmp_path):
    lib = library(tmp_path, SUCCESS)
    sim, trace = team(lib, "MultiPlanInstanceSuccessTestPlan", {"w": "Worker"}, {})
    sim.run(ticks=3)
    sim.set_facts([(True, "go", ("a",))])
    sim.run(ticks=3)
    root = sim.engines["w"].root
    assert [s.status for s in root.slots] == [ChildStatus.SUCCESS, ChildStatus.RUNNING]  # WrapperA, WrapperB
    assert root.state == "ParallelExec"
    sim.set_facts([(True, "go", ("b",))])
    sim.run(until_done=True, max_time=5)
    assert where(sim, "w") == ("Default", "Success")
    assert len(trace.of("success", plan="SuccessOnCondPlan")) == 2


def test_a_fresh_instance_in_an_adjacent_state_is_not_successful(tmp_path):
    lib = library(tmp_path, SUCCESS)
    sim, trace = team(lib, "AdjacentSuccessTestPlan", {"w": "Worker"}, {})
    sim.run(ticks=2)
    sim.set_facts([(True, "go", ("a",))])
    sim.run(ticks=1)
    sim.set_facts([(False, "go", ("a",))])
    sim.run(ticks=5)
    # StateA's instance succeeded; the fresh one of StateB waits for its own condition
    assert where(sim, "w") == ("Default", "StateB")
    assert sim.engines["w"].root.slots[0].status is ChildStatus.RUNNING
    assert len(trace.of("success", plan="SuccessOnCondPlan")) == 1
