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
            "--max-time",
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
            "150",
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
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ticks"] == 150 and summary["agents"]["scout"]["status"] == "crashed"
    assert summary["agents"]["stummel"]["tasks"][0] == "Explore"
    assert set(summary) >= {"plan", "seed", "sim_time_s", "success", "agents", "messages", "faults"}
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    kinds = {e["event"] for e in events}
    assert {"allocation", "transition", "fault", "team"} <= kinds
    assert any(e["event"] == "fault" and e["fault"] == "crash" for e in events)


def test_show_tree_prints_running_trees(capsys):
    assert main(["run", LUNAR, "--stand-ins", "--agents", "scout,stummel,amparo", "--ticks", "3", "--show-tree"]) == 0
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
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert any(f.startswith("partition") for f in summary["faults"])


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--agents", "scout:Pilot"], "no role set has the roles ['Pilot']"),
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
    assert main(["run", LUNAR, "--stand-ins", "--agents", agents, "--ticks", "3", "--json"]) == 0
    roles = {name: a["role"] for name, a in json.loads(capsys.readouterr().out)["agents"].items()}
    assert roles == {"r1": "Scout", "r2": "Stummel", "r3": "Amparo"}


def test_capabilities_that_fit_no_role(capsys):
    assert main(["run", LUNAR, "--stand-ins", "--agents", "r1:+wings", "--ticks", "1"]) == 1
    err = capsys.readouterr().err
    assert "fits no role" in err and "Scout:" in err and "missing" in err
