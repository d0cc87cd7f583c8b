"""Hot reload in a simulated team: the team agrees, switches at one tick, and carries its state over."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.errors import AlicaError
from alica.model.digest import library_changes, library_digest
from alica.testing import scripted
from tests.engine.helpers import library, team, where

PLANS = """
predicates: [go/0]
behaviours:
  - {name: Keep, skill: Work}
  - {name: Hold, skill: Wait}
plans:
  - name: Gate
    entry_points: [{task: Default, state: Waiting, min: 1, max: "*"}]
    states:
      - name: Waiting
        children: [Hold]
        transitions:
          - {to: Passed, condition: "go"}
      - {name: Passed, kind: success}
  - name: Top
    entry_points: [{task: Default, state: Work, min: 1, max: "*"}]
    states:
      - name: Work
        children: [Gate, Keep]
"""


def _two(tmp_path: Path, plans: str = PLANS):
    lib = library(tmp_path, plans)
    keep, hold = scripted(["running"]), scripted(["running"])
    sim, trace = team(lib, "Top", {"a": "Worker", "b": "Worker"}, {"Work": keep, "Wait": hold})
    return sim, trace, keep, hold


def _load(tmp_path: Path, folder: str, plans: str):
    """The library of ``plans`` written in a folder of its own (the same files, edited, in another place)."""
    (tmp_path / folder).mkdir(exist_ok=True)
    return library(tmp_path / folder, plans)


def _edited(tmp_path: Path, old: str, new: str, plans: str = PLANS):
    assert old in plans
    return _load(tmp_path, "edited", plans.replace(old, new))


def test_an_edited_condition_is_taken_by_both_agents_at_the_same_tick_and_the_other_branch_keeps_running(tmp_path):
    sim, trace, keep, _ = _two(tmp_path)
    sim.run(ticks=10)
    assert where(sim, "a", 1) == ("Default", "Waiting") and where(sim, "b", 1) == ("Default", "Waiting")
    assert len(keep.instances) == 2 and all(k.starts == 1 for k in keep.instances)
    new = _edited(tmp_path, '{to: Passed, condition: "go"}', '{to: Passed, condition: "true"}')
    old_digest = sim.engines["a"].reloads.digest
    sim.reload(new)
    sim.run(ticks=20)
    adopted = trace.of("reload", status="adopted")
    assert {e["agent"] for e in adopted} == {"a", "b"} and len({e["t"] for e in adopted}) == 1
    assert adopted[0]["library"] == old_digest and adopted[0]["adopted"] == library_digest(new)
    assert adopted[0]["changes"] == {"changed": ["plan Gate"]} and adopted[0]["restarted"] == []
    passed = trace.of("transition", target="Passed")
    assert {e["agent"] for e in passed} == {"a", "b"} and len({e["t"] for e in passed}) == 1
    assert passed[0]["t"] == adopted[0]["t"]  # the tick of the switch evaluates the new condition
    # Keep (the other branch) was not restarted; the world model untouched; Hold stopped with its state
    assert len(keep.instances) == 2 and all(k.starts == 1 and k.stops == 0 for k in keep.instances)
    assert all(e.library is new for e in sim.engines.values())


def test_a_second_reload_of_the_same_files_changes_nothing(tmp_path):
    sim, trace, *_ = _two(tmp_path)
    sim.run(ticks=5)
    same = _load(tmp_path, "same", PLANS)
    digest = sim.engines["a"].reload(same)
    assert digest == sim.engines["a"].reloads.digest and sim.engines["a"].reloads.proposed == ""
    sim.run(ticks=10)
    assert trace.of("reload") == []


def test_an_added_state_and_a_changed_utility_move_the_allocation(tmp_path):
    plans = """
functions: [bias/2]
behaviours:
  - {name: Keep, skill: Work}
  - {name: Help, skill: Wait}
plans:
  - name: Split
    entry_points:
      - {task: Work, state: Working, min: 0, max: 1}
      - {task: Help, state: Helping, min: 0, max: 1}
    utility: {priority_weight: 1.0, threshold: 0.05}
    states:
      - {name: Working, children: [Keep]}
      - {name: Helping, children: [Help]}
"""
    lib = library(tmp_path, plans)
    keep, help_ = scripted(["running"]), scripted(["running"])
    sim, trace = team(lib, "Split", {"w": "Worker"}, {"Work": keep, "Wait": help_})
    sim.engines["w"].own.set("bias", "w", "Help", value=1.0)  # what the world says: w is the one to help
    sim.engines["w"].own.set("bias", "w", "Work", value=0.0)
    sim.run(ticks=5)
    assert where(sim, "w") == ("Work", "Working")  # by priority alone: Worker has Work 0.9, Help 0.4
    # the edit: the utility reads the bias now (Help 0.2 * 0.4 + 0.8 * 1 against Work 0.2 * 0.9), and a new
    # state Resting follows Helping
    edited = plans.replace(
        "    utility: {priority_weight: 1.0, threshold: 0.05}",
        "    utility:\n      priority_weight: 0.2\n      threshold: 0.05\n"
        '      summands: [{name: Bias, weight: 0.8, expression: "bias(self, task)"}]',
    ).replace(
        "      - {name: Helping, children: [Help]}",
        "      - {name: Helping, children: [Help], transitions: [{to: Resting, condition: 'true'}]}\n"
        "      - {name: Resting, children: [Help]}",
    )
    new = _load(tmp_path, "v2", edited)
    assert library_changes(lib, new).changed == ("plan Split",)
    sim.reload(new)
    sim.run(ticks=15)
    assert trace.of("reload", status="adopted")
    assert trace.of("allocation", agent="w")[-1]["entries"] == {"w": "Help"}
    assert where(sim, "w") == ("Help", "Resting")


def test_a_removed_state_sends_the_agent_to_its_entry_state_with_a_note(tmp_path):
    plans = PLANS.replace(
        '          - {to: Passed, condition: "go"}',
        '          - {to: Later, condition: "true"}\n      - name: Later\n        children: [Hold]\n'
        '        transitions:\n          - {to: Passed, condition: "go"}',
    )
    sim, trace, *_ = _two(tmp_path, plans)
    sim.run(ticks=6)
    assert where(sim, "a", 1) == ("Default", "Later")
    new = _edited(  # Later is gone altogether
        tmp_path,
        '      - name: Later\n        children: [Hold]\n        transitions:\n          - {to: Passed, condition: "go"}\n',
        "",
        plans.replace('{to: Later, condition: "true"}', '{to: Passed, condition: "go"}'),
    )
    sim.reload(new)
    sim.run(ticks=15)
    assert where(sim, "a", 1) == ("Default", "Waiting")
    notes = trace.of("reload", agent="a")
    assert any("state 'Later' was removed: back to 'Waiting'" in str(e.get("note")) for e in notes)


def test_a_changed_behaviour_restarts_and_an_unchanged_one_keeps_running(tmp_path):
    sim, trace, keep, hold = _two(tmp_path)
    sim.run(ticks=5)
    new = _edited(tmp_path, "{name: Hold, skill: Wait}", "{name: Hold, skill: Wait, params: {duration: 2.0}}")
    sim.reload(new)
    sim.run(ticks=15)
    adopted = trace.of("reload", status="adopted", agent="a")[0]
    assert adopted["restarted"] == ["Top/Work/Gate/Waiting/Hold"]
    assert len(hold.instances) == 4  # two agents, each Hold started again
    assert all(k.starts == 1 and k.stops == 0 for k in keep.instances)


def test_a_library_without_the_root_plan_is_refused_and_the_team_goes_on(tmp_path):
    sim, trace, *_ = _two(tmp_path)
    sim.run(ticks=3)
    renamed = _edited(tmp_path, "  - name: Top\n", "  - name: Top2\n")
    with pytest.raises(AlicaError, match="no plan named 'Top'"):
        sim.reload(renamed)
    sim.run(ticks=5)
    assert trace.of("reload") == [] and where(sim, "a") == ("Default", "Work")


def test_an_agent_that_does_not_have_the_new_library_holds_the_team_back_and_is_named(tmp_path):
    sim, trace, *_ = _two(tmp_path)
    sim.run(ticks=5)
    new = _edited(tmp_path, '{to: Passed, condition: "go"}', '{to: Passed, condition: "true"}')
    sim.engines["a"].reload(new)  # b's files were not updated
    sim.run(ticks=30)
    assert trace.of("reload", status="adopted") == []
    assert where(sim, "a", 1) == ("Default", "Waiting") and where(sim, "b", 1) == ("Default", "Waiting")
    waiting = trace.of("reload", status="waiting", agent="a")
    assert len(waiting) == 1 and waiting[0]["differ"] == {"b": sim.engines["b"].reloads.digest}
    # b gets the files too: the team switches, both at one tick
    sim.engines["b"].reload(new)
    sim.run(ticks=20)
    adopted = trace.of("reload", status="adopted")
    assert {e["agent"] for e in adopted} == {"a", "b"} and len({e["t"] for e in adopted}) == 1


def test_a_crashed_agent_does_not_hold_the_team_back(tmp_path):
    sim, trace, *_ = _two(tmp_path)
    sim.run(ticks=5)
    sim.crash("b")
    sim.run(ticks=10)  # b is taken out after the team timeout
    new = _edited(tmp_path, '{to: Passed, condition: "go"}', '{to: Passed, condition: "true"}')
    sim.reload(new)
    sim.run(ticks=15)
    assert [e["agent"] for e in trace.of("reload", status="adopted")] == ["a"]


def test_a_lost_announcement_is_repeated_and_the_late_agent_switches_when_it_hears_it(tmp_path):
    lib = library(tmp_path, PLANS)
    skills = {"Work": scripted(["running"]), "Wait": scripted(["running"])}
    sim, trace = team(lib, "Top", {"a": "Worker", "b": "Worker"}, skills, loss=0.5, seed=3)
    sim.run(ticks=10)
    new = _edited(tmp_path, '{to: Passed, condition: "go"}', '{to: Passed, condition: "true"}')
    sim.reload(new)
    sim.run(ticks=60)
    assert {e["agent"] for e in trace.of("reload", status="adopted")} == {"a", "b"}
    assert where(sim, "a", 1) == ("Default", "Passed") and where(sim, "b", 1) == ("Default", "Passed")


def _with(library, **changes):
    """``library`` with its first document's sections changed (an edit of the shipped files, in memory)."""
    from dataclasses import replace

    from alica.model import PlanLibrary

    documents = list(library.documents)
    index = next(i for i, d in enumerate(documents) if any(getattr(d, k) for k in changes))
    documents[index] = replace(documents[index], **{k: f(getattr(documents[index], k)) for k, f in changes.items()})
    return PlanLibrary(tuple(documents))


def test_a_generated_plan_stays_valid_when_its_problem_is_unchanged_and_is_made_again_when_it_changed():
    from dataclasses import replace

    from alica.model import Behaviour
    from tests.prophet.blocks_team import BlockSkills, blocks_team, child_plan, events, goal_holds, run_until

    skills = BlockSkills(ticks=6)
    sim, rec = blocks_team(["r1", "r2"], skills, planner_expansions=1)
    sim.tick()
    run_until(sim, lambda: all((child_plan(sim, a) or "").startswith("StackBlocks_g1v") for a in ("r1", "r2")))
    generated = child_plan(sim, "r1")
    # an unrelated edit: a behaviour added; the running generated plan goes on
    sim.reload(_with(sim.library, behaviours=lambda b: (*b, Behaviour("Wave", "Idle"))))
    run_until(sim, lambda: len(events(rec, "reload", status="adopted")) == 2)
    assert child_plan(sim, "r1") == generated and child_plan(sim, "r2") == generated
    assert len(events(rec, "planner", what="started")) == 1 and events(rec, "replan") == []
    # the problem changed (its replanning period): its runtime starts again, the leader plans anew
    sim.reload(_with(sim.library, problems=lambda ps: tuple(replace(p, update_time=p.update_time + 1) for p in ps)))
    run_until(sim, lambda: len(events(rec, "reload", status="adopted")) == 4)
    adopted = events(rec, "reload", status="adopted", agent="r1")[-1]
    assert adopted["changes"] == {"changed": ["problem StackBlocks"]}
    assert adopted["restarted"] == ["BlocksWorldMission/Stacking/StackBlocks"]
    summary = sim.run(until_done=True, max_time=120)
    assert len(events(rec, "planner", what="started")) == 2
    assert summary["success"] and goal_holds(sim, "r1")
