"""The control center follows a hot reload (issue 39): the reload action, the log's reload lines, the plan tree.

The hub's side is tested on its own (:meth:`LiveHub.offer` and the ``adopted`` event switch the trees it
serves); the pages in headless Chromium (skipped where Playwright or the browser is missing) on a live
``alica run --center`` whose plan file is edited while it runs; a team of processes over HTTP.
Every wait is bounded (Playwright's ``wait_for_*``, the WebSocket's deadlines).
"""

from __future__ import annotations

import json
import re
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from alica.app.center.live import LiveHub, LiveSession
from alica.app.center.plan_view import trace_trees
from alica.app.center.server import live_app
from alica.app.center.team_view import TeamView
from alica.errors import AlicaError
from alica.io import Loader
from alica.model import PlanLibrary
from alica.model.digest import library_digest
from tests.center.live_run import TOKEN, live_run
from tests.conftest import PLANS

TEAM = (PLANS / "examples" / "gate.yaml").read_text(encoding="utf-8")  # the hot-reload example
"""Two workers wait in Gate's Waiting on ``go``, which nothing sets: the run goes on until it is stopped."""

WAITING = '          - {to: Passed, condition: "go"}\n'
PASSED = "      - {name: Passed, kind: success}\n"


def with_extra(text: str = TEAM) -> str:
    """The team with a state Extra in Gate that Waiting goes to at once."""
    return text.replace(WAITING, WAITING + '          - {to: Extra, condition: "true"}\n').replace(
        PASSED, PASSED + "      - {name: Extra}\n"
    )


def with_typo(text: str = TEAM) -> tuple[str, int, int]:
    """The team with the predicate ``go`` misspelt, and the line and column of the misspelling."""
    broken = text.replace('condition: "go"}', 'condition: "gox"}')
    offset = broken.index('"gox"') + 1
    line = broken.count("\n", 0, offset) + 1
    return broken, line, offset - broken.rfind("\n", 0, offset)


def _library(folder: Path, text: str) -> PlanLibrary:
    path = folder / f"team{len(list(folder.glob('*.yaml')))}.yaml"
    path.write_text(text, encoding="utf-8")
    return Loader().load(path)


def _hub(folder: Path) -> tuple[LiveHub, PlanLibrary, PlanLibrary]:
    """A hub serving the trees of the team, and the team and the team with Extra as libraries."""
    old, new = _library(folder, TEAM), _library(folder, with_extra())
    header = {"plans": ["team.yaml"], "root": "Top", "agents": {"a": {"role": "Worker", "plan": "Top"}}}
    hub = LiveHub(header, TeamView(header), old)
    hub.serve_trees(trace_trees(header, folder / "trace", loaded=([old], ["a note on the plan files"])))
    return hub, old, new


def _adopted(old: PlanLibrary, new: PlanLibrary, agent: str = "a") -> dict[str, Any]:
    return {
        "t": 1.0,
        "agent": agent,
        "event": "reload",
        "status": "adopted",
        "library": library_digest(old),
        "adopted": library_digest(new),
        "changes": {"changed": ["plan Gate"]},
        "restarted": [],
    }


def _gate_states(trees: dict[str, Any]) -> list[str]:
    gate = trees["trees"]["Top"]["states"][0]["children"][0]
    return [s["name"] for s in gate["states"]]


# -- the hub -------------------------------------------------------------------------------------


def test_an_offered_library_is_served_once_an_agent_adopts_it(tmp_path: Path) -> None:
    hub, old, new = _hub(tmp_path)
    assert hub.trees()["plans"] == library_digest(old)
    assert _gate_states(hub.trees()) == ["Waiting", "Passed"]
    hub.offer(new)
    assert _gate_states(hub.trees()) == ["Waiting", "Passed"]  # offered is not adopted: the team may never agree
    before = json.loads(hub.snapshot_json())
    assert before["plans"] == library_digest(old)
    hub(_adopted(old, new))
    trees = hub.trees()
    assert trees["plans"] == library_digest(new)
    assert _gate_states(trees) == ["Waiting", "Passed", "Extra"]
    assert trees["agents"] == {"a": "Top"}
    assert trees["notes"] == ["a note on the plan files"]  # the notes on the files stay
    assert json.loads(hub.snapshot_json())["plans"] == library_digest(new)
    assert hub.missing() is None


def test_an_adoption_heard_before_the_offer_switches_when_the_library_comes(tmp_path: Path) -> None:
    hub, old, new = _hub(tmp_path)
    hub(_adopted(old, new))
    assert hub.missing() == library_digest(new)  # a team of processes loads the files then
    assert hub.trees()["plans"] == library_digest(old)
    hub.offer(new)
    assert hub.missing() is None
    assert _gate_states(hub.trees()) == ["Waiting", "Passed", "Extra"]
    assert json.loads(hub.snapshot_json())["plans"] == library_digest(new)  # the pages learn of it with no event


def test_other_reload_events_and_a_second_agents_adoption_change_nothing(tmp_path: Path) -> None:
    hub, old, new = _hub(tmp_path)
    hub.offer(new)
    proposed = {**_adopted(old, new), "status": "proposed", "proposed": library_digest(new)}
    hub(proposed)
    hub({**_adopted(old, new), "status": "waiting", "differ": {"b": library_digest(old)}})
    assert hub.trees()["plans"] == library_digest(old)
    hub(_adopted(old, new, "a"))
    served = hub.trees()
    hub(_adopted(old, new, "b"))
    assert hub.trees() == served
    hub({**_adopted(new, old), "adopted": 12})  # not a digest: ignored
    assert hub.trees() == served


def test_the_entry_states_follow_the_adopted_library(tmp_path: Path) -> None:
    hub, old, _ = _hub(tmp_path)
    start = '    states:\n      - name: Start\n        transitions:\n          - {to: Waiting, condition: "go"}\n'
    moved_text = TEAM.replace("state: Waiting, min", "state: Start, min").replace("    states:\n", start, 1)
    moved = _library(tmp_path, moved_text)
    hub.offer(moved)
    hub(_adopted(old, moved))
    hub(
        {
            "t": 2.0,
            "agent": "a",
            "event": "allocation",
            "key": "Top/Work/Gate",
            "plan": "Gate",
            "entries": {"a": "Default"},
        }
    )
    assert json.loads(hub.snapshot_json())["agents"]["a"]["state"] == "Start"


# -- the reload action ------------------------------------------------------------------------------


def _client(hub: LiveHub, reload: Callable[[Any], dict[str, Any]] | None) -> TestClient:
    app = live_app(hub, {}, TOKEN, {"trees": {}, "agents": {}, "notes": []}, reload=reload)
    return TestClient(app, headers={"Authorization": f"Bearer {TOKEN}"})


def _on_the_teams_thread(hub: LiveHub, team: object) -> threading.Event:
    """Run the hub's queued actions on ``team`` until the returned event is set (as the team's loop does)."""
    stop = threading.Event()

    def loop() -> None:
        while not stop.wait(0.01):
            hub.run_commands(team)

    threading.Thread(target=loop, daemon=True).start()
    return stop


def test_the_reload_action_runs_on_the_teams_thread_and_answers_with_the_outcome(tmp_path: Path) -> None:
    hub, _, _ = _hub(tmp_path)
    team = object()
    called: list[tuple[object, str]] = []

    def reload(given: object) -> dict[str, Any]:
        called.append((given, threading.current_thread().name))
        return {"ok": False, "errors": ["team.yaml:19:38: error: unknown predicate 'gox'"]}

    stop = _on_the_teams_thread(hub, team)
    try:
        with _client(hub, reload) as client:
            answer = client.post("/api/reload", json={})
            refused = client.post("/api/reload", content=b"[]", headers={"Content-Type": "application/json"})
            meta = client.get("/api/meta").json()
    finally:
        stop.set()
    assert answer.status_code == 200
    assert answer.json() == {
        "ok": True,
        "result": {"ok": False, "errors": ["team.yaml:19:38: error: unknown predicate 'gox'"]},
    }
    assert refused.status_code == 400 and "JSON object" in refused.json()["error"]
    assert len(called) == 1 and called[0][0] is team and called[0][1] != threading.main_thread().name
    assert meta["reload"] is True


def test_a_center_that_cannot_reload_says_why(tmp_path: Path) -> None:
    hub, _, _ = _hub(tmp_path)
    with _client(hub, None) as client:
        answer = client.post("/api/reload", json={})
        assert client.get("/api/meta").json()["reload"] is False
    assert answer.status_code == 409
    assert "cannot load the team's plan files again" in answer.json()["error"]
    session = LiveSession()  # a demo's session: its plans are not read from files it watches
    with pytest.raises(AlicaError, match="cannot load its plan files again"):
        session.reload(object())


# -- the live page ----------------------------------------------------------------------------------


def _watched_run(plan: Path, *extra: str) -> Any:
    return live_run(str(plan), "--agents", "a:Worker,b:Worker", "--time-limit", "600", *extra)


@pytest.mark.optional
def test_the_live_page_shows_a_watched_reload_in_its_log_and_the_new_state_in_its_tree(tmp_path: Path) -> None:
    from tests.center.test_browser import _browser_or_skip, _page

    _browser_or_skip()
    plan = tmp_path / "team.yaml"
    plan.write_text(TEAM, encoding="utf-8")
    with _watched_run(plan, "--watch") as live, _page(live.url, 1400, 1000) as page:
        page.wait_for_selector('#trees-body li.state.current[data-state="Waiting"]', timeout=20_000)
        assert page.locator('#trees-body li.state[data-state="Extra"]').count() == 0
        before = page.get_attribute("#trees-body", "data-plans")
        plan.write_text(with_extra(), encoding="utf-8")
        page.wait_for_selector('#log-body tr[data-kind="reload"]:has-text("reload adopted")', timeout=30_000)
        line = page.locator('#log-body tr[data-kind="reload"]:has-text("reload adopted")').first.inner_text()
        assert "(changed plan Gate)" in line and f"{before[:4]}\u2026 ->" in line
        page.wait_for_selector('#trees-body li.state[data-state="Extra"]', timeout=20_000)
        page.wait_for_selector('#trees-body li.state.current[data-state="Extra"]', timeout=20_000)
        assert page.get_attribute("#trees-body", "data-plans") not in (None, "", before)
        assert page.locator('#log-body tr[data-kind="reload"]:has-text("reload proposed")').count() >= 2


@pytest.mark.optional
def test_the_reload_button_shows_the_located_error_then_the_new_digest_and_the_run_goes_on(tmp_path: Path) -> None:
    from tests.center.test_browser import _browser_or_skip, _page

    _browser_or_skip()
    plan = tmp_path / "team.yaml"
    plan.write_text(TEAM, encoding="utf-8")
    with _watched_run(plan, "--speed", "1") as live, _page(live.url, 1400, 1000) as page:
        page.wait_for_selector('#trees-body li.state.current[data-state="Waiting"]', timeout=20_000)
        broken, line, column = with_typo()
        plan.write_text(broken, encoding="utf-8")
        page.click("#reload")
        page.wait_for_selector('#reload-result[data-outcome="invalid"]', timeout=20_000)
        shown = page.inner_text("#reload-result")
        assert f"team.yaml:{line}:{column}:" in shown and "gox" in shown
        page.wait_for_selector('#log-body tr[data-kind="reload"]:has-text("reload invalid: ")', timeout=20_000)
        # the run goes on with the plans it has: still running, the clock moves, the agents still wait
        status = page.inner_text("#status")
        assert "running" in status
        t0 = float(status.split("=")[1].split("s")[0])
        page.wait_for_function(
            f"parseFloat(document.getElementById('status').textContent.split('=')[1]) > {t0 + 1}", timeout=20_000
        )
        assert page.locator('#trees-body li.state.current[data-state="Waiting"]').count() == 2
        plan.write_text(with_extra(), encoding="utf-8")
        page.click("#reload")
        page.wait_for_selector('#reload-result[data-outcome="ok"]', timeout=20_000)
        shown = page.inner_text("#reload-result")
        digest = shown.split("plans ", 1)[1].split(" ", 1)[0]
        assert len(digest) == 16
        page.wait_for_selector(f'#trees-body[data-plans="{digest}"]', timeout=30_000)
        page.wait_for_selector('#trees-body li.state.current[data-state="Extra"]', timeout=20_000)


# -- a team of processes ----------------------------------------------------------------------------


def test_a_team_of_processes_reloads_from_the_center_and_its_trees_follow(tmp_path: Path) -> None:
    pytest.importorskip("zenoh", reason="a team of processes talks over zenoh")
    plan = tmp_path / "team.yaml"
    plan.write_text(TEAM, encoding="utf-8")
    with _watched_run(plan, "--processes") as live:
        live.connect()
        live.until(lambda e: e.get("agent") == "a" and e.get("event") == "allocation")
        live.until(lambda e: e.get("agent") == "b" and e.get("event") == "allocation")
        plan.write_text(with_extra(), encoding="utf-8")
        status, answer = live.request("api/reload", {})
        assert status == 200 and answer["ok"] and answer["result"]["ok"], answer
        digest = answer["result"]["digest"]
        assert sorted(answer["result"]["sent"]) == ["a", "b"]
        for agent in ("a", "b"):
            live.until(
                lambda e, agent=agent: (
                    e.get("event") == "reload"
                    and e.get("status") == "adopted"
                    and e.get("agent") == agent
                    and e.get("adopted") == digest
                )
            )
        live.until_state(lambda state: state.get("plans") == digest, timeout=20.0)
        status, trees = live.request("api/trees")
        assert status == 200 and trees["plans"] == digest
        assert _gate_states(trees) == ["Waiting", "Passed", "Extra"]


def test_the_trees_of_a_watched_team_of_processes_follow_an_edit_without_the_action(tmp_path: Path) -> None:
    pytest.importorskip("zenoh", reason="a team of processes talks over zenoh")
    plan = tmp_path / "team.yaml"
    plan.write_text(TEAM, encoding="utf-8")
    with _watched_run(plan, "--processes", "--watch") as live:
        live.connect()
        live.until(lambda e: e.get("agent") == "b" and e.get("event") == "allocation")
        first = live.state["plans"]
        plan.write_text(with_extra(), encoding="utf-8")
        adopted = live.until(lambda e: e.get("event") == "reload" and e.get("status") == "adopted")
        assert adopted["library"] == first
        # the agents adopted a library the center was not offered: it loads the files itself, once
        live.until_state(lambda state: state.get("plans") == adopted["adopted"], timeout=20.0)
        status, trees = live.request("api/trees")
        assert status == 200 and _gate_states(trees) == ["Waiting", "Passed", "Extra"]


def test_a_center_that_joined_a_team_reloads_it_and_its_trees_follow(tmp_path: Path) -> None:
    pytest.importorskip("zenoh", reason="a team of processes talks over zenoh")
    import subprocess
    import sys
    import time

    from alica.comm.zenoh_transport import free_endpoints
    from tests.center.live_run import Live, stop
    from tests.center.test_team_feed import _Lines

    (tmp_path / "team.yaml").write_text(TEAM, encoding="utf-8")
    endpoints, start = free_endpoints(2), repr(time.time())
    processes: list[subprocess.Popen[str]] = []

    def spawn(*argv: str) -> subprocess.Popen[str]:
        process = subprocess.Popen(
            [sys.executable, "-m", "alica.app.cli", *argv],
            cwd=tmp_path,  # the header names team.yaml as the agents' command lines did: the center reads it here
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            bufsize=1,
        )
        processes.append(process)
        return process

    try:
        for index, name in enumerate(("a", "b")):
            argv = ["agent", "team.yaml", "--agents", "a:Worker,b:Worker", "--name", name, "--start-at", start]
            argv += ["--listen", endpoints[index], "--time-limit", "120", "--json"]
            argv += ["--connect", endpoints[0]] if index else []
            assert json.loads(_Lines(spawn(*argv)).line(30))["event"] == "started"
        center = spawn("center", "--team", endpoints[0], "--port", "0", "--token", TOKEN)
        url = _Lines(center).line(30).strip()
        assert url.startswith("http://127.0.0.1:"), url
        live = Live(url, center)
        try:
            live.connect()
            for agent in ("a", "b"):
                live.until(lambda e, agent=agent: e.get("agent") == agent and e.get("event") == "allocation")
            first = live.state["plans"]
            assert first is not None  # the center loaded the header's plan file
            (tmp_path / "team.yaml").write_text(with_extra(), encoding="utf-8")
            status, answer = live.request("api/reload", {})
            assert status == 200 and answer["result"]["ok"], answer
            digest = answer["result"]["digest"]
            assert digest != first and sorted(answer["result"]["sent"]) == ["a", "b"]
            live.until(lambda e: e.get("event") == "reload" and e.get("status") == "adopted" and e["adopted"] == digest)
            live.until_state(lambda state: state.get("plans") == digest, timeout=20.0)
            assert _gate_states(live.request("api/trees")[1]) == ["Waiting", "Passed", "Extra"]
        finally:
            live.stack.close()
    finally:
        for process in processes:
            stop(process)


@pytest.mark.optional
def test_a_replay_shows_each_kind_of_reload_event_as_a_line(tmp_path: Path) -> None:
    import contextlib

    from tests.center.test_browser import _browser_or_skip, _page, _serve, _slide_to

    _browser_or_skip()
    old, new = "dc5abc3e56d5c033", "0e03a1f4c2b7d955"
    header = {"t": 0.0, "agent": "-", "event": "trace", "format": "alica-trace", "version": 2}
    header["agents"] = {"a": {"role": "Worker", "plan": "Top"}, "b": {"role": "Worker", "plan": "Top"}}
    reload = {"agent": "a", "event": "reload"}
    events = [
        header,
        {**reload, "t": 1.0, "agent": "-", "status": "invalid", "errors": ["team.yaml:19:38: error: unknown 'gox'"]},
        {
            **reload,
            "t": 2.0,
            "status": "proposed",
            "library": old,
            "proposed": new,
            "changes": {"changed": ["plan Gate"]},
        },
        {**reload, "t": 2.5, "status": "waiting", "library": old, "proposed": new, "differ": {"b": old}},
        {**reload, "t": 3.0, "status": "agreed", "proposed": new, "at": 3.5},
        {
            **reload,
            "t": 3.5,
            "status": "adopted",
            "library": old,
            "adopted": new,
            "changes": {"changed": ["plan Gate"]},
        },
        {**reload, "t": 3.5, "key": "Top/Work/Gate", "note": "state Gone was removed: the agent goes to Waiting"},
    ]
    trace = tmp_path / "reload.jsonl"
    trace.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    with contextlib.contextmanager(_serve)("--trace", str(trace)) as url, _page(url, 1280, 900) as page:
        _slide_to(page, "max")
        page.wait_for_function(
            "document.querySelectorAll('#log-body tr[data-kind=reload]').length === 6", timeout=10_000
        )
        rows = page.locator("#log-body tr[data-kind=reload]").all_inner_texts()
        lines = [re.sub(r"^\s*[\d.]+ s  \S+\s+", "", row) for row in rows]  # without the time and the agent
    assert lines[::-1] == [
        "reload invalid: team.yaml:19:38: error: unknown 'gox'",
        "reload proposed dc5a\u2026 -> 0e03\u2026 (changed plan Gate)",
        "reload waiting: b has dc5a\u2026 (not 0e03\u2026; the team goes on with dc5a\u2026)",
        "reload agreed on 0e03\u2026 at t=3.50",
        "reload adopted dc5a\u2026 -> 0e03\u2026 (changed plan Gate)",
        "reload Top/Work/Gate: state Gone was removed: the agent goes to Waiting",
    ]
