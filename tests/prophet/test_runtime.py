"""The runtime of planning problems (IMPERA 7.1-7.2) in simulated time, with scripted skills.

The blocks-world team runs the shipped BlocksWorldMission: its state Stacking
holds the planning problem StackBlocks (WaitPlan DriveToFreePosition, no
AlternativePlan). The skills are scripted: each runs a few ticks and then
changes the world model as the IPC blocks domain says.
"""

from __future__ import annotations

import pytest

from alica.prophet import engine_config
from alica.prophet.planners import PLANNERS
from alica.testing import scripted
from tests.engine.helpers import library, team, where
from tests.prophet.blocks_team import SUSSMAN, BlockSkills, blocks_team, child_plan, events, goal_holds, run_until

KEY = "BlocksWorldMission/Stacking/StackBlocks"


def test_wait_plan_while_planning_then_the_team_switches_to_the_first_plan():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, planner_expansions=1)
    sim.tick()
    assert [child_plan(sim, a) for a in ("r1", "r2")] == ["DriveToFreePosition"] * 2
    started = events(rec, "planner", what="started")
    assert [e["agent"] for e in started] == ["r1"]  # the lowest id leads
    run_until(sim, lambda: all((child_plan(sim, a) or "").startswith("StackBlocks_g1v") for a in ("r1", "r2")))
    first = events(rec, "planner", what="plan")[0]
    assert first["agent"] == "r1" and first["steps"] == 6
    adopted = events(rec, "problem", phase="plan")
    assert {e["agent"] for e in adopted} == {"r1", "r2"}
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and goal_holds(sim, "r1") and goal_holds(sim, "r2")
    # the plan was spread: both robots manipulated blocks
    manipulators = {agent for agent, skill, _ in skills.runs if skill in ("Pickup", "Unstack", "Stack", "Putdown")}
    assert manipulators == {"r1", "r2"}
    assert events(rec, "replan") == []


def test_agents_no_task_needs_stand_by_in_the_wait_plan():
    # the Sussman anomaly makes three tasks: two of five robots have none and keep out of the way
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2", "r3", "r4", "r5"], skills)
    sim.tick()
    run_until(sim, lambda: all((child_plan(sim, a) or "").startswith("StackBlocks_g1v") for a in sim.engines))
    allocation = next(e for e in events(rec, "allocation", agent="r1") if e["plan"].startswith("StackBlocks_g1v"))
    standing_by = sorted(a for a, entry in allocation["entries"].items() if entry == "Standby")
    working = sorted(a for a, entry in allocation["entries"].items() if entry not in ("Standby", None))
    assert len(standing_by) == 2 and len(working) == 3
    # they run the WaitPlan inside the generated plan's Standby state
    waiting = {
        e["agent"]
        for e in events(rec, "allocation", plan="DriveToFreePosition")
        if e["key"].endswith("/Standby/DriveToFreePosition")
    }
    assert waiting == set(standing_by)
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and goal_holds(sim, "r1")
    manipulators = {agent for agent, skill, _ in skills.runs if skill in ("Pickup", "Unstack", "Stack", "Putdown")}
    assert manipulators == set(working)


def test_one_robot_runs_every_task_in_turn():
    skills = BlockSkills()
    sim, _ = blocks_team(["r1"], skills)
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and goal_holds(sim, "r1")
    assert [s for _, s, _ in skills.runs if s in ("Pickup", "Unstack", "Stack", "Putdown")] == [
        "Unstack",
        "Putdown",
        "Pickup",
        "Stack",
        "Pickup",
        "Stack",
    ]


def test_a_failed_step_sends_the_team_back_to_the_wait_plan_and_the_leader_replans():
    skills = BlockSkills(fail=["Pickup"])
    sim, rec = blocks_team(["r1", "r2"], skills)
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and goal_holds(sim, "r1")
    replans = events(rec, "replan")
    assert replans and all(e["agent"] == "r1" for e in replans)
    assert "failed" in replans[0]["reason"]
    # after the failure every agent ran the WaitPlan of generation 2, then its plan
    for agent in ("r1", "r2"):
        assert events(rec, "problem", agent=agent, phase="wait", generation=2)
        assert events(rec, "problem", agent=agent, phase="plan", generation=2)
    assert summary["agents"]["r1"]["replans"] >= 1


def test_a_non_leader_step_failure_is_reported_to_the_leader():
    skills = BlockSkills(fail=["Pickup"])
    sim, rec = blocks_team(["r1", "r2"], skills)
    sim.run(until_done=True, max_time=60)
    failed_by = next(agent for agent, skill, _ in skills.runs if skill == "Pickup")
    replan = events(rec, "replan")[0]
    if failed_by != "r1":
        assert replan["reason"].startswith(f"{failed_by}: ")


def test_the_world_changing_under_the_plan_makes_the_leader_replan():
    skills = BlockSkills(ticks=6)
    stacks = [*SUSSMAN, ["d"]]
    sim, rec = blocks_team(["r1"], skills, stacks=stacks)  # one robot: it unstacks c before it picks b up
    run_until(sim, lambda: events(rec, "problem", agent="r1", phase="plan"))
    # an opponent puts d on b before anyone picked b up: Pickup(b) cannot run any more
    sim.set_facts([(False, "ontable", ("d",)), (False, "clear", ("b",)), (True, "on", ("d", "b"))])
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    replans = events(rec, "replan")
    assert replans and "the world changed under the plan" in replans[0]["reason"]
    assert "Pickup(b)" in replans[0]["reason"] or "Unstack" in replans[0]["reason"]


def test_the_leader_crashes_while_planning_and_the_next_lowest_id_takes_over():
    skills = BlockSkills()
    # a budget of one progress event per tick keeps the first planning in flight for a few ticks
    sim, rec = blocks_team(["r1", "r2", "r3"], skills, stacks=[["a", "b", "c", "d", "e", "f"]], planner_expansions=1)
    sim.tick()
    assert events(rec, "planner", agent="r1", what="started")
    sim.crash("r1")
    summary = sim.run(until_done=True, max_time=90)
    takeover = events(rec, "planner", agent="r2", what="started")
    assert takeover and takeover[0]["reason"] == "taking over from r1"
    assert events(rec, "planner", agent="r3", what="started") == []
    assert summary["agents"]["r2"]["status"] == "success" and summary["agents"]["r3"]["status"] == "success"
    assert goal_holds(sim, "r2")


def test_the_leader_crashes_during_execution_and_the_team_still_reaches_the_goal():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2", "r3"], skills)
    run_until(sim, lambda: any(a == "r1" and s in ("Unstack", "Pickup") for a, s, _ in skills.runs))
    sim.crash("r1")
    summary = sim.run(until_done=True, max_time=90)
    assert summary["agents"]["r2"]["status"] == "success" and summary["agents"]["r3"]["status"] == "success"
    assert goal_holds(sim, "r2")
    # r1 held a block when it crashed or had just started: either the team replanned around it, or its task was taken over
    assert events(rec, "replan") or any(a != "r1" for a, s, _ in skills.runs if s == "Stack")


def test_the_same_seed_gives_the_same_trace():
    def trace():
        sim, rec = blocks_team(["r1", "r2", "r3"], BlockSkills(fail=["Stack"]), seed=7)
        sim.run(until_done=True, max_time=60)
        return list(rec.events)

    assert trace() == trace()


def test_the_operator_sets_a_new_goal_and_the_leader_replans():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills)
    run_until(sim, lambda: events(rec, "problem", agent="r2", phase="plan"))
    for engine in sim.engines.values():
        engine.set_problem("StackBlocks", goal="on(c, b) and on(b, a) and ontable(a)")
    summary = sim.run(until_done=True, max_time=90)
    assert events(rec, "replan", reason="the operator changed the planning problem")
    world = sim.engines["r1"].world_model
    assert summary["success"] and world.holds("on", "c", "b") and world.holds("on", "b", "a")


# -- planner failure and timeout: the AlternativePlan -------------------------------

PROBLEM = """
predicates: [done/0, ready/0]
behaviours:
  - {name: Hold, skill: Wait}
  - {name: GoHome, skill: Work}
plans:
  - name: Step
    signature: {parameters: [], precondition: "ready and not done", effect: "done"}
    entry_points: [{task: Work, state: Stepping, min: 1, max: 1}]
    states:
      - {name: Stepping, children: [Hold], transitions: [{to: Stepped, condition: succeeded}]}
      - {name: Stepped, kind: success}
  - name: Park
    entry_points: [{task: Watch, state: Parked, min: 1, max: "*"}]
    states:
      - {name: Parked, children: [Hold]}
  - name: Home
    entry_points: [{task: Help, state: Going, min: 1, max: "*"}]
    states:
      - {name: Going, children: [GoHome], transitions: [{to: There, condition: succeeded}]}
      - {name: There, kind: success}
  - name: Top
    entry_points: [{task: Default, state: Solve, min: 1, max: "*"}]
    states:
      - name: Solve
        children: [Solve]
        transitions:
          - {to: Done, condition: "succeeded(Solve)"}
          - {to: GaveUp, condition: "failed(Solve)"}
      - {name: Done, kind: success}
      - {name: GaveUp, kind: success}
problems:
  - name: Solve
    elements: [Step]
    wait_plan: Park
    ALTERNATIVE
    timeout: 2
    planner: PLANNER
    goal: "done"
"""


def problem_team(tmp_path, planner="builtin", alternative=True):
    text = PROBLEM.replace("PLANNER", planner).replace("ALTERNATIVE", "alternative_plan: Home" if alternative else "")
    lib = library(tmp_path, text)
    config = engine_config(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3)
    return team(
        lib,
        "Top",
        {"w": "Worker", "h": "Helper"},
        {"Wait": scripted(["running"]), "Work": scripted(["running", "success"])},
        config=config,
    )


def test_an_unsolvable_problem_runs_the_alternative_plan(tmp_path):
    sim, rec = problem_team(tmp_path)
    sim.run(ticks=3)  # the leader h plans in tick 2, w hears of it in tick 3
    failed = events(rec, "problem", phase="alternative")
    assert {e["agent"] for e in failed} == {"w", "h"}
    assert "unsolvable" in failed[0]["reason"]
    sim.run(ticks=5)
    assert events(rec, "allocation", plan="Home")
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"] and where(sim, "w") == ("Default", "Done")  # the AlternativePlan's outcome is the child's


def test_a_planner_timeout_runs_the_alternative_plan(tmp_path, monkeypatch):
    monkeypatch.setitem(PLANNERS, "stall", "tests.prophet.blocks_team:StallingPlanner")
    sim, rec = problem_team(tmp_path, planner="stall")
    sim.run(ticks=15)
    assert events(rec, "problem", phase="alternative") == []  # still planning within the 2 s timeout
    assert child_plan(sim, "w") == "Park"
    sim.run(ticks=10)
    timeout = events(rec, "problem", agent="h", phase="alternative")
    assert timeout and "timeout of 2 s" in timeout[0]["reason"]
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"]


def test_without_an_alternative_plan_a_planning_failure_fails_the_child(tmp_path):
    sim, rec = problem_team(tmp_path, alternative=False)
    summary = sim.run(until_done=True, max_time=10)
    assert summary["success"] and where(sim, "w") == ("Default", "GaveUp")
    assert events(rec, "problem", phase="failed")


def test_without_an_alternative_plan_an_unsolvable_problem_waits_while_robots_outside_the_team_may_change_the_world():
    # c is seen on nothing and a is not clear, with nothing the planner knows on it (c lies across two blocks,
    # say): unsolvable now, but an opponent is around and may move things
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills)
    sim.set_facts([(True, "handempty", ("o1",)), (False, "on", ("c", "a"))])
    sim.run(ticks=40)
    waiting = events(rec, "planner", what="waiting")
    assert waiting and "robots outside the team (o1) may change the world" in waiting[0]["reason"]
    assert events(rec, "problem", phase="failed") == []
    sim.set_facts([(True, "clear", ("a",)), (True, "on", ("c", "a"))])  # the world changes: solvable again
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")


def test_a_goal_that_holds_already_succeeds_at_once(tmp_path):
    sim, rec = problem_team(tmp_path)
    sim.set_facts([(True, "done", ())])
    summary = sim.run(until_done=True, max_time=5)
    assert summary["success"] and where(sim, "w") == ("Default", "Done")
    assert events(rec, "problem", phase="done")
    assert events(rec, "allocation", plan="Home") == []


@pytest.mark.parametrize("planner", ["nonesuch"])
def test_an_unknown_planner_is_a_planning_failure_with_its_reason(tmp_path, planner):
    sim, rec = problem_team(tmp_path, planner=planner)
    sim.run(ticks=2)
    failed = events(rec, "problem", phase="alternative")
    assert failed and "unknown planner 'nonesuch'" in failed[0]["reason"]


def test_a_robot_holding_a_block_at_a_replan_is_part_of_the_new_plan():
    skills = BlockSkills(fail=["Stack"])
    sim, rec = blocks_team(["r1", "r2", "r3"], skills, seed=7)
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and goal_holds(sim, "r1")
    stacks = [(agent, params["object"]) for agent, skill, params in skills.runs if skill == "Stack"]
    failed_agent, block = stacks[0]
    # the robot whose Stack failed still holds its block: the new plan has it stack that block (a pinned task)
    assert (failed_agent, block) in stacks[1:]
    replanned = events(rec, "planner", what="plan", generation=2)
    assert replanned and replanned[0]["steps"] < 6


def test_a_block_held_by_a_robot_outside_the_team_the_team_does_the_rest_then_waits():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, stacks=[["a", "c"], ["d", "e"]])
    for agent in ("r1", "r2"):
        sim.engines[agent].set_problem("StackBlocks", goal="on(a, b) and on(b, c) and ontable(c) and ontable(e)")
    sim.set_facts([(True, "holding", ("o1", "b"))])  # an opponent holds b: it is missing from the team's world
    sim.run(ticks=60)
    # the leader plans for the part of the goal not tied to b (e on the table), then waits for b; a on b on c
    # is left out as a whole: c on the table would only be a base for b, whose place is not known yet
    started = events(rec, "planner", what="started")[0]
    assert started["goal"] == "ontable(e)" and started["outside"] == ["b"]
    assert sim.engines["r1"].world_model.holds("ontable", "e")
    assert sim.engines["r1"].world_model.holds("on", "c", "a")
    assert any(
        "robots outside the team hold, or nobody sees, b" in e["reason"] for e in events(rec, "planner", what="waiting")
    )
    assert events(rec, "problem", phase="failed") == []
    # while the team waits, its WaitPlan guards the part of the goal that holds (e on the table)
    waits = [params for _, skill, params in skills.runs if skill == "WaitAside"]
    assert waits[-1].get("guard") == "e"
    sim.set_facts(
        [(False, "holding", ("o1", "b")), (True, "ontable", ("b",)), (True, "clear", ("b",))]
    )  # it puts b down
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    assert events(rec, "planner", what="started", reason="the world changed while planning was blocked")


def test_a_goal_block_nobody_sees_is_left_out_of_the_plan_not_a_failure():
    # b falls: for a moment no fact mentions it; the team plans for the rest instead of failing the problem
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, stacks=[["a", "c"], ["b"]])
    sim.set_facts([(False, "ontable", ("b",)), (False, "clear", ("b",))])
    sim.run(ticks=60)
    # every goal literal is tied to b (a on b on c): the team waits for b instead of planning
    waiting = events(rec, "planner", what="waiting")
    assert waiting and "nobody sees, b" in waiting[0]["reason"]
    assert events(rec, "problem", phase="failed") == []
    sim.set_facts([(True, "ontable", ("b",)), (True, "clear", ("b",))])  # it is seen again
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")


def test_a_plan_for_part_of_the_goal_runs_to_its_end_then_the_rest_is_planned():
    # b is free before the team finished the rest of the goal: the plan goes on, then the leader plans for the whole goal
    skills = BlockSkills(ticks=8)
    sim, rec = blocks_team(["r1", "r2"], skills, stacks=[["a", "c"], ["d", "e"]])
    for agent in ("r1", "r2"):
        sim.engines[agent].set_problem("StackBlocks", goal="on(a, b) and on(b, c) and ontable(c) and ontable(e)")
    sim.set_facts([(True, "holding", ("o1", "b"))])
    run_until(sim, lambda: events(rec, "problem", agent="r2", phase="plan"))
    sim.set_facts([(False, "holding", ("o1", "b")), (True, "ontable", ("b",)), (True, "clear", ("b",))])
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    replans = events(rec, "replan")
    assert len(replans) == 1 and "the plan is done, but the goal does not hold" in replans[0]["reason"]
    # the first plan (e onto the table) was not cut short
    first = [(a, s, p["object"]) for a, s, p in skills.runs if s in ("Unstack", "Putdown")][:2]
    assert [(s, o) for _, s, o in first] == [("Unstack", "e"), ("Putdown", "e")]


def test_a_goal_block_taken_by_an_opponent_does_not_stop_the_rest_of_the_plan():
    # the opponent picks up d, which only the goal names (on the table): the steps on a, b and c go on
    skills = BlockSkills(ticks=8)
    sim, rec = blocks_team(["r1", "r2"], skills, stacks=[*SUSSMAN, ["d"]])
    sim.engines["r1"].set_problem("StackBlocks", goal="on(a, b) and on(b, c) and ontable(c) and ontable(d)")
    sim.engines["r2"].set_problem("StackBlocks", goal="on(a, b) and on(b, c) and ontable(c) and ontable(d)")
    run_until(sim, lambda: events(rec, "problem", agent="r2", phase="plan"))
    sim.set_facts([(False, "ontable", ("d",)), (False, "clear", ("d",)), (True, "holding", ("o1", "d"))])
    sim.run(ticks=150)
    assert goal_holds(sim, "r1")
    assert events(rec, "replan") == []
    sim.set_facts([(True, "ontable", ("d",)), (True, "clear", ("d",)), (False, "holding", ("o1", "d"))])
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"]


def test_a_free_task_is_not_stuck_while_an_agent_that_may_take_it_finishes_an_earlier_one():
    from alica.prophet.runtime import _stalled
    from alica.prophet.world import TaskProgress

    # T0 and T1 at work, T2 free, T3's agent waits for T2 (the plan: T0 step 0, T1 steps 1 and 2, T2 step 3, T3 step 4)
    order = [[0], [1, 2], [3], [4]]
    progress = [
        TaskProgress("r1", 0, running=True),
        TaskProgress("r2", 1, running=True),
        TaskProgress(None, 0),
        TaskProgress("r4", 0),
    ]
    members = ("r1", "r2", "r4")
    assert _stalled(progress, order, (None, None, ("r1", "r2"), ("r4",)), members) is None  # r1 or r2 takes T2 next
    # only r4 may take T2, and it waits in T3: stuck
    assert "task T2 has nobody" in _stalled(progress, order, (None, None, ("r4",), ("r4",)), members)
    # the agents that may take it crashed (not members any more): stuck
    assert "task T2 has nobody" in _stalled(progress, order, (None, None, ("r1", "r2"), ("r4",)), ("r4",))


def test_a_free_task_pinned_to_a_crashed_agent_is_stuck_when_nobody_waits_for_it():
    from alica.prophet.runtime import _stalled
    from alica.prophet.world import TaskProgress

    # seed 13, the leader r1 crashed at 25 s holding d: T3 = Stack(d, e) is pinned to r1; T0-T2 are done, so
    # nobody waits for T3, and the team idled until its time limit instead of planning again
    order = [[0, 1, 2], [3], [4, 5], [6]]
    done = [TaskProgress(None, len(steps), done=True) for steps in order[:3]]
    progress = [*done, TaskProgress(None, 0)]
    members = ("r2", "r3")
    allowed = (("r3",), ("r2",), None, ("r1",))
    reason = _stalled(progress, order, allowed, members)
    assert reason is not None and reason.startswith("task T3 has nobody, and only r1 may start it")
    # r1 back in the team: it takes T3 by the engine's reuse rule, nothing is stuck
    assert _stalled(progress, order, allowed, ("r1", "r2", "r3")) is None
    # a free task anyone may take is not stuck either: the reuse rule gives it to a free agent
    assert _stalled(progress, order, (("r3",), ("r2",), None, None), members) is None


def test_a_free_task_pinned_to_an_agent_that_waits_for_it_in_an_earlier_task_is_stuck():
    from alica.prophet.runtime import _stalled
    from alica.prophet.world import TaskProgress

    # seed 10 of the 5-agent demo: T1 = Unstack(d, g) (step 1) and Stack(d, g) (step 4); T2 = Pickup(g), Stack(g, h)
    # (steps 2, 3), pinned to r5. r5 took T1 and waits before step 4, which comes after T2: nobody will ever take T2
    order = [[0], [1, 4], [2, 3], [5]]
    progress = [TaskProgress(None, 1, done=True), TaskProgress("r5", 1), TaskProgress(None, 0), TaskProgress("r3", 0)]
    members = ("r1", "r3", "r5")
    assert "task T2 has nobody, and the agent of task T3 waits for it" in _stalled(
        progress, order, (None, ("r1", "r5"), ("r5",), ("r3",)), members
    )
    # r3 may take it as well, and runs its step now: it takes T2 when that step is done
    at_work = [*progress[:3], TaskProgress("r3", 0, running=True)]
    assert _stalled(at_work, order, (None, ("r1", "r5"), ("r3", "r5"), ("r3",)), members) is None
    # r5 still before step 1 (it comes before T2): it finishes that step and T1 waits for T2 only then
    before = [TaskProgress(None, 1, done=True), TaskProgress("r5", 0), TaskProgress(None, 0), TaskProgress("r3", 0)]
    assert _stalled(before, order, (None, ("r1", "r5"), ("r5",), ("r3",)), members) is None


def test_a_planner_that_fails_inside_its_search_fails_the_problem_with_the_reason(monkeypatch):
    # grounding runs lazily inside the search: an error there is a failed planning, not a crash of the engine
    import alica.prophet.runtime as runtime
    from alica.errors import PlannerError

    class Broken:
        def __init__(self, *args, **kwargs):
            pass

        def search(self, anytime=True):
            yield from ()  # a generator: the error comes on the first step, as grounding's does
            raise PlannerError("object 'f_0_0' has type 'frontier', which domain 'x' does not declare")

    monkeypatch.setattr(runtime, "plan_problem", Broken)
    skills = BlockSkills()
    sim, rec = blocks_team(["r1"], skills)
    sim.run(ticks=40)
    failed = events(rec, "planner", what="failed")
    assert failed and "does not declare" in failed[0]["reason"]


def test_a_step_that_fails_the_same_way_in_the_same_world_gives_up_with_the_alternative_plan(tmp_path):
    # an unreachable sample: the same plan would be made and fail again for ever; after GIVE_UP_AFTER tries
    # in an unchanged world the problem fails and the team runs the AlternativePlan
    from alica.prophet.giving_up import failure_cause
    from alica.prophet.runtime import GIVE_UP_AFTER

    text = PROBLEM.replace("PLANNER", "builtin").replace("ALTERNATIVE", "alternative_plan: Home")
    text = text.replace(
        "  - {name: GoHome, skill: Work}", "  - {name: GoHome, skill: Work}\n  - {name: Attempt, skill: Check}"
    )
    text = text.replace(
        "      - {name: Stepping, children: [Hold], transitions: [{to: Stepped, condition: succeeded}]}",
        "      - name: Stepping\n        children: [Attempt]\n"
        "        transitions: [{to: Stepped, condition: succeeded}, {to: Broken, condition: failed}]\n"
        "      - {name: Broken, kind: failure}",
    )
    lib = library(tmp_path, text)
    config = engine_config(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3)
    skills = {
        "Wait": scripted(["running"]),
        "Work": scripted(["running", "success"]),
        "Check": scripted(["running", "failure"]),
    }
    sim, rec = team(lib, "Top", {"w": "Worker", "h": "Helper"}, skills, config=config)
    sim.set_facts([(True, "ready", ())])
    summary = sim.run(until_done=True, max_time=60)
    replans = events(rec, "replan")
    assert len({failure_cause(e["reason"]) for e in replans}) == 1 and len(replans) >= GIVE_UP_AFTER
    failed = events(rec, "problem", phase="alternative")
    assert failed and f"the same step failed {GIVE_UP_AFTER} times" in failed[-1]["reason"]
    assert summary["success"] and events(rec, "allocation", plan="Home")


def test_a_robot_whose_step_failed_is_kept_off_that_step_and_another_robot_does_it():
    # r1 cannot unstack (boxed in, say): every Unstack it runs fails. Kept off the step, another robot with
    # a free hand does it (r2 picks b up at once: the task that can start first)
    skills = BlockSkills(broken=[("r1", "Unstack")])
    sim, rec = blocks_team(["r1", "r2", "r3"], skills)
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"] and goal_holds(sim, "r2")
    unstacks = [agent for agent, skill, _ in skills.runs if skill == "Unstack"]
    assert unstacks.count("r1") <= 1 and unstacks[-1] != "r1"  # at most the failure itself
    replans = events(rec, "replan")
    assert len(replans) == unstacks.count("r1")
