"""Conflicting views that keep flipping an allocation are settled by authority: the lowest id wins."""

from __future__ import annotations

from alica.testing import scripted
from tests.engine.helpers import library, team, where

PLANS = """
functions: [bias/2]
behaviours:
  - {name: DoWork, skill: Work}
plans:
  - name: Contest
    utility:
      priority_weight: 0.5
      summands: [{name: Bias, weight: 0.5, expression: "bias(self, task)"}]
      threshold: 0.05
    entry_points:
      - {task: Work, state: Working, min: 0, max: 1}
      - {task: Help, state: Helping, min: 0, max: 1}
    states:
      - {name: Working, children: [DoWork]}
      - {name: Helping, children: [DoWork]}
"""


def _disagree(sim):
    """Each agent believes it is the better one for Work: their views differ for good."""
    for me, other in (("a", "b"), ("b", "a")):
        own = sim.engines[me].own
        own.set("bias", me, "Work", value=1.0)
        own.set("bias", other, "Work", value=0.0)
        for agent in (me, other):
            own.set("bias", agent, "Help", value=0.0)


def test_flipping_allocation_is_settled_by_the_lowest_id(tmp_path):
    lib = library(tmp_path, PLANS)
    sim, trace = team(lib, "Contest", {"a": "Worker", "b": "Worker"}, {"Work": scripted(["running"])})
    _disagree(sim)
    sim.run(ticks=1)
    assert where(sim, "a") == ("Work", "Working") and where(sim, "b") == ("Work", "Working")
    sim.run(ticks=150)
    grants = trace.of("authority")
    assert grants and {g["agent"] for g in grants} == {"a"}
    assert trace.of("allocation", agent="b", reason="authority", by="a")
    # settled: a works, b helps, and both agree
    assert where(sim, "a") == ("Work", "Working")
    assert where(sim, "b") == ("Help", "Helping")
    views = {name: {k: v[0] for k, v in e.root.believed.items()} for name, e in sim.engines.items()}
    assert views["a"] == views["b"] == {"a": "Work", "b": "Help"}


def test_authority_window_grows_on_repeated_conflicts(tmp_path):
    lib = library(tmp_path, PLANS)
    sim, trace = team(lib, "Contest", {"a": "Worker", "b": "Worker"}, {"Work": scripted(["running"])})
    _disagree(sim)
    sim.run(ticks=600)
    windows = [g["window"] for g in trace.of("authority")]
    assert len(windows) >= 2
    assert windows == sorted(windows) and windows[-1] > windows[0]
