"""The control center of a team of processes: ``alica run --processes --center`` and ``alica center --team``.

Two blocks-world manipulators with stand-ins, the blocks set by operator facts
at 0 s (a on b, c on the table), plan at run time over zenoh on loopback.
Every wait is bounded: a process's pipe is read with a deadline, a page's
WebSocket until the event a test waits for; every process is stopped in
``finally``.
"""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest

from alica.app.cli import main
from alica.comm.zenoh_transport import free_endpoints
from alica.io import plans_dir
from tests.center.live_run import TOKEN, Live, live_run, stop

PLAN = str(plans_dir() / "blocksworld" / "mission.yaml")
FACTS = "on(a, b) and ontable(b) and ontable(c) and clear(a) and clear(c) and handempty(r1) and handempty(r2)@0"
ROSTER = "r1:Manipulator,r2:Manipulator"
TEAM = [PLAN, "--agents", ROSTER, "--stand-ins", "--fact", FACTS]
"""Two manipulators stacking a, b and c; about 6 s without review."""


def _proposal(e: dict[str, Any]) -> bool:
    return e["event"] == "proposal" and "error" not in e


def _plan_shared(e: dict[str, Any]) -> bool:
    return e["event"] == "planner" and e.get("what") == "plan"


def test_a_team_of_processes_is_shown_live_until_it_ends() -> None:
    with live_run(*TEAM, "--processes", "--crash", "r2@2.5", "--recover", "r2@3.5", "--time-limit", "40") as live:
        hello = live.connect()
        assert hello["type"] == "hello" and hello["meta"]["mode"] == "live"
        assert hello["meta"]["agents"] == ["r1", "r2"]
        assert hello["meta"]["problems"]["StackBlocks"]["predicates"]["on"] == 2
        assert live.request("api/meta")[1]["agents"] == ["r1", "r2"]
        # every agent's events come, and the state folds them agent by agent
        for name in ("r1", "r2"):
            live.until(lambda e, name=name: e["event"] == "allocation" and e["agent"] == name, timeout=20)
        live.until(_plan_shared, timeout=20)
        state = live.until_state(lambda s: all(a["plans"] for a in s["agents"].values()), timeout=20)
        assert state["agents"]["r1"]["plans"][0]["plan"] == "BlocksWorldMission"
        assert "StackBlocks" in state["operator"]["running"]
        # the kill -9 and the restart come from this process; the new r2 process's history comes again
        live.until(lambda e: e["event"] == "fault" and e["fault"] == "crash" and e["agent"] == "r2", timeout=20)
        live.until(lambda e: e["event"] == "fault" and e["fault"] == "recover" and e["agent"] == "r2", timeout=20)
        live.until(lambda e: e["event"] == "note" and e["message"].startswith("a new process of r2"), timeout=20)
        # the team ends: the page shows the run's summary and stays up
        done = live.until_state(lambda s: not s["status"]["running"], timeout=30)
        summary = done["status"]["summary"]
        assert summary["processes"] and summary["success"], summary
        assert {a["status"] for a in summary["agents"].values()} == {"success"}
        assert live.request("api/meta")[0] == 200


def test_the_operator_reviews_the_plans_of_a_team_of_processes() -> None:
    with live_run(*TEAM, "--processes", "--review", "--time-limit", "40") as live:
        live.connect()
        first = live.until(_proposal, timeout=20)
        assert first["generation"] == 1 and first["steps"]
        assert not any(_plan_shared(e) for e in live.events)  # nothing runs before the operator decides
        status, answer = live.request("api/decide", {"problem": "StackBlocks", "generation": 1, "action": "accept"})
        assert status == 200 and answer["ok"], answer
        shared = live.until(lambda e: _plan_shared(e) and e["generation"] == 1, timeout=20)
        assert shared["agent"] == first["leader"]
        assert any(e["event"] == "operator" and e["what"] == "accept" for e in live.events)
        # a new goal: the leader plans again, for it
        goal = "on(c, a) and ontable(a)"
        status, answer = live.request("api/goal", {"problem": "StackBlocks", "goal": goal})
        assert status == 200 and answer["ok"], answer
        again = live.until(lambda e: _proposal(e) and e["goal"] == goal, timeout=20)
        assert again["generation"] > 1
        # facts reach the agents' world models; a bad goal is refused with its reason
        assert live.request("api/facts", {"facts": "checked(a)"})[0] == 200
        live.until(lambda e: e["event"] == "operator" and e["what"] == "facts", timeout=10)
        status, refused = live.request("api/goal", {"problem": "Nope", "goal": goal})
        assert status == 400 and "no planning problem named 'Nope'" in refused["error"]


class _Lines:
    """A process's standard output, read by a thread: lines are taken with a deadline."""

    def __init__(self, process: subprocess.Popen[str]) -> None:
        self.queue: queue.Queue[str] = queue.Queue()
        assert process.stdout is not None
        stream = process.stdout
        threading.Thread(target=lambda: [self.queue.put(line) for line in stream], daemon=True).start()

    def line(self, timeout: float) -> str:
        try:
            return self.queue.get(timeout=timeout)
        except queue.Empty:
            raise AssertionError(f"no line within {timeout} s") from None


@contextmanager
def _agents(*extra: str) -> Iterator[list[str]]:
    """Two ``alica agent`` processes (r2 connects to r1) under --review: they wait for the operator; their endpoints."""
    endpoints = free_endpoints(2)
    start = repr(time.time())
    processes = []
    try:
        for index, name in enumerate(("r1", "r2")):
            argv = [sys.executable, "-m", "alica.app.cli", "agent", *TEAM, "--name", name, "--start-at", start]
            argv += ["--listen", endpoints[index], "--time-limit", "40", "--review", "--json", *extra]
            if index:
                argv += ["--connect", endpoints[0]]
            processes.append(
                subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
            )
        for process in processes:
            assert json.loads(_Lines(process).line(30))["event"] == "started"
        yield endpoints
    finally:
        for process in processes:
            stop(process)


@contextmanager
def _center(*argv: str) -> Iterator[Live]:
    """``alica center ARGV`` on a free port, with the test's token; its address read with a deadline."""
    process = subprocess.Popen(
        [sys.executable, "-m", "alica.app.cli", "center", *argv, "--port", "0", "--token", TOKEN],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        url = _Lines(process).line(30).strip()
        assert url.startswith("http://127.0.0.1:"), url
        live = Live(url, process)
        try:
            yield live
        finally:
            live.stack.close()
    finally:
        stop(process)


def test_a_center_that_joins_late_gets_the_history_and_decides() -> None:
    with _agents() as endpoints:
        with _center("--team", endpoints[0]) as early:
            early.connect()
            proposal = early.until(_proposal, timeout=20)  # the team is under way before the late center joins
            for name in ("r1", "r2"):  # each agent's events come as they come: r2's may follow r1's proposal
                early.until(lambda e, name=name: e["event"] == "allocation" and e["agent"] == name, timeout=20)
            with _center("--team", endpoints[1]) as late:
                hello = late.connect()
                assert hello["meta"]["agents"] == ["r1", "r2"]
                late.until(lambda e: _proposal(e) and e["generation"] == proposal["generation"], timeout=10)
                histories = [e for e in late.events if e["event"] == "note" and "history" in e["message"]]
                assert {m["message"].split("'")[0] for m in histories} == {"r1", "r2"}
                joined = max(m["t"] for m in histories)
                old = {e["agent"] for e in late.events if e["event"] == "allocation" and e["t"] < joined}
                assert old == {"r1", "r2"}  # allocations from before it joined, from both agents
                assert late.state["operator"]["proposals"]["StackBlocks"]["generation"] == proposal["generation"]
                # the late center's decision reaches the team: the plan runs, and both pages see it
                body = {"problem": "StackBlocks", "generation": proposal["generation"], "action": "accept"}
                assert late.request("api/decide", body)[0] == 200
                late.until(_plan_shared, timeout=20)
                early.until(_plan_shared, timeout=20)
        # a key prefix no agent has: one clear line, exit 1, bounded by --wait
        wrong = subprocess.run(
            [sys.executable, "-m", "alica.app.cli", "center", "--team", endpoints[0], "--key-prefix", "other"]
            + ["--wait", "2", "--port", "0"],
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert wrong.returncode == 1
        assert wrong.stdout == ""
        assert wrong.stderr.strip().splitlines() == [
            PLAIN,
            f"alica: error: no agent of the team answered within 2 s at {endpoints[0]}: "
            "no agent with the key prefix 'other' is there (the agents' --key-prefix)",
        ]


PLAIN = "alica center: no team credentials (--team-keys): unauthenticated and unencrypted, on loopback only"
"""What a center without credentials says first (issue 37)."""


def _center_fails(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "alica.app.cli", "center", *argv, "--port", "0"],
        capture_output=True,
        text=True,
        timeout=30,
    )


def test_a_center_refuses_an_endpoint_nothing_listens_on_and_a_bad_prefix() -> None:
    (endpoint,) = free_endpoints(1)
    began = time.monotonic()
    nobody = _center_fails("--team", endpoint)
    assert time.monotonic() - began < 20
    assert nobody.returncode == 1 and nobody.stdout == ""
    lines = nobody.stderr.strip().splitlines()
    assert len(lines) == 2 and lines[0] == PLAIN
    assert lines[1].startswith(f"alica: error: cannot reach the team at {endpoint}: ")
    bad = _center_fails("--team", endpoint, "--key-prefix", "a/b")
    assert bad.returncode == 1
    assert "key prefix must be a non-empty name without '/'" in bad.stderr
    assert bad.stderr.strip().splitlines()[0] == PLAIN and len(bad.stderr.strip().splitlines()) == 2
    misplaced = _center_fails("--plan", PLAN, "--key-prefix", "x")
    assert misplaced.returncode == 1 and "--key-prefix go(es) with --team" in misplaced.stderr
    keys = _center_fails("--plan", PLAN, "--team-keys", "keys", "--wait", "3")
    assert keys.returncode == 1 and "--wait and --team-keys go(es) with --team" in keys.stderr
    not_an_endpoint = _center_fails("--team", "localhost")
    assert not_an_endpoint.returncode == 1 and "looks like 'tcp/127.0.0.1:7447'" in not_an_endpoint.stderr


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--show-tree"], "--center shows the team in a web page; it does not go with --show-tree"),
        (["--speed", "2"], "--speed only work in the simulated run"),
    ],
)
def test_a_process_run_with_the_center_refuses_what_does_not_fit(capsys, argv, message) -> None:  # type: ignore[no-untyped-def]
    assert main(["run", *TEAM, "--processes", "--center", "--center-port", "0", *argv]) == 1
    assert message in capsys.readouterr().err
