"""Traces for the control center's tests: one recorded by ``alica run``, one written by hand with replans and poses."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from alica.app.cli import main
from alica.io import plans_dir

TOKEN = "test-token"


@pytest.fixture(scope="session")
def recorded_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The formation example run by three robots, r2 crashing at 1 s."""
    path = tmp_path_factory.mktemp("center") / "formation.jsonl"
    code = main(
        [
            "run",
            str(plans_dir() / "examples" / "formation.yaml"),
            "--agents",
            "r1:Robot,r2:Robot,r3:Robot",
            "--stand-ins",
            "--crash",
            "r2@1",
            "--time-limit",
            "5",
            "--trace",
            str(path),
        ]
    )
    assert code in (0, 1)
    assert path.stat().st_size > 0
    return path


@pytest.fixture()
def written_trace(tmp_path: Path) -> Path:
    """A header line, allocations, a transition, two replans, a crash and poses."""
    events = [
        {
            "t": 0.0,
            "agent": "-",
            "event": "trace",
            "format": "alica-trace",
            "version": 2,
            "agents": {"a": {"role": "Scout", "plan": "Top"}, "b": {"role": "Stummel", "plan": "Top"}},
        },
        {"t": 0.0, "agent": "a", "event": "allocation", "key": "Top", "plan": "Top", "entries": {"a": "Go", "b": "Go"}},
        {"t": 0.0, "agent": "b", "event": "allocation", "key": "Top", "plan": "Top", "entries": {"a": "Go", "b": "Go"}},
        {"t": 0.5, "agent": "a", "event": "pose", "x": 0.0, "y": 0.0, "yaw": 0.0},
        {"t": 1.0, "agent": "a", "event": "transition", "key": "Top", "plan": "Top", "source": "S1", "target": "S2"},
        {"t": 1.5, "agent": "a", "event": "pose", "x": 1.0, "y": 2.0, "yaw": 0.5},
        {"t": 2.0, "agent": "a", "event": "replan", "key": "Top/S2/P", "reason": "a step failed"},
        {"t": 3.0, "agent": "-", "event": "fault", "fault": "crash", "agent_name": "b"},
        {"t": 3.0, "agent": "b", "event": "fault", "fault": "crash"},
        {"t": 4.0, "agent": "a", "event": "replan", "key": "Top/S2/P", "reason": "b lost"},
    ]
    path = tmp_path / "written.jsonl"
    path.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def blocks_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The blocks world demo: two manipulators, four blocks (a generated plan, object events of the blocks)."""
    folder = tmp_path_factory.mktemp("blocks")
    _demo("blocksworld", "--robots", "2", "--blocks", "4", "--seed", "4", "--out", str(folder))
    return folder / "trace.jsonl"


def _demo(*args: str) -> None:
    """Run ``alica demo ARGS`` in a process of its own (bounded).

    Not in this process: OMPL's random generator is one per process and seeded when the first motion planner
    is made, so a demo run here would change the motions of every later test in the session.
    """
    done = subprocess.run(
        [sys.executable, "-m", "alica.app.cli", "demo", *args], capture_output=True, text=True, timeout=300
    )
    assert done.returncode in (0, 1), done.stderr[-2000:]


@pytest.fixture(scope="session")
def lunar_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A short lunar demo on a small field: samples found, rocks, and team maps every 5 s (a few seconds of wall time)."""
    folder = tmp_path_factory.mktemp("lunar")
    _demo(  # the mission need not finish in 12 s (exit 1): the trace is what counts
        "lunar",
        "--agents",
        "scout,stummel",
        "--samples",
        "3",
        "--rocks",
        "8",
        "--size",
        "12",
        "--pick",
        "2",
        "--time-limit",
        "12",
        "--out",
        str(folder),
        "--no-progress",
    )
    path = folder / "trace.jsonl"
    assert path.stat().st_size > 0
    return path
