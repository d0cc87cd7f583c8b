"""Tick-by-tick rules of one agent: transitions, behaviour life cycle, success and failure propagation."""

from __future__ import annotations

from alica.engine import ChildStatus
from alica.testing import scripted
from tests.engine.helpers import library, team, where

PLANS = """
predicates: [ready/0, abort/0, stop/0]
behaviours:
  - {name: DoWork, skill: Work}
  - {name: Guarded, skill: Work, pre: "ready"}
  - {name: Running, skill: Work, run: "not abort"}
plans:
  - name: Job
    entry_points: [{task: Work, state: Start, min: 1, max: 1, success_required: true}]
    states:
      - name: Start
        children: [DoWork]
        transitions:
          - {to: Finish, condition: "succeeded"}
          - {to: Broken, condition: "failed"}
      - {name: Finish, kind: success}
      - {name: Broken, kind: failure}
  - name: Parent
    entry_points: [{task: Default, state: Run, min: 1, max: "*"}]
    states:
      - name: Run
        children: [Job]
        transitions:
          - {to: Done, condition: "succeeded(Job)"}
          - {to: Gave, condition: "failed(Job)"}
      - {name: Done, kind: success}
      - {name: Gave, kind: failure}
  - name: Gate
    entry_points: [{task: Default, state: Wait, min: 1, max: "*"}]
    states:
      - name: Wait
        children: [Guarded]
        transitions:
          - {to: Left, condition: "stop"}
      - {name: Left, kind: success}
  - name: Watchful
    entry_points: [{task: Default, state: Busy, min: 1, max: "*"}]
    states:
      - name: Busy
        children: [Running]
        transitions:
          - {to: Left, condition: "failed"}
      - {name: Left, kind: success}
  - name: Unhandled
    entry_points: [{task: Default, state: Busy, min: 1, max: "*"}]
    states:
      - name: Busy
        children: [DoWork]
        transitions:
          - {to: Left, condition: "succeeded"}
      - {name: Left, kind: success}
"""


def test_transition_fires_the_tick_after_the_behaviour_succeeds(tmp_path):
    lib = library(tmp_path, PLANS)
    work = scripted(["running", "running", "success"])
    sim, trace = team(lib, "Parent", {"w": "Worker"}, {"Work": work})
    # 1. tick: root allocated, Job allocated, DoWork started and running
    sim.tick()
    assert where(sim, "w") == ("Default", "Run") and where(sim, "w", 1) == ("Work", "Start")
    assert work.instances[0].starts == 1
    sim.tick()  # 2. running
    sim.tick()  # 3. success (rules ran before the behaviour)
    assert where(sim, "w", 1) == ("Work", "Start")
    sim.tick()  # 4. Start -> Finish; Job succeeds; Run -> Done in the same tick (fast path)
    assert where(sim, "w") == ("Default", "Done")
    assert sim.engines["w"].root.status is ChildStatus.SUCCESS
    names = [(e["source"], e["target"]) for e in trace.of("transition")]
    assert names == [("Start", "Finish"), ("Run", "Done")]
    assert sim.done() and sim.summary()["success"]


def test_behaviour_not_started_while_its_precondition_fails(tmp_path):
    lib = library(tmp_path, PLANS)
    work = scripted(["running"])
    sim, _ = team(lib, "Gate", {"w": "Worker"}, {"Work": work})
    sim.run(ticks=3)
    assert work.instances == []
    sim.engines["w"].world_model.assert_fact("ready")
    sim.run(ticks=1)
    assert len(work.instances) == 1 and work.instances[0].starts == 1


def test_leaving_a_state_terminates_its_running_behaviour(tmp_path):
    lib = library(tmp_path, PLANS)
    work = scripted(["running"])
    sim, _ = team(lib, "Gate", {"w": "Worker"}, {"Work": work})
    sim.engines["w"].world_model.assert_fact("ready")
    sim.run(ticks=2)
    assert work.instances[0].stops == 0
    sim.engines["w"].world_model.assert_fact("stop")
    sim.run(ticks=1)
    assert where(sim, "w") == ("Default", "Left")
    assert work.instances[0].stops == 1


def test_runtime_condition_failure_fails_the_behaviour(tmp_path):
    lib = library(tmp_path, PLANS)
    sim, trace = team(lib, "Watchful", {"w": "Worker"}, {"Work": scripted(["running"])})
    sim.run(ticks=2)
    sim.engines["w"].world_model.assert_fact("abort")
    sim.run(ticks=2)
    assert where(sim, "w") == ("Default", "Left")
    failed = trace.of("behaviour", status="failure")
    assert failed and "no longer holds" in failed[0]["reason"]


def test_a_handled_failure_is_not_repaired_and_the_failure_state_is_repaired(tmp_path):
    lib = library(tmp_path, PLANS)
    work = scripted(["failure"])
    sim, trace = team(lib, "Parent", {"w": "Worker"}, {"Work": work})
    sim.run(ticks=20)
    job = [e["stage"] for e in trace.of("repair", key="Parent/Run/Job")]
    root = [e["stage"] for e in trace.of("repair", key="Parent")]
    # Job reaches its failure state; Parent handles that with a transition into its own failure
    # state Gave, in the same step and before any repair of Job (the C++ engine's continueOnFailure).
    # Parent fails in turn: the master plan is retried once (Job fails, Gave again), then the
    # mission has failed.
    assert job == []
    assert root == ["retry", "propagate"]
    assert [e["target"] for e in trace.of("transition", key="Parent")] == ["Gave", "Gave"]
    assert len(work.instances) == 2
    assert sim.status_of("w") == "failure"


def test_unhandled_child_failure_fails_the_plan(tmp_path):
    lib = library(tmp_path, PLANS)
    sim, trace = team(lib, "Unhandled", {"w": "Worker"}, {"Work": scripted(["failure"])})
    sim.run(ticks=8)
    reasons = [e["reason"] for e in trace.of("failure")]
    assert any("no transition handles it" in r for r in reasons)
    # the master plan is retried once, then the agent's mission has failed
    assert [e["stage"] for e in trace.of("repair")] == ["retry", "propagate"]
    assert sim.status_of("w") == "failure"
    assert sim.done() and not sim.summary()["success"]
