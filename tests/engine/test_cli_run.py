"""``alica run`` end to end: summary, JSON, trace, faults, and clear errors for bad input."""

from __future__ import annotations

import json

import pytest

from alica.app.cli import main
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")


def test_run_until_done_prints_a_summary(capsys):
    code = main(
        [
            "run",
            LUNAR,
            "--stand-ins",
            "--agents",
            "scout,stummel,amparo",
            "--fact",
            "found(a) and found(b)@3",
            "--time-limit",
            "120",
        ]
    )
    out = capsys.readouterr().out
    assert code == 0, out
    assert out.startswith("LunarMission: success after")
    assert "amparo" in out and "LunarMission:DeliveredA" in out


def test_json_summary_and_trace(tmp_path, capsys):
    trace = tmp_path / "run.jsonl"
    code = main(
        [
            "run",
            LUNAR,
            "--stand-ins",
            "--agents",
            "scout:Scout,stummel:Stummel,amparo:Amparo",
            "--ticks",
            "240",
            "--crash",
            "scout@1",
            "--loss",
            "0.1",
            "--delay",
            "30",
            "--trace",
            str(trace),
            "--json",
        ]
    )
    assert code == 1  # not finished within --ticks 240
    summary = json.loads(capsys.readouterr().out)
    assert summary["ticks"] == 240 and summary["agents"]["scout"]["status"] == "crashed"
    assert summary["agents"]["stummel"]["tasks"][0] == "Explore"
    assert set(summary) >= {"plan", "seed", "sim_time_s", "success", "agents", "messages", "faults"}
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    kinds = {e["event"] for e in events}
    assert {"allocation", "transition", "fault", "team"} <= kinds
    assert any(e["event"] == "fault" and e["fault"] == "crash" for e in events)


def test_show_tree_prints_running_trees(capsys):
    assert main(["run", LUNAR, "--stand-ins", "--agents", "scout,stummel,amparo", "--ticks", "3", "--show-tree"]) == 1
    out = capsys.readouterr().out
    assert "scout [Scout]" in out and "└─ LunarMission  task Explore  state Exploring" in out


def test_partition_option(capsys):
    assert (
        main(
            [
                "run",
                LUNAR,
                "--stand-ins",
                "--agents",
                "scout,stummel,amparo",
                "--ticks",
                "60",
                "--partition",
                "scout|stummel,amparo@0.5-1.5",
                "--json",
            ]
        )
        == 1  # not finished within --ticks 60
    )
    summary = json.loads(capsys.readouterr().out)
    assert summary["faults"] == ["partition scout|amparo,stummel@0.5-1.5"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--agents", "scout:Pilot"],
            "agent 'scout' has role 'Pilot', which no role set has; roles: Amparo, Scout, Stummel",
        ),
        (["--agents", "robot1"], "agent 'robot1' has no role"),
        (["--agents", "a:Scout,a:Scout"], "given twice"),
        (["--agents", "scout", "--crash", "nobody@2"], "no agent named 'nobody'"),
        (["--agents", "scout", "--crash", "scout"], "not of the form WHAT@T"),
        (["--agents", "scout", "--partition", "scout@soon"], "not of the form WHAT@T1-T2"),
        (["--agents", "scout", "--loss", "1.5"], "--loss must lie in [0, 1)"),
        (["--agents", "scout", "--fact", "found(@1"], "error"),
    ],
)
def test_bad_input_gets_a_clear_error(argv, message, capsys):
    code = main(["run", LUNAR, "--stand-ins", "--ticks", "1", *argv])
    err = capsys.readouterr().err
    assert code == 1
    assert message in err
    assert "Traceback" not in err and "internal error" not in err


def test_missing_plan_file(capsys):
    assert main(["run", "no/such/plan.yaml", "--agents", "scout"]) == 1
    assert "no/such/plan.yaml" in capsys.readouterr().err


def test_roles_from_capabilities(capsys):
    agents = "r1:+base+lidar2d+camera,r2:+base+arm+gripper+lidar2d+camera,r3:+base+arm+gripper+lidar3d+stereo_camera"
    assert main(["run", LUNAR, "--stand-ins", "--agents", agents, "--ticks", "3", "--json"]) == 1  # unfinished
    roles = {name: a["role"] for name, a in json.loads(capsys.readouterr().out)["agents"].items()}
    assert roles == {"r1": "Scout", "r2": "Stummel", "r3": "Amparo"}


def test_capabilities_that_fit_no_role(capsys):
    assert main(["run", LUNAR, "--stand-ins", "--agents", "r1:+wings", "--ticks", "1"]) == 1
    err = capsys.readouterr().err
    assert "fits no role" in err and "Scout:" in err and "missing" in err


PLAYGROUND = """\
tasks: [Default]
rolesets:
  - name: R
    roles: [{name: Worker, priorities: {Default: 1}}]
behaviours:
  - {name: Wait, skill: Idle}
plans:
  - name: Quick
    entry_points: [{task: Default, state: Start, min: 1}]
    states:
      - {name: Start, transitions: [{to: Done, condition: 'true'}]}
      - {name: Done, kind: success}
  - name: Doomed
    entry_points: [{task: Default, state: Start, min: 1}]
    states:
      - {name: Start, children: [Wait], transitions: [{to: Broken, condition: 'true'}]}
      - {name: Broken, kind: failure}
  - name: Endless
    entry_points: [{task: Default, state: Start, min: 1}]
    states:
      - {name: Start, children: [Wait], transitions: [{to: Done, condition: 'false'}]}
      - {name: Done, kind: success}
  - name: Crowd
    entry_points: [{task: Default, state: Start, min: 2}]
    states:
      - {name: Start, kind: success}
"""


@pytest.fixture
def playground(tmp_path):
    path = tmp_path / "playground.yaml"
    path.write_text(PLAYGROUND)
    return str(path)


@pytest.mark.parametrize(
    ("plan", "limit", "code"),
    [
        ("Quick", ["--ticks", "5"], 0),
        ("Quick", ["--until-done"], 0),
        ("Quick", [], 0),
        ("Doomed", ["--ticks", "30"], 1),
        ("Doomed", ["--until-done"], 1),
        ("Endless", ["--ticks", "30"], 1),
        ("Endless", ["--until-done", "--time-limit", "2"], 1),
        ("Endless", ["--time-limit", "2"], 1),
    ],
)
def test_one_exit_code_rule_for_both_limits(playground, capsys, plan, limit, code):
    """0 when the root plan succeeded; 1 when it failed or did not finish within --ticks or --time-limit."""
    assert main(["run", playground, "--name", plan, "--agents", "w:Worker", *limit]) == code
    out = capsys.readouterr().out
    verdict = {"Quick": "success", "Doomed": "failed", "Endless": "not finished"}[plan]
    assert out.startswith(f"{plan}: {verdict} after")


@pytest.mark.parametrize(
    ("plan", "reason"),
    [
        ("Doomed", "plan 'Doomed' failed: reached failure state 'Broken' at t="),
        ("Endless", "in Endless:Start (Wait running), waiting for one of: false"),
        ("Crowd", "no valid assignment: plan 'Crowd' needs at least 2 agents"),
    ],
)
def test_summary_says_why_a_run_did_not_succeed(playground, capsys, plan, reason):
    argv = ["run", playground, "--name", plan, "--agents", "w:Worker", "--time-limit", "2"]
    assert main(argv) == 1
    assert f"why w: {reason}" in capsys.readouterr().out
    assert main([*argv, "--json"]) == 1
    assert reason in json.loads(capsys.readouterr().out)["agents"]["w"]["reason"]


def test_no_reason_on_success(playground, capsys):
    assert main(["run", playground, "--name", "Quick", "--agents", "w:Worker", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["agents"]["w"]["reason"] is None
    assert main(["run", playground, "--name", "Quick", "--agents", "w:Worker"]) == 0
    assert "why" not in capsys.readouterr().out


def test_crashed_agent_and_fault_times_print_as_given(capsys):
    argv = ["run", LUNAR, "--stand-ins", "--agents", "scout,stummel,amparo", "--time-limit", "3", "--crash", "scout@2"]
    assert main([*argv, "--partition", "scout|stummel,amparo@1-2.5", "--recover", "scout@2.5"]) == 1
    out = capsys.readouterr().out
    assert "faults: partition scout|amparo,stummel@1-2.5; crash scout@2; recover scout@2.5" in out
    assert main([*argv, "--partition", "stummel|amparo@1"]) == 1
    out = capsys.readouterr().out
    assert "why scout: crashed at 2 s" in out and "faults: partition stummel|amparo@1; crash scout@2" in out
