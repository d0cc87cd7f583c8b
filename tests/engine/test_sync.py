"""Synchronised transitions fire for all agents together, or fail after their timeout."""

from __future__ import annotations

from alica.testing import scripted
from tests.engine.helpers import library, team, where

PLANS = """
predicates: [grasped/1]
behaviours:
  - {name: Hold, skill: Wait}
plans:
  - name: Lift
    entry_points:
      - {task: Work, state: GraspA, min: 1, max: 1}
      - {task: Help, state: GraspB, min: 1, max: 1}
    synchronisations:
      - {name: Together, transitions: [UpA, UpB], talk_timeout: 0.1, sync_timeout: 1.0, fail_on_timeout: FAIL}
    states:
      - name: GraspA
        children: [Hold]
        transitions:
          - {to: LiftedA, condition: "grasped(a)", name: UpA, sync: Together}
      - name: GraspB
        children: [Hold]
        transitions:
          - {to: LiftedB, condition: "grasped(b)", name: UpB, sync: Together}
      - {name: LiftedA, kind: success}
      - {name: LiftedB, kind: success}
"""


def _setup(tmp_path, fail: bool):
    lib = library(tmp_path, PLANS.replace("FAIL", "true" if fail else "false"))
    return team(lib, "Lift", {"w": "Worker", "h": "Helper"}, {"Wait": scripted(["running"])})


def test_both_fire_in_the_same_tick_once_both_conditions_hold(tmp_path):
    sim, trace = _setup(tmp_path, fail=False)
    sim.run(ticks=2)
    assert where(sim, "w") == ("Work", "GraspA") and where(sim, "h") == ("Help", "GraspB")
    sim.engines["w"].world_model.assert_fact("grasped", "a")
    sim.run(ticks=5)
    # w's condition holds but h's does not: nobody moves
    assert where(sim, "w") == ("Work", "GraspA")
    sim.engines["h"].world_model.assert_fact("grasped", "b")
    sim.run(ticks=6)
    assert where(sim, "w") == ("Work", "LiftedA") and where(sim, "h") == ("Help", "LiftedB")
    fired = trace.of("transition")
    assert {e["agent"] for e in fired} == {"w", "h"}
    assert len({e["t"] for e in fired}) == 1, fired
    assert sim.summary()["success"]


def test_timeout_fails_the_plan_when_asked(tmp_path):
    sim, trace = _setup(tmp_path, fail=True)
    sim.run(ticks=1)
    sim.engines["w"].world_model.assert_fact("grasped", "a")
    sim.run(ticks=15)
    failures = trace.of("failure", agent="w")
    assert failures and "timed out" in failures[0]["reason"]
    assert not trace.of("transition", agent="w", target="LiftedA")


def test_timeout_without_failure_starts_over(tmp_path):
    sim, trace = _setup(tmp_path, fail=False)
    sim.run(ticks=1)
    sim.engines["w"].world_model.assert_fact("grasped", "a")
    sim.run(ticks=15)
    assert trace.of("sync", agent="w", outcome="timeout")
    assert not trace.of("failure", agent="w")
    sim.engines["h"].world_model.assert_fact("grasped", "b")
    sim.run(ticks=6)
    assert where(sim, "w") == ("Work", "LiftedA")
