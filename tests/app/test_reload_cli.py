"""``--watch`` end to end: a plan file edited while the team runs, in simulation and as processes.

Every run is bounded (``--time-limit``; process waits have timeouts). A test
edits the file once the trace shows the agents waiting on the condition it
changes, polling the trace (line-buffered) rather than waiting a fixed time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from alica.comm.zenoh_transport import free_endpoints
from tests.conftest import PLANS

PLAN = (PLANS / "examples" / "gate.yaml").read_text(encoding="utf-8")  # the hot-reload example
WAIT = 'condition: "go"}'
WAIT_LINE = next(number for number, line in enumerate(PLAN.splitlines(), 1) if WAIT in line)
HOLDS = 'condition: "true"}'
TYPO = 'condition: "og"}'
LIMIT = 60.0  # wall seconds any one run may take here


def _cli(*argv: str, env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "alica.app.cli", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def _events(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    lines = path.read_text(encoding="utf-8").splitlines()
    return [json.loads(line) for line in lines if line.endswith("}")]  # (the last line may be half written)


def _until(check: Callable[[], bool], what: str, process: subprocess.Popen[str] | None = None) -> None:
    """Poll ``check`` until it holds (a bounded wait for another process; no fixed sleep)."""
    deadline = time.monotonic() + LIMIT
    while not check():
        if process is not None and process.poll() is not None:
            raise AssertionError(f"the run ended before {what}: {process.stderr.read() if process.stderr else ''}")
        assert time.monotonic() < deadline, f"no {what} within {LIMIT:g} s"
        time.sleep(0.05)


def _waiting(trace: Path, agents: int) -> Callable[[], bool]:
    """Whether the trace shows ``agents`` agents running Hold (waiting in Gate)."""

    def check() -> bool:
        running = {e["agent"] for e in _events(trace) if e["event"] == "behaviour" and e.get("behaviour") == "Hold"}
        return len(running) >= agents

    return check


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")


def _finish(process: subprocess.Popen[str]) -> tuple[int, str, str]:
    try:
        out, err = process.communicate(timeout=LIMIT)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    return process.returncode, out, err


def _keep_started_once(events: list[dict[str, Any]], agents: set[str]) -> None:
    """The other branch (Keep) started once per agent and never stopped before Top's Done."""
    keep = [e for e in events if e["event"] == "behaviour" and e.get("behaviour") == "Keep"]
    assert sorted(e["agent"] for e in keep if e["status"] == "running") == sorted(agents)
    assert all(e["status"] == "running" for e in keep)


def test_a_watched_simulated_run_takes_an_edited_condition_on_both_agents_at_one_tick(tmp_path: Path) -> None:
    plan, trace = tmp_path / "team.yaml", tmp_path / "trace.jsonl"
    plan.write_text(PLAN, encoding="utf-8")
    run = _cli(
        "run",
        str(plan),
        "--agents",
        "a:Worker,b:Worker",
        "--watch",
        "--speed",
        "4",
        "--time-limit",
        "120",
        "--trace",
        str(trace),
        "--json",
    )
    _until(_waiting(trace, 2), "agents waiting in Gate", run)
    _edit(plan, WAIT, TYPO)  # an invalid edit first: reported with file, line and column; nothing changes
    _until(lambda: any(e.get("status") == "invalid" for e in _events(trace)), "the invalid edit's report", run)
    _edit(plan, TYPO, HOLDS)
    code, out, err = _finish(run)
    assert code == 0, err[-2000:]
    assert json.loads(out)["success"]
    events = _events(trace)
    invalid = [e for e in events if e["event"] == "reload" and e["status"] == "invalid"]
    assert len(invalid) == 1 and f"{plan}:{WAIT_LINE}:" in invalid[0]["errors"][0] and "unknown predicate 'og'" in err
    adopted = [e for e in events if e["event"] == "reload" and e["status"] == "adopted"]
    assert {e["agent"] for e in adopted} == {"a", "b"} and len({e["t"] for e in adopted}) == 1
    assert adopted[0]["changes"] == {"changed": ["plan Gate"]} and adopted[0]["restarted"] == []
    passed = [e for e in events if e["event"] == "transition" and e["target"] == "Passed"]
    assert {e["agent"] for e in passed} == {"a", "b"} and {e["t"] for e in passed} == {adopted[0]["t"]}
    _keep_started_once(events, {"a", "b"})
    assert "reload: a switched plans" in err and "reload: b switched plans" in err


def test_a_watched_team_of_processes_switches_together(tmp_path: Path) -> None:
    plan, trace = tmp_path / "team.yaml", tmp_path / "run.jsonl"
    plan.write_text(PLAN, encoding="utf-8")
    run = _cli(
        "run",
        str(plan),
        "--agents",
        "a:Worker,b:Worker",
        "--processes",
        "--watch",
        "--time-limit",
        "40",
        "--trace",
        str(trace),
        "--json",
        env={**os.environ, "TMPDIR": str(tmp_path)},  # the agents' traces go to a temporary folder: here
    )
    _until(lambda: _agent_traces_waiting(tmp_path), "agents waiting in Gate", run)
    _edit(plan, WAIT, HOLDS)
    code, out, err = _finish(run)
    assert code == 0, err[-2000:]
    summary = json.loads(out)
    adopted = [r for r in summary["reloads"] if r["status"] == "adopted"]
    assert {r["agent"] for r in adopted} == {"a", "b"}
    agreed = [r for r in summary["reloads"] if r["status"] == "agreed"]
    assert len(agreed) == 1 and agreed[0]["agent"] == "a"  # the leader, the lowest name
    events = _events(trace)
    passed = {e["agent"]: e["t"] for e in events if e["event"] == "transition" and e["target"] == "Passed"}
    assert set(passed) == {"a", "b"}
    # the same tick of the agreed time: each agent's first tick at or after it (30 Hz, unaligned clocks)
    assert all(agreed[0]["at"] <= t <= agreed[0]["at"] + 2 / 30 for t in passed.values()), (passed, agreed)
    _keep_started_once(events, {"a", "b"})


def _agent_traces_waiting(folder: Path) -> bool:
    traces = list(folder.glob("alica-run-*/*.jsonl"))  # alica run --processes keeps its agents' traces there
    held = {
        e["agent"]
        for path in traces
        for e in _events(path)
        if e["event"] == "behaviour" and e.get("behaviour") == "Hold"
    }
    return held >= {"a", "b"}


def test_a_team_whose_agents_see_different_files_does_not_switch_and_names_the_agent_that_differs(
    tmp_path: Path,
) -> None:
    ends = free_endpoints(2)
    plans = {name: tmp_path / name / "team.yaml" for name in ("a", "b")}
    agents = {}
    for i, (name, plan) in enumerate(plans.items()):
        plan.parent.mkdir()
        plan.write_text(PLAN, encoding="utf-8")
        agents[name] = _cli(
            "agent",
            str(plan),
            "--name",
            name,
            "--agents",
            "a:Worker,b:Worker",
            "--listen",
            ends[i],
            "--connect",
            ends[1 - i],
            "--key-prefix",
            f"reload-{tmp_path.name}",
            "--watch",
            "--json",
            "--trace",
            str(plan.parent / "trace.jsonl"),
            "--time-limit",
            "40",
        )
    try:
        for name, plan in plans.items():
            _until(_waiting(plan.parent / "trace.jsonl", 1), f"{name} waiting in Gate", agents[name])
        _edit(plans["a"], WAIT, HOLDS)  # b's robot was not updated
        trace_a = plans["a"].parent / "trace.jsonl"
        _until(lambda: any(e.get("status") == "waiting" for e in _events(trace_a)), "a's report", agents["a"])
        waiting = next(e for e in _events(trace_a) if e.get("status") == "waiting")
        b_digest = next(e for e in _events(trace_a) if e.get("status") == "proposed")["library"]
        assert waiting["differ"] == {"b": b_digest}  # b runs the old plans and proposes nothing
        both = [*_events(trace_a), *_events(plans["b"].parent / "trace.jsonl")]
        assert not any(e.get("status") == "adopted" or e.get("target") == "Passed" for e in both)
        _edit(plans["b"], WAIT, HOLDS)  # now b has them too: the team switches
        results = {name: _finish(process) for name, process in agents.items()}
    finally:
        for process in agents.values():
            if process.poll() is None:
                process.kill()
                process.communicate()
    for name, (code, out, err) in results.items():
        assert code == 0, (name, err[-2000:])
        lines = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
        assert any(r["event"] == "reload" and r["status"] == "waiting" for r in lines) == (name == "a")
        assert any(r["event"] == "reload" and r["status"] == "adopted" for r in lines)
