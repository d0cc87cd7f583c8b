"""The operator reviews the leader's plan before the team runs it (IMPERA: accept, decline or modify), in simulated time."""

from __future__ import annotations

import pytest

from alica.engine import PlanDecision
from alica.errors import AlicaError
from alica.prophet import made_plans
from alica.prophet.review import describe_proposal
from tests.prophet.blocks_team import BlockSkills, blocks_team, child_plan, events, goal_holds, run_until

PROBLEM = "StackBlocks"
WORK = ("Pickup", "Unstack", "Stack", "Putdown")
TABLE = [["a"], ["b"], ["c"], ["d"]]
"""Four blocks on the table; with the goal below one robot stacks c on d, then a on b (two independent tasks)."""
TWO_PAIRS = "on(a, b) and on(c, d)"


def proposals(recorder, **match):
    return events(recorder, "proposal", **match)


def wait_for_proposal(sim, recorder, count=1, **match):
    run_until(sim, lambda: len(proposals(recorder, **match)) >= count)
    return proposals(recorder, **match)[count - 1]


def work(skills):
    return [(agent, skill, params) for agent, skill, params in skills.runs if skill in WORK]


def team_on_table(skills, agents=("r1",)):
    sim, rec = blocks_team(list(agents), skills, stacks=TABLE, review=True)
    sim.set_goal(PROBLEM, TWO_PAIRS)
    return sim, rec


def test_with_review_on_nothing_runs_before_the_operator_accepts_then_the_team_runs_the_plan():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, review=True, planner="builtin")  # the cost counts the steps
    proposal = wait_for_proposal(sim, rec)
    assert proposal["agent"] == "r1" and proposal["leader"] == "r1"
    assert proposal["problem"] == PROBLEM and proposal["generation"] == 1 and proposal["cost"] == 6
    assert proposal["goal"] == "on(a, b) and on(b, c) and ontable(c)"
    assert len(proposal["steps"]) == 6 and proposal["steps"][0].startswith("(unstack")
    # every step is in exactly one task; each task says its entry point, steps and pins
    assert sorted(i for task in proposal["tasks"] for i in task["steps"]) == list(range(6))
    assert all({"entry_point", "steps", "labels", "robots"} <= set(task) for task in proposal["tasks"])
    assert "error" not in proposal
    for _ in range(50):  # the operator takes its time: the team waits
        sim.tick()
    assert work(skills) == []
    assert [child_plan(sim, a) for a in ("r1", "r2")] == ["DriveToFreePosition"] * 2
    assert events(rec, "problem", phase="plan") == [] and events(rec, "planner", what="plan") == []
    assert len(proposals(rec)) == 1  # proposed once, planned no further
    sim.decide_plan(PROBLEM, 1, PlanDecision("accept"))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    shared = made_plans(sim.engines["r2"])[-1][2]
    assert [step.index for task in shared.tasks for step in task] == [i for t in proposal["tasks"] for i in t["steps"]]
    assert events(rec, "replan") == []


def test_a_declined_plan_is_planned_again_and_the_new_generation_is_proposed():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, review=True)
    wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("decline"))
    second = wait_for_proposal(sim, rec, generation=2)
    assert second["leader"] == "r1" and "error" not in second
    replan = events(rec, "replan")
    assert len(replan) == 1 and "declined" in replan[0]["reason"]
    assert work(skills) == []
    sim.decide_plan(PROBLEM, 2, PlanDecision("accept"))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    assert {e["generation"] for e in events(rec, "problem", phase="plan")} == {2}


def test_a_valid_reorder_runs_the_steps_in_the_new_order():
    skills = BlockSkills()
    sim, rec = team_on_table(skills)
    proposal = wait_for_proposal(sim, rec)
    steps = proposal["steps"]
    assert [s.split()[0] for s in steps] == ["(pickup", "(stack", "(pickup", "(stack"]
    first, second = steps[0].split()[2].rstrip(")"), steps[2].split()[2].rstrip(")")
    assert {first, second} == {"a", "c"}
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", order=(2, 3, 0, 1)))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"]
    world = sim.engines["r1"].world_model
    assert world.holds("on", "a", "b") and world.holds("on", "c", "d")
    picked = [params["object"] for _, skill, params in work(skills) if skill == "Pickup"]
    assert picked == [second, first]  # the operator's order, not the planner's
    shared = events(rec, "planner", what="plan")
    assert len(shared) == 1 and shared[0]["steps"] == 4


def test_dropping_a_needed_step_is_refused_with_the_validators_reason_then_accept_runs_the_plan():
    skills = BlockSkills()
    sim, rec = team_on_table(skills)
    proposal = wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", order=(1, 2, 3)))  # the first pickup is gone
    refused = wait_for_proposal(sim, rec, count=2)
    assert refused["generation"] == 1 and refused["steps"] == proposal["steps"]
    # the validator's reason: the mission's temporal plan checks the step's at-start condition (builtin: precondition)
    assert "step 1" in refused["error"] and "condition" in refused["error"] and "(holding r1 c)" in refused["error"]
    assert refused["decision"] == {"action": "modify", "order": [1, 2, 3]}
    for _ in range(30):
        sim.tick()
    assert work(skills) == [] and events(rec, "planner", what="plan") == []
    sim.decide_plan(PROBLEM, 1, PlanDecision("accept"))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"]
    assert len(proposals(rec)) == 2


def test_a_pinned_task_runs_on_the_pinned_robot():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, review=True)
    proposal = wait_for_proposal(sim, rec)
    unstack = next(i for i, task in enumerate(proposal["tasks"]) if task["labels"][0].startswith("Unstack"))
    assert proposal["tasks"][unstack]["robots"] is None  # either robot could take it
    entry = proposal["tasks"][unstack]["entry_point"]
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", pins={entry: "r2"}))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["success"] and goal_holds(sim, "r1")
    assert [agent for agent, skill, _ in work(skills) if skill == "Unstack"] == ["r2"]
    assert [agent for agent, skill, _ in work(skills) if skill == "Putdown"] == ["r2"]
    assert made_plans(sim.engines["r1"])[-1][2].allowed[unstack] == ("r2",)


@pytest.mark.parametrize(
    ("pins", "message"),
    [({"T0": "r9"}, "'r9' is not in the team"), ({"T7": "r1"}, "no task 'T7'")],
)
def test_a_bad_pin_is_refused_with_an_error_proposal(pins, message):
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, review=True)
    wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", pins=pins))
    refused = wait_for_proposal(sim, rec, count=2)
    assert message in refused["error"] and refused["generation"] == 1
    for _ in range(20):
        sim.tick()
    assert work(skills) == []


def test_operator_actions_are_operator_events_in_the_trace():
    skills = BlockSkills()
    sim, rec = team_on_table(skills)
    sim.set_facts([(True, "clear", ("d",))], by_operator=True)
    wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", order=(0, 1, 2, 3), pins={"0": "r1"}))
    mine = [e for e in events(rec, "operator") if e["agent"] == "operator"]
    assert [e["what"] for e in mine] == ["goal", "facts", "modify"]
    assert mine[0]["goal"] == TWO_PAIRS and mine[0]["problem"] == PROBLEM
    assert mine[1]["facts"] == ["clear(d)"]
    assert mine[2]["order"] == [0, 1, 2, 3] and mine[2]["pins"] == {"0": "r1"} and mine[2]["generation"] == 1
    # the team's own set-up (not an operator's action) is traced as before
    assert [e["agent"] for e in events(rec, "operator") if "what" not in e] == ["-"]


def test_a_decision_for_an_older_generation_is_ignored_with_a_note():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills, review=True)
    wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("decline"))
    wait_for_proposal(sim, rec, generation=2)
    sim.decide_plan(PROBLEM, 1, PlanDecision("accept"))
    run_until(sim, lambda: events(rec, "note"))
    assert "generation 1 is ignored" in events(rec, "note")[0]["message"]
    for _ in range(20):
        sim.tick()
    assert work(skills) == []


def test_the_leader_crashing_while_a_proposal_waits_the_next_leader_proposes():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2", "r3"], skills, review=True)
    wait_for_proposal(sim, rec, agent="r1")
    sim.crash("r1")
    taken = wait_for_proposal(sim, rec, agent="r2")
    assert taken["generation"] == 2 and taken["leader"] == "r2"
    assert events(rec, "planner", agent="r2", what="started")[0]["reason"] == "taking over from r1"
    assert work(skills) == []
    sim.decide_plan(PROBLEM, 2, PlanDecision("accept"))
    summary = sim.run(until_done=True, max_time=90)
    assert summary["agents"]["r2"]["status"] == "success" and summary["agents"]["r3"]["status"] == "success"
    assert goal_holds(sim, "r2")
    assert sim.engines["r1"].decisions[PROBLEM] == [(2, PlanDecision("accept"))]  # a crashed agent is told too


def test_describe_proposal_prints_steps_tasks_and_error():
    skills = BlockSkills()
    sim, rec = team_on_table(skills)
    wait_for_proposal(sim, rec)
    sim.decide_plan(PROBLEM, 1, PlanDecision("modify", order=(1,)))
    text = describe_proposal(wait_for_proposal(sim, rec, count=2))
    assert "generation 1" in text and "0: (pickup r1" in text and "task StackBlocks_g1_proposal_T0" in text
    assert "refused change: the modified plan is invalid: step 1" in text


def test_a_plan_decision_checks_its_fields_and_the_problem_name():
    with pytest.raises(ValueError, match="accept"):
        PlanDecision("approve")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="only 'modify'"):
        PlanDecision("accept", order=(0,))
    sim, _ = blocks_team(["r1"], BlockSkills(), review=True)
    with pytest.raises(AlicaError, match="no planning problem named 'Nope'"):
        sim.decide_plan("Nope", 1, PlanDecision("accept"))


def test_without_review_the_first_plan_runs_at_once_and_nothing_is_proposed():
    skills = BlockSkills()
    sim, rec = blocks_team(["r1", "r2"], skills)
    summary = sim.run(until_done=True, max_time=60)
    assert summary["success"] and proposals(rec) == []


def test_a_stepwise_planner_proposes_every_step_and_each_runs_only_once_accepted():
    from tests.prophet.protap.test_team import goal_holds as survey_done
    from tests.prophet.protap.test_team import survey_team

    skills = BlockSkills()
    sim, rec = survey_team(skills, review=True)
    accepted: list[int] = []
    for _ in range(1200):
        if sim.done():
            break
        waiting = [p for p in proposals(rec) if p["generation"] not in accepted]
        if waiting:
            # before the operator accepts a step, the team runs no action of it
            assert len(made_plans(sim.engines["r1"])) == len(accepted)
            accepted.append(waiting[0]["generation"])
            sim.decide_plan("SurveySites", waiting[0]["generation"], PlanDecision("accept"))
        sim.tick()
    assert sim.done() and survey_done(sim, "r1")
    assert len(accepted) >= 2  # one proposal per step: drive, then act
    assert [g for g, _, _ in made_plans(sim.engines["r1"])] == accepted
    assert all(task["robots"] and len(task["robots"]) == 1 for p in proposals(rec) for task in p["tasks"])
