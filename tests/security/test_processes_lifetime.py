"""A team of processes dies with its parent (issue 37, finding 8).

``alica run --processes`` hands each ``alica agent`` the run's deadline and
the read end of a pipe on its standard input (``--parent-pipe 0``): the
agent ends by itself at the deadline plus a margin, and at once when the
pipe reaches end of file, which is when its parent is gone (even by
``kill -9``). An output path is checked before any agent starts, and
``alica agent`` does not create folders.

Each test waits with a deadline (never a bare sleep) and kills what it
started in ``finally``: the parent runs in its own process group, which its
agents share.
"""

from __future__ import annotations

import contextlib
import json
import os
import queue
import select
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from alica.app.cli import main
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")
TEAM = ["--stand-ins", "--agents", "scout,stummel,amparo"]
NAMES = {"scout", "stummel", "amparo"}
START_UP = 40.0
"""Seconds the team's processes have to start (a busy 2-core machine)."""

needs_proc = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the agent processes in /proc")


def _stat(pid: int) -> list[str] | None:
    """The fields of ``/proc/PID/stat`` after the command's name, or ``None`` when there is no such process."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text[text.rindex(")") + 2 :].split()


def alive(pid: int) -> bool:
    """Whether the process runs (a zombie waiting for its reaper has ended)."""
    fields = _stat(pid)
    return fields is not None and fields[0] not in ("Z", "X")


def agents_of(parent: int) -> list[int]:
    """The ``alica agent`` processes whose parent is ``parent``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        fields = _stat(int(entry.name))
        if fields is None or int(fields[1]) != parent:
            continue
        with contextlib.suppress(OSError):
            argv = (entry / "cmdline").read_bytes().split(b"\0")
            if b"agent" in argv:
                found.append(int(entry.name))
    return found


def all_exit(pids: list[int], timeout: float) -> bool:
    """Wait until every process of ``pids`` has exited, at most ``timeout`` seconds; whether they all did.

    Event-driven, not polled: a pidfd of each process becomes readable when it exits (Linux 5.3+).
    A zombie (exited, not yet reaped by its new parent) counts as gone, as in :func:`alive`.
    """
    end = time.monotonic() + timeout
    for pid in pids:
        try:
            fd = os.pidfd_open(pid)
        except ProcessLookupError:
            continue
        try:
            while alive(pid):
                remaining = end - time.monotonic()
                if remaining <= 0:
                    return False
                select.select([fd], [], [], min(remaining, 1.0))  # wakes on exit; 1 s bounds the zombie re-check
        finally:
            os.close(fd)
    return True


def start_team(tmp_path: Path, *argv: str) -> tuple[subprocess.Popen[str], list[int]]:
    """``alica run --processes`` in its own process group, once its agents are up; with their pids."""
    command = [sys.executable, "-m", "alica.app.cli", "run", LUNAR, *TEAM, "--processes", "--json", *argv]
    parent = subprocess.Popen(
        command,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        start_new_session=True,
    )
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert parent.stderr is not None
        for line in parent.stderr:
            lines.put(line)
        lines.put("")

    threading.Thread(target=read, daemon=True).start()
    end = time.monotonic() + START_UP
    while True:
        try:
            line = lines.get(timeout=max(0.0, end - time.monotonic()))
        except queue.Empty:
            raise AssertionError("the team did not start in time") from None
        assert line, "the run ended before its agents started"
        if "3 agent processes started" in line:
            break
    agents = agents_of(parent.pid)
    assert len(agents) == 3, agents
    return parent, agents


def kill_group(parent: subprocess.Popen[str]) -> None:
    """Kill the parent's process group (the parent and its agents), then reap the parent."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(parent.pid, signal.SIGKILL)
    parent.wait(timeout=30)


@needs_proc
def test_kill_9_of_the_parent_ends_its_agents(tmp_path):
    parent, agents = start_team(tmp_path, "--time-limit", "120")
    try:
        assert all(alive(pid) for pid in agents)
        os.kill(parent.pid, signal.SIGKILL)  # the parent only: its agents get no signal
        parent.wait(timeout=10)
        assert all_exit(agents, 15.0), [p for p in agents if alive(p)]
    finally:
        kill_group(parent)


@needs_proc
def test_agents_of_a_frozen_parent_end_at_the_runs_deadline(tmp_path):
    from alica.app.processes import DEADLINE_MARGIN

    limit = 8.0
    began = time.monotonic()
    parent, agents = start_team(tmp_path, "--time-limit", repr(limit))
    try:
        os.kill(parent.pid, signal.SIGSTOP)  # alive, so the pipes stay open, but it cannot stop anyone
        gone = all_exit(agents, limit + DEADLINE_MARGIN + 20.0)
        assert gone, [p for p in agents if alive(p)]
        assert time.monotonic() - began >= limit  # they ended at the deadline, not at once
    finally:
        kill_group(parent)


def test_an_agent_whose_parent_pipe_closes_stops_and_says_why(tmp_path):
    argv = [sys.executable, "-m", "alica.app.cli", "agent", LUNAR, "--stand-ins", "--name", "scout"]
    argv += ["--agents", "scout", "--listen", "tcp/127.0.0.1:0", "--key-prefix", "parent-pipe-test"]
    argv += ["--time-limit", "120", "--json", "--parent-pipe", "0"]
    log = tmp_path / "agent.log"
    with log.open("w") as stderr:
        agent = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=stderr, text=True)
    try:
        assert agent.stdin is not None and agent.stdout is not None
        first = agent.stdout.readline()  # the agent ends by itself by --time-limit at the latest
        assert json.loads(first)["event"] == "started", first
        agent.stdin.close()  # as when the parent is gone
        agent.wait(timeout=15)
        out, err = agent.stdout.read(), log.read_text()
        summary = [json.loads(line) for line in out.splitlines() if '"summary"' in line]
        assert summary and summary[-1]["ended"] == "parent gone", (out, err)
        assert "the process that started it is gone" in err
    finally:
        if agent.poll() is None:
            agent.kill()
            agent.wait()


def test_an_agent_refuses_a_parent_pipe_that_is_not_open(capsys):
    argv = ["--name", "scout", "--agents", "scout", "--time-limit", "5", "--parent-pipe", "987"]
    assert main(["agent", LUNAR, "--stand-ins", *argv]) == 1
    assert "--parent-pipe 987" in capsys.readouterr().err


def test_a_run_gives_each_agent_its_deadline_and_its_parent_pipe(tmp_path, monkeypatch):
    from alica.app import processes

    started: list[tuple[list[str], object]] = []

    class Fake:
        def __init__(self, argv: list[str], **kwargs: object) -> None:
            started.append((argv, kwargs.get("stdin")))
            self.pid, self.stdout, self.stdin = 0, iter(()), None

        def poll(self) -> int:
            return 0

    monkeypatch.setattr(processes.subprocess, "Popen", Fake)
    team = processes.ProcessTeam(LUNAR, "scout", ["scout"], [], tmp_path, deadline=30.0)
    team.launch()
    [(argv, stdin)] = started
    assert argv[argv.index("--time-limit") + 1] == repr(30.0 + processes.DEADLINE_MARGIN)
    assert argv[argv.index("--parent-pipe") + 1] == "0" and stdin == subprocess.PIPE


@pytest.mark.parametrize("where", ["a-file/run.jsonl", "a-folder"])
def test_an_unusable_trace_path_is_refused_before_any_agent_starts(tmp_path, monkeypatch, capsys, where):
    from alica.app.processes import ProcessTeam

    (tmp_path / "a-file").write_text("not a folder\n")
    (tmp_path / "a-folder").mkdir()
    launched: list[int] = []
    monkeypatch.setattr(ProcessTeam, "launch", lambda self: launched.append(1))
    trace = tmp_path / where
    code = main(["run", LUNAR, *TEAM, "--processes", "--time-limit", "3", "--trace", str(trace)])
    err = capsys.readouterr().err
    assert code == 1 and not launched, err
    assert f"--trace {trace}:" in err and "[Errno" not in err


def test_alica_agent_does_not_create_the_traces_folder(tmp_path, capsys):
    trace = tmp_path / "missing" / "scout.jsonl"
    argv = ["--name", "scout", "--agents", "scout", "--time-limit", "0.3", "--listen", "tcp/127.0.0.1:0"]
    code = main(["agent", LUNAR, "--stand-ins", *argv, "--key-prefix", "no-folders-test", "--trace", str(trace)])
    err = capsys.readouterr().err
    assert code == 1 and "no such folder" in err, err
    assert not (tmp_path / "missing").exists()


@needs_proc
def test_sigterm_of_the_run_stops_its_agents_and_keeps_the_summary_and_trace(tmp_path):
    parent, agents = start_team(tmp_path, "--time-limit", "120", "--trace", "run.jsonl")
    try:
        parent.send_signal(signal.SIGTERM)  # before: the run died at once, without the merged trace
        assert parent.wait(timeout=30) == 130
        assert all_exit(agents, 15.0), [p for p in agents if alive(p)]
        events = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text(encoding="utf-8").splitlines()]
        assert events[0]["event"] == "trace" and {e.get("agent") for e in events[1:]} >= {"scout", "stummel", "amparo"}
    finally:
        kill_group(parent)
