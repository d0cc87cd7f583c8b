"""The blocks-world demo end to end, in simulated time with the real skills in pybullet."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from alica.app.demos.blocksworld import DemoConfig, goal_facts, goal_text, run_demo
from tests.conftest import ROOT

START = [["a", "c"], ["b"], ["d"]]
GOAL = [["d", "c", "b", "a"]]


def test_two_agents_reach_a_four_block_goal():
    result = run_demo(DemoConfig(agents=2, start=START, goal=GOAL, seed=3, time_limit=300))
    assert result.success and result.satisfied == result.goal_literals == 4
    assert result.plan_length >= 1 and sum(result.tasks.values()) >= 2
    assert result.messages > 0 and result.sim_time_s < 300


def test_with_an_opponent_the_goal_is_still_reached_after_replanning():
    # through the CLI in a fresh process: OMPL's generator is seeded once per process, so the run is the seed's own
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "alica.app.cli",
            "demo",
            "blocksworld",
            "--robots",
            "2",
            "--opponents",
            "1",
            "--blocks",
            "4",
            "--seed",
            "2",
            "--time-limit",
            "300",
            "--json",
            "--no-progress",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    summary = json.loads(next(line for line in reversed(run.stdout.splitlines()) if line.startswith("{")))
    assert run.returncode == 0 and summary["success"], summary
    assert summary["replans"] >= 1 and summary["satisfied"] == summary["goal_literals"] == 4
    assert set(summary["tasks"]) == {"r1", "r2"}  # the opponent is not part of the team


def test_a_robot_crash_in_the_middle_the_team_still_reaches_the_goal():
    crashed = []

    def crash_one_not_holding(team):
        # a robot that holds nothing (a crashed robot keeps what it holds, and that block is lost to the team)
        world = team.world
        name = next(n for n in sorted(team.engines, reverse=True) if world.robots[n].arm.held is None)
        crashed.append(name)
        team.crash(name)

    result = run_demo(
        DemoConfig(agents=3, start=START, goal=GOAL, seed=3, time_limit=400), actions=[(12.0, crash_one_not_holding)]
    )
    assert result.crashed == crashed and len(crashed) == 1
    assert result.success, result.as_json()


def test_goal_text_and_facts():
    assert goal_facts([["a", "b"], ["c"]]) == [("ontable", "a"), ("on", "b", "a"), ("ontable", "c")]
    assert goal_text([["a", "b"]]) == "ontable(a) and on(b, a)"


SCRIPT = """
import json, sys
from alica.app.demos.blocksworld import DemoConfig, run_demo
events = []
run_demo(DemoConfig(agents=2, start={start}, goal={goal}, seed=5, time_limit=120), observers=[events.append])
open(sys.argv[1], "w").write(json.dumps(events, sort_keys=True, default=str))
"""


@pytest.mark.parametrize("hash_seed", [("1", "2")])
def test_the_same_seed_gives_the_same_trace(hash_seed, tmp_path):
    # OMPL's random generator is seeded once per process: a run is repeatable in a fresh process
    script = SCRIPT.format(start=START, goal=GOAL)
    outputs = []
    for seed in hash_seed:
        out = tmp_path / f"trace-{seed}.json"
        run = subprocess.run(
            [sys.executable, "-c", script, str(out)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=600,
            env={"PYTHONHASHSEED": seed, "PATH": "", "PYTHONPATH": str(ROOT)},
        )
        assert run.returncode == 0, run.stderr[-2000:]
        outputs.append(json.loads(out.read_text()))
    assert outputs[0] == outputs[1]
    assert any(e["event"] == "planner" for e in outputs[0])


def test_small_demo_reports_the_steps_each_agent_carried_out(capsys):
    from alica.app.cli import main

    code = main(["demo", "blocksworld", "--robots", "2", "--blocks", "3", "--seed", "1", "--json", "--no-progress"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["success"], summary
    # start [[a], [b, c]], goal [[a], [b], [c]]: one robot unstacks c and puts it down, as one task
    assert summary["steps_executed"] == 2 and summary["plans"] == 1
    assert sorted(summary["steps"].values()) == [0, 2] and sorted(summary["tasks"].values()) == [0, 1]
    assert summary["steps"].keys() == summary["tasks"].keys() == {"r1", "r2"}


def test_counter_counts_finished_steps_across_plans_and_not_aborted_ones():
    from alica.app.demos.blocksworld import PROBLEM
    from alica.app.demos.common import StepCounter

    at = f"M/Stacking/{PROBLEM}"
    counter = StepCounter(["Pickup", "Stack"], PROBLEM)
    events = [
        {"event": "allocation", "agent": "r1", "key": at, "plan": "G1", "entries": {"r1": "G1_T0", "r2": "Standby"}},
        {"event": "planner", "agent": "r1", "key": at, "what": "plan", "generation": 1, "steps": 4},
        {"event": "allocation", "agent": "r1", "key": f"{at}/S0/Pickup", "plan": "Pickup", "entries": {}},
        {"event": "success", "agent": "r1", "key": f"{at}/S0/Pickup", "plan": "Pickup"},
        {"event": "allocation", "agent": "r1", "key": f"{at}/S1/Stack", "plan": "Stack", "entries": {}},
        {"event": "replan", "agent": "r1", "key": at},  # the Stack step is abandoned
        {"event": "planner", "agent": "r1", "key": at, "what": "plan", "generation": 2, "steps": 1},
        {"event": "allocation", "agent": "r1", "key": at, "plan": "G2", "entries": {"r1": "G2_T0"}},
        {"event": "allocation", "agent": "r1", "key": f"{at}/S0/Stack", "plan": "Stack", "entries": {}},
        {"event": "success", "agent": "r1", "key": f"{at}/S0/Stack", "plan": "Stack"},
        {"event": "success", "agent": "o1", "key": "Opp/Pickup", "plan": "Pickup"},  # an opponent's
    ]
    for event in events:
        counter(event)
    assert counter.steps == {"r1": 2} and len(counter.tasks["r1"]) == 2
    assert len(counter.plans) == 2 and counter.plan_length == 1 and counter.replans == 1


def test_counter_keeps_a_step_when_the_agent_reports_a_teammates_allocation():
    from alica.app.demos.blocksworld import PROBLEM
    from alica.app.demos.common import StepCounter

    at = f"M/Stacking/{PROBLEM}"
    counter = StepCounter(["Unstack", "Putdown"], PROBLEM)
    events = [
        {"event": "allocation", "agent": "r3", "key": at, "plan": "G1", "entries": {"r2": "G1_T1", "r3": "G1_T2"}},
        {"event": "allocation", "agent": "r3", "key": f"{at}/T2_S0/Unstack", "plan": "Unstack", "entries": {}},
        # r3 sees r1 take task T3 while its own Unstack runs: r3's step and task stay
        {"event": "allocation", "agent": "r3", "key": at, "plan": "G1", "entries": {"r1": "G1_T3"}},
        {"event": "success", "agent": "r3", "key": f"{at}/T2_S0/Unstack", "plan": "Unstack"},
    ]
    for event in events:
        counter(event)
    assert counter.steps == {"r3": 1} and counter.tasks["r3"] == {("G1", "G1_T2")}


def _demo_cli(*options: str) -> tuple[subprocess.CompletedProcess[str], dict]:
    run = subprocess.run(
        [sys.executable, "-m", "alica.app.cli", "demo", "blocksworld", *options, "--json", "--no-progress"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    lines = [line for line in run.stdout.splitlines() if line.startswith("{")]
    return run, json.loads(lines[-1]) if lines else {}


def test_a_leader_restarted_while_the_team_plans_rejoins_and_the_goal_is_reached():
    # the restarted r1 leads again before it knows the team's plans: it used to reuse a plan name
    # (KeyError: "plan 'StackBlocks_g2v1' has no state 'T1_S0_Unstack'") or plan for the mission's own goal
    run, summary = _demo_cli(
        "--robots",
        "3",
        "--blocks",
        "5",
        "--seed",
        "0",
        "--time-limit",
        "300",
        "--crash",
        "r1@3.5",
        "--recover",
        "r1@13.75",
    )
    assert "Traceback" not in run.stderr and run.returncode == 0, run.stderr[-2000:]
    assert summary["success"] and summary["crashed"] == []
    assert summary["steps"]["r1"] >= 1  # the recovered robot acts again


def test_demo_fault_options_are_checked():
    run, _ = _demo_cli("--robots", "2", "--crash", "r3@2")
    assert run.returncode == 1 and "--crash: 'r3' is not a team robot; the team is r1, r2" in run.stderr
    run, _ = _demo_cli("--recover", "r1")
    assert run.returncode == 1 and "--recover: 'r1' is not of the form WHAT@T" in run.stderr
    assert "Traceback" not in run.stderr


def test_a_crashed_holder_drops_its_block_and_the_team_plans_again():
    crashed: list[tuple[str, str]] = []
    revived: list[bool] = []

    def crash_a_holder(team):
        if crashed:
            return
        for name in sorted(team.engines):
            held = team.world.robots[name].arm.held
            if held is not None:
                crashed.append((name, held.name))
                team.crash(name)  # power loss: the gripper opens
                assert team.world.robots[name].arm.held is None
                team.recover(name, at=team.now() + 10.0)
                team.at(team.now() + 10.5, "check", lambda: revived.append(not team.world.robots[name].crashed))
                return

    result = run_demo(
        DemoConfig(agents=3, blocks=5, seed=0, time_limit=300),
        actions=[(5.0 + 0.5 * i, crash_a_holder) for i in range(60)],
    )
    assert len(crashed) == 1, "a robot held a block"
    assert revived == [True]  # the recovered robot's body takes commands again
    assert result.success and result.replans >= 1, result.as_json()


def test_with_ten_blocks_and_the_builtin_planner_four_agents_finish_sooner_than_two():
    # issue 19: more robots pay off with the plan for the fewest steps. Simulated times over a fixed set of
    # seeds, not wall times. Each run in a fresh process, as a user runs it: OMPL's generator is per process,
    # so in the test session a run's outcome would depend on the tests that ran before it. (The mission's
    # temporal planner is faster with either team, but over seeds 0-9 its 4 agents take 1.06x the time of
    # its 2: docs/blocksworld.md.)
    def run(robots: int, seed: int) -> dict:
        argv = ["demo", "blocksworld", "--robots", str(robots), "--blocks", "10", "--seed", str(seed)]
        argv += ["--planner", "builtin"]
        done = subprocess.run(
            [sys.executable, "-m", "alica.app.cli", *argv, "--time-limit", "400", "--json", "--no-progress"],
            capture_output=True,
            text=True,
            timeout=600,
            check=False,
        )
        return json.loads(done.stdout)

    seeds = (0, 1)
    two = [run(2, s) for s in seeds]
    four = [run(4, s) for s in seeds]
    assert all(r["success"] for r in two + four)
    assert sum(r["sim_time_s"] for r in four) < sum(r["sim_time_s"] for r in two), (
        [r["sim_time_s"] for r in two],
        [r["sim_time_s"] for r in four],
    )


def test_the_team_plans_for_its_time_with_the_temporal_planner(capsys, tmp_path):
    # four single blocks into one tower: planned for the makespan (the mission's planner), both robots carry blocks
    from alica.app.cli import main

    code = main(
        ["demo", "blocksworld", "--robots", "2", "--blocks", "4", "--seed", "2"]
        + ["--json", "--no-progress", "--out", str(tmp_path)]
    )
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["success"], summary
    assert all(steps >= 1 for steps in summary["steps"].values())  # both robots worked
    # the leader shares a temporal problem's first plan when its search is done or after one UpdateTime (1 s)
    events = [json.loads(line) for line in (tmp_path / "trace.jsonl").read_text().splitlines()]
    planner = [e for e in events if e.get("event") == "planner" and e["what"] in ("started", "plan", "done")]
    firsts = [(i, e) for i, e in enumerate(planner) if e["what"] == "plan" and e["version"] == 1]
    assert firsts
    for i, first in firsts:
        done_then = any(e["what"] == "done" and e["t"] == first["t"] for e in planner[i + 1 : i + 2])
        assert first["after_s"] >= 1.0 - 1e-9 or done_then, first


def test_another_planner_than_the_missions_is_for_the_in_process_demo():
    run, _ = _demo_cli("--robots", "2", "--processes", "--planner", "builtin")
    assert run.returncode == 1 and "--planner builtin runs only in the in-process demo" in run.stderr
    run, _ = _demo_cli("--planner", "fastest")
    assert run.returncode == 2 and "invalid choice: 'fastest'" in run.stderr
    assert "Traceback" not in run.stderr
