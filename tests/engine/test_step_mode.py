"""One agent's engine used directly in step mode, a skill that is a whole py_trees subtree, and team agreement."""

from __future__ import annotations

import py_trees
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.clock import ManualClock
from alica.comm import SimNetwork
from alica.engine import AgentEngine, EngineConfig, SimulatedTeam, SkillBinder
from alica.io import load_library
from alica.testing import ScriptedSkill, default_fallback
from alica.worldmodel import WorldModel
from tests.conftest import PLANS
from tests.engine.helpers import library

JOB = """
behaviours:
  - {name: DoWork, skill: Work}
plans:
  - name: Job
    entry_points: [{task: Work, state: Start, min: 1, max: 1, success_required: true}]
    states:
      - name: Start
        children: [DoWork]
        transitions:
          - {to: Finish, condition: "succeeded"}
      - {name: Finish, kind: success}
"""


def subtree(name, params, context):
    """A skill made of two steps: a py_trees sequence."""
    return py_trees.composites.Sequence(
        name,
        memory=True,
        children=[ScriptedSkill("approach", ["running", "success"]), ScriptedSkill("grasp", ["success"])],
    )


def test_an_agent_engine_in_step_mode_with_a_subtree_skill(tmp_path):
    lib = library(tmp_path, JOB)
    clock = ManualClock()
    network = SimNetwork(clock, seed=0)
    engine = AgentEngine(
        "w",
        {"w": "Worker"},
        lib,
        "Job",
        lib.rolesets["Crew"],
        network.attach("w"),
        WorldModel("w"),
        clock,
        config=EngineConfig(frequency=10),
        skills=SkillBinder({"Work": subtree}),
    )
    states = []
    for _ in range(5):
        engine.tick()
        states.append(engine.root.state)
        clock.advance(0.1)
    # sequence: approach runs, then approach succeeds and grasp succeeds in the same tick, then the transition
    assert states == ["Start", "Start", "Finish", "Finish", "Finish"]
    assert engine.done and clock.now() == 0.5


@settings(max_examples=12)
@given(
    seed=st.integers(0, 10_000),
    crash=st.sampled_from(["scout", "stummel", "amparo", None]),
    at=st.floats(0.2, 3.0),
    loss=st.sampled_from([0.0, 0.2]),
)
def test_survivors_agree_on_the_assignment(seed, crash, at, loss):
    lunar = load_library(PLANS / "lunar" / "mission.yaml")
    team = SimulatedTeam(
        lunar,
        "LunarMission",
        {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"},
        seed=seed,
        loss=loss,
        delay=0.02,
        jitter=0.02,
        fallback=default_fallback(seed, 5.0, 10.0),
        config=EngineConfig(frequency=10, team_timeout=0.6),
    )
    if crash:
        team.crash(crash, at=at)
    team.run(ticks=50)
    alive = [n for n in team.engines if n not in team.crashed]
    views = {n: {a: e[0] for a, e in team.engines[n].root.believed.items()} for n in alive}
    first = views[alive[0]]
    assert all(v == first for v in views.values()), views
    assert set(first) == set(alive)
    # every survivor's own entry point is what the others believe it is
    for n in alive:
        assert team.engines[n].root.ep == first[n]
