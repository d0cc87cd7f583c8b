"""A team of processes over zenoh: ``alica run --processes`` end to end, with kill -9, restart and a partition.

Every run is bounded by ``--time-limit`` (wall seconds) and talks on loopback
only; the partition cuts the relays between the agents' links, never the
host's network. The 3-agent lunar mission with stand-ins takes about 15 s.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from alica.app.cli import main
from tests.conftest import PLANS, blocks_mission_with_builtin

LUNAR = str(PLANS / "lunar" / "mission.yaml")
TEAM = ["--stand-ins", "--agents", "scout,stummel,amparo", "--fact", "found(a) and found(b)@3"]
TEAM_TIMEOUT = 3.0
TICK = 1 / 30


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict]:
    code = main(["run", LUNAR, *TEAM, "--processes", "--time-limit", "60", "--json", *argv])
    return code, json.loads(capsys.readouterr().out)


def events(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


def team_changes(trace: list[dict], change: str, who: str) -> dict[str, float]:
    """When each agent saw ``who`` lost or back (the first time)."""
    seen: dict[str, float] = {}
    for e in trace:
        if e["event"] == "team" and e["change"] == change and e["who"] == who:
            seen.setdefault(e["agent"], e["t"])
    return seen


def test_a_lunar_team_of_processes_succeeds(capsys, tmp_path):
    code, summary = run(capsys, "--trace", str(tmp_path / "run.jsonl"))
    assert code == 0, summary
    assert summary["processes"] and summary["clock"] == "wall"
    assert {name: a["status"] for name, a in summary["agents"].items()} == dict.fromkeys(
        ("scout", "stummel", "amparo"), "success"
    )
    assert summary["world_models_agree"]
    messages = summary["messages"]
    assert set(messages) == {"sent", "delivered", "dropped_lost", "dropped_undecodable"}  # copies per receiver
    assert messages["delivered"] > 0 and messages["dropped_lost"] == messages["dropped_undecodable"] == 0
    trace = events(tmp_path / "run.jsonl")
    assert {e["agent"] for e in trace} >= {"scout", "stummel", "amparo"}
    assert [e["t"] for e in trace] == sorted(e["t"] for e in trace)
    headers = [e for e in trace if e["event"] == "trace"]  # the run's, first; the agents' own are left out
    assert headers == [trace[0]] and trace[0]["processes"] and set(trace[0]["agents"]) == {"scout", "stummel", "amparo"}


def test_kill_9_takes_an_agent_out_and_its_restart_catches_up(capsys, tmp_path):
    trace_file = tmp_path / "run.jsonl"
    code, summary = run(capsys, "--crash", "stummel@6", "--recover", "stummel@9", "--trace", str(trace_file))
    assert code == 0, summary
    assert summary["agents"]["stummel"]["incarnations"] == 2
    assert summary["world_models_agree"]
    trace = events(trace_file)
    crash = next(e["t"] for e in trace if e["event"] == "fault" and e["fault"] == "crash")
    recover = next(e["t"] for e in trace if e["event"] == "fault" and e["fault"] == "recover")
    lost = team_changes(trace, "lost", "stummel")
    assert set(lost) == {"scout", "amparo"}
    for t in lost.values():  # liveliness: well within the team timeout
        assert crash <= t <= crash + TEAM_TIMEOUT + 2 * TICK
    back = team_changes(trace, "back", "stummel")
    assert set(back) == {"scout", "amparo"} and all(t >= recover for t in back.values())
    # the killed process's trace is kept up to the kill, then its restart's
    lives = {e.get("incarnation") for e in trace if e.get("agent") == "stummel" and e["event"] != "fault"}
    assert lives == {1, 2}


def test_a_partition_heals_with_world_models_converged(capsys, tmp_path):
    trace_file = tmp_path / "run.jsonl"
    code, summary = run(capsys, "--partition", "scout|stummel,amparo@4-8", "--trace", str(trace_file))
    assert code == 0, summary
    assert (
        summary["world_models_agree"]
        and summary["messages"]["dropped_lost"] == summary["messages"]["dropped_undecodable"] == 0
    )
    trace = events(trace_file)
    assert set(team_changes(trace, "lost", "scout")) == {"stummel", "amparo"}
    assert set(team_changes(trace, "lost", "stummel")) == {"scout"}
    back = team_changes(trace, "back", "scout")
    assert set(back) == {"stummel", "amparo"} and all(t >= 8.0 for t in back.values())
    # both sides went on while cut off: the far side's behaviours changed during the cut
    assert any(e["event"] == "behaviour" and e["agent"] in ("stummel", "amparo") and 4.5 < e["t"] < 8.0 for e in trace)


def test_ctrl_c_stops_every_agent_process(tmp_path):
    argv = [sys.executable, "-m", "alica.app.cli", "run", LUNAR, *TEAM, "--processes", "--time-limit", "60", "--json"]
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    assert process.stderr is not None
    started = process.stderr.readline()  # the run says when every agent process is up
    assert "3 agent processes started" in started, started
    os.kill(process.pid, signal.SIGINT)
    out, err = process.communicate(timeout=30)
    assert process.returncode == 130, err
    summary = json.loads(out)
    assert all(a["status"] == "running" for a in summary["agents"].values())  # stopped mid-mission, each reported


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--trace-messages"], "--trace-messages only work in the simulated run"),
        (["--loss", "0.1"], "--loss only work in the simulated run"),
        (["--crash", "nobody@3"], "no agent named 'nobody'"),
    ],
)
def test_process_runs_refuse_what_only_simulation_does(capsys, argv, message):
    assert main(["run", LUNAR, *TEAM, "--processes", *argv]) == 1
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--name", "zorro", "--agents", "scout,stummel"], "--name zorro is not in --agents"),
        (["--name", "scout", "--zenoh", "nonsense"], "is not KEY=JSON"),
        (["--name", "scout", "--connect", "localhost"], "a zenoh endpoint looks like"),
        (["--name", "scout", "--frequency", "0"], "--frequency must be > 0"),
    ],
)
def test_alica_agent_explains_bad_input(capsys, argv, message):
    assert main(["agent", LUNAR, "--stand-ins", *argv]) == 1
    assert message in capsys.readouterr().err


def test_writes_on_both_sides_of_a_partition_reach_everyone_once_it_heals(tmp_path):
    from alica.app.processes import ProcessTeam

    team = ProcessTeam(
        LUNAR,
        "scout,stummel,amparo",
        ["scout", "stummel", "amparo"],
        ["--stand-ins", "--time-limit", "40"],
        tmp_path,
        relays=True,
        own={"scout": ["--fact", "found(a)@5"], "amparo": ["--fact", "found(b)@6"]},  # one robot's operator each
    )
    try:
        team.launch()
        team.run([(3.5, "partition", ([["scout"], ["stummel", "amparo"]], 3.5, 8.0)), (8.0, "heal", None)], 40)
    finally:
        team.stop()
    summary = team.summary("LunarMission", 0)
    assert summary["success"], summary
    assert summary["world_models_agree"]
    for agent in summary["agents"].values():
        assert {"found(a)", "found(b)"} <= set(agent["world_facts"])


def test_a_planning_team_of_processes_plans_with_magic_across_them(capsys, tmp_path):
    blocks = str(blocks_mission_with_builtin(tmp_path))  # MAGiC splits the builtin planner's search
    facts = (
        "ontable(a) and on(c, a) and clear(c) and ontable(b) and clear(b) "
        "and handempty(r1) and handempty(r2) and handempty(r3)@0"
    )
    trace_file = tmp_path / "run.jsonl"
    argv = ["run", blocks, "--agents", "r1:Manipulator,r2:Manipulator,r3:Manipulator", "--stand-ins", "--fact", facts]
    code = main(
        [*argv, "--parallel-planning", "--processes", "--time-limit", "120", "--json", "--trace", str(trace_file)]
    )
    summary = json.loads(capsys.readouterr().out)
    digest = {name: (a["status"], a.get("path"), a.get("reason", "")) for name, a in summary["agents"].items()}
    assert code == 0, (digest, [e for e in events(trace_file) if e["event"] == "planner"][-6:])
    assert summary["messages"]["dropped_lost"] == summary["messages"]["dropped_undecodable"] == 0
    trace = events(trace_file)
    [start] = [e for e in trace if e["event"] == "planner" and e["what"] == "magic"][:1]
    assert start["agents"] == ["r1", "r2", "r3"]
    rounds = [e for e in trace if e["event"] == "planner" and e["what"] == "magic done"]
    assert rounds and rounds[0]["status"] == "solved" and all(e["messages"] <= 6 for e in rounds)


def test_alica_agent_writes_a_header_naming_itself(capsys, tmp_path):
    from alica.engine import read_trace

    path = tmp_path / "scout.jsonl"
    argv = ["--name", "scout", "--agents", "scout", "--time-limit", "0.3", "--listen", "tcp/127.0.0.1:0"]
    main(["agent", LUNAR, "--stand-ins", *argv, "--key-prefix", "trace-header-test", "--trace", str(path)])
    capsys.readouterr()
    trace = read_trace(path)
    assert trace.version == 2 and trace.meta["recorder"] == "scout" and trace.meta["clock"] == "wall"
    assert trace.meta["agents"] == {"scout": {"role": "Scout", "plan": "LunarMission"}} and trace.meta["plans"] == [
        LUNAR
    ]
