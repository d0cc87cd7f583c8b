"""Agents on a world server: ``alica agent --world``, ``alica run --processes --world``, faults (issue 38).

Every test starts real processes (a world server, agents) on loopback and is
bounded in wall time; every process is killed in a ``finally``.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from alica.app.cli import main
from alica.app.cli_agent import mission_knowledge
from alica.comm.zenoh_transport import free_endpoints
from alica.errors import AlicaError
from alica.io.loader import plans_dir

ALICA = [sys.executable, "-m", "alica.app.cli"]

#: One robot drives 8 m; a failed drive waits a second and drives again.
TRIP = """\
alica: 1
imports: ["alica:plans/tasks.yaml", "alica:plans/roles.yaml"]
behaviours:
  - name: Far
    skill: DriveTo
    params: {goal: [8.0, 0.0], tolerance: 0.5, timeout: 120.0}
plans:
  - name: Trip
    entry_points:
      - {task: MoveTo, state: Drive, min: 1, max: 1}
    states:
      - name: Drive
        children: [Far]
        transitions:
          - {to: There, condition: "succeeded"}
          - {to: Again, condition: "failed"}
      - name: Again
        transitions:
          - {to: Drive, condition: "elapsed > 1"}
      - name: There
        kind: success
"""


def _serve(endpoint: str, log: Path) -> subprocess.Popen[bytes]:
    argv = [*ALICA, "world", "serve", "--world", "lunar", "--rocks", "0", "--samples", "0", "--size", "20"]
    with log.open("ab") as out:
        return subprocess.Popen(
            [*argv, "--listen", endpoint, "--agents", "scout", "--duration", "120"], stdout=out, stderr=out
        )


def _agent(plan: Path, world: str, trace: Path) -> subprocess.Popen[str]:
    """Scout's agent on the trip, its robot at the world server ``world``; done when the trip is."""
    argv = [*ALICA, "agent", str(plan), "--name", "scout", "--agents", "scout:Scout", "--world", world]
    argv += ["--json", "--time-limit", "90", "--until-done", "--trace", str(trace)]
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(check, seconds: float) -> bool:
    """Whether ``check()`` came true within ``seconds`` wall seconds (the processes run on the wall clock)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if check():
            return True
        time.sleep(0.1)  # a bounded poll of other processes' files (they run on the wall clock; nothing signals)
    return False


def test_a_dead_world_server_fails_the_skill_with_a_reason_and_the_agent_goes_on_with_a_new_one(tmp_path: Path) -> None:
    plan = tmp_path / "trip.yaml"
    plan.write_text(TRIP, encoding="utf-8")
    (endpoint,) = free_endpoints(1)
    trace = tmp_path / "scout.jsonl"
    processes: list[subprocess.Popen] = []
    try:
        processes.append(_serve(endpoint, tmp_path / "server.log"))
        agent = _agent(plan, endpoint, trace)
        processes.append(agent)
        assert _wait_for(lambda: trace.exists() and '"running"' in trace.read_text(), 60), "the drive never started"
        processes[0].kill()  # kill -9 of the world server while the robot drives
        processes[0].wait()
        failed = lambda: '"failure"' in trace.read_text()  # noqa: E731
        assert _wait_for(failed, 20), "the drive did not fail when the server died"
        assert agent.poll() is None, "the agent must not end when its world server dies"
        processes.append(_serve(endpoint, tmp_path / "server.log"))  # a server comes back on the same endpoint
        out, err = agent.communicate(timeout=90)
    finally:
        for process in processes:
            if process.poll() is None:
                process.kill()
                process.wait()
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["status"] == "success" and summary["path"] == "Trip:There", (summary, err[-2000:])
    assert "Traceback" not in err
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    reasons = [e["reason"] for e in events if e.get("event") == "behaviour" and e.get("status") == "failure"]
    assert reasons and all("world server" in r and "does not answer" in r for r in reasons), reasons
    times = [e["t"] for e in events if "t" in e and e.get("event") != "trace"]
    assert times == sorted(times), "the agent's time went back when the new server started from 0"


@pytest.mark.parametrize(
    ("argv", "world"),
    [
        (["examples/formation.yaml", "--agents", "scout:Robot,stummel:Robot,amparo:Robot"], "lunar"),
        (["blocksworld/mission.yaml", "--agents", "r1:Manipulator,r2:Manipulator", "--fact", "start@0"], "blocks"),
    ],
)
def test_alica_run_processes_with_a_world_runs_the_real_skills_in_a_world_server(argv, world, capfd) -> None:
    plan, *rest = argv
    code = main(
        ["run", str(plans_dir() / plan), *rest, "--processes", "--world", world, "--time-limit", "120", "--json"]
    )
    out = capfd.readouterr().out
    summary = json.loads(out[out.index("{") :])
    assert code == 0 and summary["success"], summary
    assert summary["processes"] and summary["skills"]["world"] == world and summary["skills"]["stand_ins"] == []
    # (whether the world models agree at the stop is not asserted: robots share their poses while they move,
    # and SIGTERM reaches the agents at different ticks)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--goal", "GetObjects"], "is not PROBLEM=FORMULA"),
        (["--goal", "Nope=at(a, g)"], "no planning problem named 'Nope'"),
        (["--object", "g"], "is not NAME:TYPE"),
        (["--value", "pos(g)"], "is not FUNCTION(ARGS)=VALUE"),
        (["--value", "pos(g)=[1, 2"], "is not a YAML value"),
        (["--perception", "blocks"], "give --world or --robot too"),
        (["--world", "tcp/127.0.0.1:9", "--robot", "unicycle"], "choose one"),
    ],
)
def test_bad_agent_options_get_a_clear_error(argv, message, capsys) -> None:
    mission = str(plans_dir() / "lunar" / "impera.yaml")
    assert main(["agent", mission, "--name", "scout", "--agents", "scout:Scout", *argv]) != 0
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err, err


def test_an_agent_without_a_server_at_its_world_endpoint_says_so(capsys) -> None:
    (endpoint,) = free_endpoints(1)
    mission = str(plans_dir() / "skills" / "explore.yaml")
    assert main(["agent", mission, "--name", "scout", "--agents", "scout:Scout", "--world", endpoint]) != 0
    err = capsys.readouterr().err
    assert f"--world {endpoint}" in err and "no world server" in err and "Traceback" not in err, err


NAMES = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True)


@given(
    function=NAMES,
    args=st.lists(NAMES, max_size=3),
    value=st.one_of(
        st.integers(-1000, 1000),
        st.lists(st.floats(-1e6, 1e6, allow_nan=False).map(lambda v: round(v, 3)), min_size=1, max_size=3),
    ),
)
def test_mission_values_read_back_what_was_written(function, args, value) -> None:
    text = f"{function}({', '.join(args)})={json.dumps(value)}"
    _, values = mission_knowledge([], [text])
    assert values == [(function, tuple(args), tuple(value) if isinstance(value, list) else value)]


@given(st.text(max_size=30))
def test_mission_values_never_fail_other_than_with_a_clear_error(text) -> None:
    try:
        mission_knowledge([text], [text])
    except AlicaError as exc:
        assert "--object" in str(exc) or "--value" in str(exc)


def test_with_the_teams_credentials_the_world_server_is_the_member_world(tmp_path: Path, capfd) -> None:
    keys = tmp_path / "keys"
    assert main(["team", "keys", "--out", str(keys), "scout", "stummel", "amparo", "world"]) == 0
    plan = str(plans_dir() / "examples" / "formation.yaml")
    argv = ["run", plan, "--agents", "scout:Robot,stummel:Robot,amparo:Robot", "--processes", "--world", "lunar"]
    code = main([*argv, "--team-keys", str(keys), "--time-limit", "120", "--json"])
    out = capfd.readouterr().out
    summary = json.loads(out[out.index("{") :])
    assert code == 0 and summary["success"] and summary["skills"]["world"] == "lunar", summary


def test_a_partition_between_an_agent_and_its_world_server_is_a_robot_that_does_not_answer(tmp_path: Path) -> None:
    """The agent reaches the server through a relay; cutting it fails the drive within a bounded wait, healing it
    lets the agent drive on (the server lives on meanwhile: free-running, its robot stopped where it was)."""
    from alica.comm.relay import LinkRelay

    plan = tmp_path / "trip.yaml"
    plan.write_text(TRIP, encoding="utf-8")
    (endpoint,) = free_endpoints(1)
    trace = tmp_path / "scout.jsonl"
    processes: list[subprocess.Popen] = []
    relay = None
    try:
        processes.append(_serve(endpoint, tmp_path / "server.log"))
        relay = LinkRelay(endpoint)
        agent = _agent(plan, relay.endpoint, trace)
        processes.append(agent)
        assert _wait_for(lambda: trace.exists() and '"running"' in trace.read_text(), 60), "the drive never started"
        cut_at = time.monotonic()
        relay.cut()
        assert _wait_for(lambda: '"failure"' in trace.read_text(), 20), "the drive did not fail when cut off"
        assert time.monotonic() - cut_at < 15.0  # a bounded wait: the zenoh lease and a call's time-out
        assert agent.poll() is None
        relay.heal()
        out, err = agent.communicate(timeout=90)
    finally:
        for process in processes:
            if process.poll() is None:
                process.kill()
                process.wait()
        if relay is not None:
            relay.close()
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["status"] == "success", (summary, err[-2000:])
    assert "Traceback" not in err
