"""ProTaP in a plan file: a team runs the planning problem SurveySites (planner protap) under the engine.

The skills are scripted (they run a few ticks, then succeed, or fail when
told to); the runtime writes each finished step's effect, as for the
classical planners. The leader plans one step at a time; each step's actions
go to the robots the planner named; a failed drive sends the team back to
the WaitPlan and the next step is planned from where the robot really is.
"""

from __future__ import annotations

from alica.engine import SimulatedTeam, TraceRecorder
from alica.io import load_library
from alica.model import PlanningProblem
from alica.prophet import engine_config
from tests.conftest import PLANS
from tests.prophet.blocks_team import BlockSkills

SKILLS = ("MoveToPosition", "Pickup", "Putdown", "DetectCircles", "Idle")
POSITIONS = {"base": (0.0, 0.0), "s1": (6.0, 0.0), "s2": (0.0, 6.0), "s3": (6.0, 6.0)}
GOAL = (("sampled", "s1"), ("sampled", "s2"), ("scanned", "s3"))


def survey_team(skills: BlockSkills, agents=("r1", "r2"), seed: int = 0, review: bool = False):  # type: ignore[no-untyped-def]
    library = load_library(PLANS / "examples" / "protap_survey.yaml")
    recorder = TraceRecorder()
    sim = SimulatedTeam(
        library,
        "SurveyMission",
        dict.fromkeys(agents, "Surveyor"),
        seed=seed,
        config=engine_config(
            frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3, review=review
        ),
        skills={name: skills.factory(name) for name in SKILLS},
        observers=[recorder],
    )
    sim.set_facts([(True, "at", (agent, "base")) for agent in agents])
    for engine in sim.engines.values():
        for name, position in POSITIONS.items():
            engine.world_model.set("pos", name, value=position)
    return sim, recorder


def made_plans(sim, agent):  # type: ignore[no-untyped-def]
    planning = sim.engines[agent].children.factory(PlanningProblem)
    return [created for _, _, created in planning.board.made]


def events(recorder, kind, **match):  # type: ignore[no-untyped-def]
    return [e for e in recorder.events if e["event"] == kind and all(e.get(k) == v for k, v in match.items())]


def goal_holds(sim, agent) -> bool:  # type: ignore[no-untyped-def]
    world = sim.engines[agent].world_model
    return all(world.holds(name, arg) for name, arg in GOAL)


def test_the_team_reaches_the_goal_step_by_step_each_action_done_by_the_robot_the_planner_named():
    skills = BlockSkills()
    sim, recorder = survey_team(skills)
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"], summary
    assert goal_holds(sim, "r1") and goal_holds(sim, "r2")
    made = made_plans(sim, "r1")
    assert len(made) >= 2  # one plan per step: the goal needs at least two steps (drive, then act)
    for created in made:
        # one task per robot, pinned to the robot the planner chose for its steps
        assert created.allowed == tuple((task[0].robot,) for task in created.tasks)
        assert all(len({step.robot for step in task}) == 1 for task in created.tasks)
    # concurrency: some step has actions for both robots
    assert any(len(created.tasks) == 2 for created in made)
    # the skills ran on the robots the plans named: every drive to a site by its planned robot
    planned = {
        (step.robot, dict(step.bindings)["to"])
        for created in made
        for task in created.tasks
        for step in task
        if step.skill.name == "GotoSite"
    }
    driven = {(agent, str(params["at"])) for agent, skill, params in skills.runs if skill == "MoveToPosition"}
    assert driven == planned
    assert events(recorder, "planner", what="started", planner="protap")


def test_a_failed_drive_is_replanned_from_where_the_robot_is():
    skills = BlockSkills(fail=["MoveToPosition"])
    sim, recorder = survey_team(skills)
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"], summary
    assert goal_holds(sim, "r1")
    failures = [e for e in events(recorder, "replan") if "failed" in e["reason"]]
    assert failures, "the failed drive made the leader replan"
    # the robot whose drive failed was still at its start site when the next step was planned
    failed_agent = next(agent for agent, skill, _ in skills.runs if skill == "MoveToPosition")
    made = made_plans(sim, "r1")
    first, second = made[0], made[1]
    assert any(step.robot == failed_agent and step.skill.name == "GotoSite" for task in first.tasks for step in task)
    starts = {
        step.robot: dict(step.bindings)["from"]
        for task in second.tasks
        for step in task
        if step.skill.name == "GotoSite"
    }
    assert starts[failed_agent] == "base"


def test_the_same_seed_gives_the_same_run():
    runs = []
    for _ in range(2):
        skills = BlockSkills()
        sim, _ = survey_team(skills, seed=3)
        sim.run(until_done=True, max_time=120)
        runs.append(skills.runs)
    assert runs[0] == runs[1]


def test_alica_plan_prints_the_next_step_of_a_plan_file_problem_with_the_problem_s_own_planner(capsys):
    from alica.app.cli import main

    survey = str(PLANS / "examples" / "protap_survey.yaml")
    assert main(["plan", survey, "--world", "at(r1, base) and at(r2, s3)"]) == 0
    out = capsys.readouterr().out
    assert "; planner: protap" in out and "; the next step only" in out
    assert "(scansite r2 s3)" in out  # r2 stands at s3, whose scan is a goal: it scans in this step


def test_alica_run_with_stand_ins_reaches_the_goal(capsys):
    from alica.app.cli import main

    survey = str(PLANS / "examples" / "protap_survey.yaml")
    argv = [
        "run",
        survey,
        "--agents",
        "r1:Surveyor,r2:Surveyor",
        "--stand-ins",
        "--fact",
        "at(r1, base) and at(r2, base)@0",
    ]
    assert main([*argv, "--max-time", "120"]) == 0
    assert "SurveyMission: success" in capsys.readouterr().out


def test_the_leader_crashes_and_the_other_robot_finishes_the_survey_alone():
    skills = BlockSkills()
    sim, _ = survey_team(skills)
    sim.crash("r1", at=1.0)  # while r1 drives to its first site
    summary = sim.run(until_done=True, max_time=120)
    assert summary["success"], summary
    assert goal_holds(sim, "r2")
    later = made_plans(sim, "r2")[1:]
    assert later and all(step.robot == "r2" for created in later for task in created.tasks for step in task)
    # the site the crashed robot stood at is still surveyed: a declared place is never held by a robot outside
    assert any(step.label == "TakeSample(s1)" for created in later for task in created.tasks for step in task)
