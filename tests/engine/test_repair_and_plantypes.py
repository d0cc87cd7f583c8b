"""Plan types: the best alternative is chosen by utility; repair retries, replaces, then propagates.

A parent state that handles its child's failure with a transition (``failed(Approach)``) sees the
failure first, before any repair (the C++ engine's continueOnFailure); ``TopAuto`` has no such
transition, so its child goes through the repair stages.
"""

from __future__ import annotations

from alica.testing import scripted
from tests.engine.helpers import library, team, where

PLANS = """
behaviours:
  - {name: DoWork, skill: Work}
  - {name: DoHelp, skill: Check}
plantypes:
  - {name: Approach, plans: [ByHelping, ByWorking]}
plans:
  - name: ByWorking
    entry_points: [{task: Work, state: W, min: 1, max: 1, success_required: true}]
    states:
      - name: W
        children: [DoWork]
        transitions:
          - {to: WDone, condition: "succeeded"}
          - {to: WFail, condition: "failed"}
      - {name: WDone, kind: success}
      - {name: WFail, kind: failure}
  - name: ByHelping
    entry_points: [{task: Help, state: H, min: 1, max: 1, success_required: true}]
    states:
      - name: H
        children: [DoHelp]
        transitions:
          - {to: HDone, condition: "succeeded"}
          - {to: HFail, condition: "failed"}
      - {name: HDone, kind: success}
      - {name: HFail, kind: failure}
  - name: Top
    entry_points: [{task: Default, state: Try, min: 1, max: "*"}]
    states:
      - name: Try
        children: [Approach]
        transitions:
          - {to: Done, condition: "succeeded(Approach)"}
          - {to: GaveUp, condition: "failed(Approach)"}
      - {name: Done, kind: success}
      - {name: GaveUp, kind: success}
  - name: TopAuto
    entry_points: [{task: Default, state: Try, min: 1, max: "*"}]
    states:
      - name: Try
        children: [Approach]
        transitions:
          - {to: Done, condition: "succeeded(Approach)"}
      - {name: Done, kind: success}
"""


def _plan_of(sim, agent):
    root = sim.engines[agent].root
    return root.slots[0].node.plan.name if root.slots and root.slots[0].node else None


def test_plan_type_takes_the_alternative_with_the_best_utility(tmp_path):
    lib = library(tmp_path, PLANS)
    # a Worker prefers Work (0.9) to Help (0.4): ByWorking although ByHelping is listed first
    sim, _ = team(lib, "Top", {"w": "Worker"}, {"Work": scripted(["running"]), "Check": scripted(["running"])})
    sim.tick()
    assert _plan_of(sim, "w") == "ByWorking"
    sim2, _ = team(lib, "Top", {"h": "Helper"}, {"Work": scripted(["running"]), "Check": scripted(["running"])})
    sim2.tick()
    assert _plan_of(sim2, "h") == "ByHelping"


def test_three_repair_stages(tmp_path):
    lib = library(tmp_path, PLANS)
    work, check = scripted(["failure"]), scripted(["failure"])
    sim, trace = team(lib, "TopAuto", {"w": "Worker"}, {"Work": work, "Check": check})
    sim.run(ticks=6)
    stages = [(e["stage"], e["plan"]) for e in trace.of("repair", key="TopAuto/Try/Approach")]
    assert stages[:4] == [
        ("retry", "ByWorking"),  # 1. the failed plan is restarted
        ("replace", "ByWorking"),  # 2. it failed again: the next-best alternative replaces it
        ("retry", "ByHelping"),  #    which gets its own retry
        ("propagate", "ByHelping"),  # 3. no alternative left: the plan type fails
    ]
    # no transition of Try handles the failed type: TopAuto fails, and its own repair starts
    assert [e["stage"] for e in trace.of("repair", key="TopAuto")][:1] == ["retry"]


def test_a_parent_that_handles_the_failure_sees_it_before_any_repair(tmp_path):
    lib = library(tmp_path, PLANS)
    work, check = scripted(["failure"]), scripted(["failure"])
    sim, trace = team(lib, "Top", {"w": "Worker"}, {"Work": work, "Check": check})
    sim.run(ticks=6)
    assert not trace.of("repair")
    assert len(work.instances) == 1 and not check.instances
    assert where(sim, "w") == ("Default", "GaveUp")


def test_replacement_succeeds(tmp_path):
    lib = library(tmp_path, PLANS)
    sim, trace = team(
        lib, "TopAuto", {"w": "Worker"}, {"Work": scripted(["failure"]), "Check": scripted(["running", "success"])}
    )
    sim.run(until_done=True, max_time=10)
    assert where(sim, "w") == ("Default", "Done")
    assert [e["stage"] for e in trace.of("repair")] == ["retry", "replace"]
