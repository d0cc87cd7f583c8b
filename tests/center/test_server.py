"""The control center's server: the token, the replay API, the plan view, and the start-up line."""

from __future__ import annotations

import json
import re
import urllib.request
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from alica.app.center.cli import plan_views
from alica.app.center.replay import Replay
from alica.app.center.server import cookie_name, plan_app, replay_app
from alica.app.center.trace_file import load_trace
from alica.io import plans_dir

from .conftest import TOKEN
from .live_run import serving

COOKIE = cookie_name(80)
"""The token cookie of a center reached as TestClient does (http://testserver, port 80)."""


def _client(trace: Path) -> TestClient:
    return TestClient(replay_app(Replay(load_trace(trace)), TOKEN))


@pytest.mark.parametrize("path", ["/", "/api/meta", "/api/state?t=0", "/api/events", "/static/replay.js"])
def test_every_request_without_the_token_is_refused(written_trace: Path, path: str) -> None:
    client = _client(written_trace)
    assert client.get(path).status_code == 403
    assert client.get(path + ("&" if "?" in path else "?") + "token=wrong").status_code == 403
    assert client.get(path, headers={"Authorization": "Bearer wrong"}).status_code == 403


def test_the_token_opens_the_page_and_sets_a_cookie_for_the_rest(written_trace: Path) -> None:
    client = _client(written_trace)
    page = client.get(f"/?token={TOKEN}")
    assert page.status_code == 200
    assert "alica control center" in page.text
    assert client.cookies.get(COOKIE) == TOKEN
    assert client.get("/api/meta").status_code == 200  # the cookie alone
    assert client.get("/static/replay.js").status_code == 200
    assert client.get("/static/style.css").status_code == 200


def test_a_websocket_without_the_token_is_closed_unaccepted(written_trace: Path) -> None:
    from starlette.websockets import WebSocketDisconnect

    with pytest.raises(WebSocketDisconnect) as closed, _client(written_trace).websocket_connect("/ws"):
        pass
    assert closed.value.code == 1008


def test_a_bearer_header_is_enough(written_trace: Path) -> None:
    client = _client(written_trace)
    response = client.get("/api/meta", headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 200


def test_meta_and_state_of_a_recorded_run(recorded_trace: Path) -> None:
    client = _client(recorded_trace)
    client.cookies.set(COOKIE, TOKEN)
    meta = client.get("/api/meta").json()
    assert meta["agents"] == ["r1", "r2", "r3"]
    assert meta["kinds"]["allocation"] >= 3
    assert meta["kinds"]["fault"] >= 1
    assert meta["poses"] is False
    assert meta["duration"] > 0
    start = client.get(f"/api/state?t={meta['start']}").json()["agents"]
    assert start["r1"]["plan"] == "Formation"
    assert start["r1"]["task"] is not None
    assert all(a["alive"] for a in start.values())
    end = client.get(f"/api/state?t={meta['end']}").json()["agents"]
    assert end["r2"]["alive"] is False
    assert end["r1"]["alive"] is True
    fault = client.get("/api/next?kind=fault&after=0").json()["t"]
    assert fault == pytest.approx(1.0, abs=0.2)


def test_state_follows_transitions_crashes_and_header_roles(written_trace: Path) -> None:
    client = _client(written_trace)
    client.cookies.set(COOKIE, TOKEN)
    before = client.get("/api/state?t=0.9").json()["agents"]
    a = before["a"]
    assert (a["role"], a["task"], a["alive"], a["plan"], a["state"], a["key"]) == (
        "Scout",
        "Go",
        True,
        "Top",
        None,
        "Top",
    )
    assert a["pose"] == {"x": 0.0, "y": 0.0, "yaw": 0.0}
    assert before["b"]["role"] == "Stummel"  # from the header's agents
    after = client.get("/api/state?t=3.5").json()["agents"]
    assert after["a"]["state"] == "S2"
    assert after["a"]["pose"] == {"x": 1.0, "y": 2.0, "yaw": 0.5}
    assert after["b"]["alive"] is False
    assert client.get("/api/meta").json()["poses"] is True


def test_next_replan_jumps_from_replan_to_replan(written_trace: Path) -> None:
    client = _client(written_trace)
    client.cookies.set(COOKIE, TOKEN)
    assert client.get("/api/next?kind=replan&after=0").json()["t"] == 2.0
    assert client.get("/api/next?kind=replan&after=2.0").json()["t"] == 4.0
    assert client.get("/api/next?kind=replan&after=4.0").json()["t"] is None
    assert client.get("/api/next?kind=fault&after=0").json()["t"] == 3.0
    assert client.get("/api/next?kind=nonsense").status_code == 400
    assert client.get("/api/next?kind=replan&after=soon").status_code == 400


def test_events_by_window_and_kind(written_trace: Path) -> None:
    client = _client(written_trace)
    client.cookies.set(COOKIE, TOKEN)
    everything = client.get("/api/events").json()["events"]
    assert len(everything) == 9
    window = client.get("/api/events?start=1&end=3&kinds=replan,fault").json()["events"]
    assert [(e["t"], e["event"]) for e in window] == [(2.0, "replan"), (3.0, "fault"), (3.0, "fault")]


@pytest.mark.parametrize(
    ("file", "root", "expected"),
    [
        ("examples/formation.yaml", "Formation", ["plan", "state"]),
        ("blocksworld/mission.yaml", None, ["plan", "state", "problem"]),
    ],
)
def test_the_plan_view_draws_a_plan_file(file: str, root: str | None, expected: list[str]) -> None:
    path = str(plans_dir() / file)
    trees, svgs = plan_views(path)
    if root is not None:
        assert list(trees) == [root]
    client = TestClient(plan_app(path, trees, svgs, TOKEN))
    assert client.get("/api/plan").status_code == 403
    client.cookies.set(COOKIE, TOKEN)
    assert "plan file" in client.get("/").text
    data = client.get("/api/plan").json()
    assert data["roots"] == list(trees)
    tree = data["trees"][data["roots"][0]]
    assert tree["kind"] == "plan"
    assert tree["states"]
    response = client.get("/api/plan.svg")
    assert response.headers["content-type"].startswith("image/svg+xml")
    text = response.text
    assert text.startswith("<svg")
    for kind in expected:
        assert f'class="{kind}"' in text
    for state in tree["states"]:
        assert f'data-state="{state["name"]}"' in text
    assert client.get("/api/plan.svg?root=Nothing").status_code == 404


def test_the_start_up_line_names_the_real_port_and_the_page_loads(recorded_trace: Path) -> None:
    with serving(["center", "--trace", str(recorded_trace), "--port", "0"]) as (line, _):
        match = re.fullmatch(r"http://127\.0\.0\.1:(\d+)/\?token=([A-Za-z0-9_-]{20,})", line)
        assert match, line
        assert int(match.group(1)) > 0
        with urllib.request.urlopen(line, timeout=10) as response:
            assert response.status == 200
            assert "alica control center" in response.read().decode()
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(f"http://127.0.0.1:{match.group(1)}/api/meta", timeout=10)
        assert refused.value.code == 403


def test_a_blocks_world_demo_trace_replays(tmp_path: Path) -> None:
    from alica.app.cli import main

    assert main(["demo", "blocksworld", "--robots", "2", "--blocks", "3", "--seed", "1", "--out", str(tmp_path)]) == 0
    client = _client(tmp_path / "trace.jsonl")
    client.cookies.set(COOKIE, TOKEN)
    meta = client.get("/api/meta").json()
    assert meta["agents"] == ["r1", "r2"]
    assert meta["kinds"]["planner"] >= 1
    agents = client.get(f"/api/state?t={meta['end']}").json()["agents"]
    assert {a["plan"] for a in agents.values()} <= {
        *(e["plan"] for e in client.get("/api/events?kinds=allocation,transition").json()["events"])
    }
    assert all(a["plan"] for a in agents.values())


def test_the_page_files_are_package_data() -> None:
    import fnmatch
    import tomllib

    root = Path(__file__).resolve().parents[2]
    config = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    globs = config["package-data"]["alica.app.center"]
    static = root / "alica" / "app" / "center" / "static"
    files = [p.relative_to(static.parent).as_posix() for p in static.iterdir()]
    assert {"static/replay.html", "static/replay.js", "static/plan.html", "static/style.css"} <= set(files)
    for name in files:
        assert any(fnmatch.fnmatch(name, g) for g in globs), f"{name} is not in the wheel's package data"


def test_a_transition_above_leaves_the_plans_below_and_a_recovery_starts_afresh() -> None:
    from alica.app.center.trace_file import Trace

    def allocation(t: float, key: str, plan: str, task: str) -> dict[str, object]:
        return {"t": t, "agent": "a", "event": "allocation", "key": key, "plan": plan, "entries": {"a": task}}

    events = [
        allocation(0.0, "Top", "Top", "Lead"),
        {"t": 1.0, "agent": "a", "event": "transition", "key": "Top", "plan": "Top", "source": "S1", "target": "S2"},
        allocation(1.0, "Top/S2/Sub", "Sub", "Carry"),
        {"t": 2.0, "agent": "a", "event": "transition", "key": "Top/S2/Sub", "plan": "Sub", "target": "Lift"},
        allocation(2.5, "Top", "Top", "Lead"),  # a reallocation above does not leave Sub
        {"t": 3.0, "agent": "a", "event": "transition", "key": "Top", "plan": "Top", "source": "S2", "target": "S3"},
        {"t": 4.0, "agent": "a", "event": "fault", "fault": "crash"},
        {"t": 5.0, "agent": "a", "event": "fault", "fault": "recover"},
    ]
    replay = Replay(Trace("x.jsonl", events))

    def at(t: float) -> tuple[object, ...]:
        a = replay.state(t)["agents"]["a"]
        return a["plan"], a["task"], a["state"], a["alive"], [n["plan"] for n in a["plans"]]

    assert at(0.5) == ("Top", "Lead", None, True, ["Top"])
    assert at(1.5) == ("Sub", "Carry", None, True, ["Top", "Sub"])
    assert at(2.7) == ("Sub", "Carry", "Lift", True, ["Top", "Sub"])
    assert at(3.5) == ("Top", "Lead", "S3", True, ["Top"])
    assert at(4.5) == ("Top", "Lead", "S3", False, ["Top"])
    assert at(5.5) == (None, None, None, True, [])


def test_a_version_1_trace_is_replayed_with_the_reader_s_note(tmp_path: Path) -> None:
    import json

    from alica.app.center.replay import Replay
    from alica.app.center.server import replay_app
    from alica.app.center.trace_file import load_trace

    path = tmp_path / "old.jsonl"
    lines = [{"t": 0.0, "agent": "a", "event": "allocation", "key": "Top", "plan": "Top", "entries": {"a": "Go"}}]
    path.write_text("".join(json.dumps(e) + "\n" for e in lines), encoding="utf-8")
    client = TestClient(replay_app(Replay(load_trace(path)), "tok"))
    meta = client.get("/api/meta?token=tok").json()
    assert meta["header"]["version"] == 1
    assert meta["notes"] and "pose" in " ".join(meta["notes"])
    assert meta["agents"] == ["a"]


def test_the_plan_trees_of_a_demo_trace(blocks_trace: Path) -> None:
    client = _client(blocks_trace)
    assert client.get("/api/trees").status_code == 403
    client.cookies.set(COOKIE, TOKEN)
    data = client.get("/api/trees").json()
    assert data["agents"] == {"r1": "BlocksWorldMission", "r2": "BlocksWorldMission"}
    assert data["notes"] == []
    tree = data["trees"]["BlocksWorldMission"]
    assert tree["kind"] == "plan"
    stacking = next(s for s in tree["states"] if s["name"] == "Stacking")
    problem = stacking["children"][0]
    assert (problem["kind"], problem["name"]) == ("problem", "StackBlocks")
    assert "ref" not in json.dumps(tree)  # every plan spelled out where it is used, so each node can be lit
    assert client.get("/api/meta").json()["plan_notes"] == []


def _with_plans(tmp_path: Path, source: Path, plans: list[str]) -> Path:
    lines = source.read_text(encoding="utf-8").splitlines(keepends=True)
    header = json.loads(lines[0])
    header["plans"] = plans
    path = tmp_path / "moved.jsonl"
    path.write_text(json.dumps(header) + "\n" + "".join(lines[1:]), encoding="utf-8")
    return path


def test_a_plan_file_beside_the_trace_is_found(tmp_path: Path, recorded_trace: Path) -> None:
    mine = tmp_path / "mine"
    mine.mkdir()
    text = (plans_dir() / "examples" / "formation.yaml").read_text(encoding="utf-8")
    (mine / "formation.yaml").write_text(text.replace("imports: [../tasks.yaml]", "imports: [tasks.yaml]"))
    (mine / "tasks.yaml").write_bytes((plans_dir() / "tasks.yaml").read_bytes())
    client = _client(_with_plans(tmp_path, recorded_trace, ["mine/formation.yaml"]))
    client.cookies.set(COOKIE, TOKEN)
    data = client.get("/api/trees").json()
    assert data["notes"] == []
    assert set(data["agents"]) == {"r1", "r2", "r3"}
    assert data["trees"]["Formation"]["name"] == "Formation"


@pytest.mark.parametrize(
    ("plans", "note"),
    [
        (["nowhere/missing.yaml"], r"plan file nowhere/missing\.yaml not found \(looked for"),
        (["broken.yaml"], r"plan file broken\.yaml does not load: "),
        ([], r"names no plan files"),
    ],
)
def test_plan_files_that_do_not_load_give_a_note_not_a_traceback(
    tmp_path: Path, recorded_trace: Path, plans: list[str], note: str
) -> None:
    (tmp_path / "broken.yaml").write_text("plans: [this is: not a plan\n", encoding="utf-8")
    client = _client(_with_plans(tmp_path, recorded_trace, plans))
    client.cookies.set(COOKIE, TOKEN)
    meta = client.get("/api/meta")
    assert meta.status_code == 200
    assert len(meta.json()["plan_notes"]) == 1
    assert re.search(note, meta.json()["plan_notes"][0])
    data = client.get("/api/trees").json()
    assert (data["trees"], data["agents"]) == ({}, {})
    assert client.get("/api/state?t=1").status_code == 200  # the replay works without trees


def test_state_carries_the_world_objects_and_map(tmp_path: Path) -> None:
    from alica.engine.trace import MAP_ENCODING, encode_cells

    header = {"t": 0.0, "agent": "-", "event": "trace", "format": "alica-trace", "version": 2, "world": "lunar"}
    header |= {"bounds": [-2.0, -2.0, 2.0, 2.0], "agents": {"a": {"role": "Scout", "plan": "Top"}}}
    events = [
        header,
        {"t": 0.1, "agent": "-", "event": "object", "name": "s", "kind": "sample", "x": 1.0, "y": 1.0, "z": 0.0},
        {"t": 0.2, "agent": "-", "event": "found", "name": "red", "kind": "red", "x": 1.1, "y": 1.0},
        {"t": 5.0, "agent": "-", "event": "map", "origin": [-2.0, -2.0], "resolution": 2.0, "width": 2}
        | {"height": 2, "encoding": MAP_ENCODING, "cells": encode_cells(bytes([1, 2, 0, 1]), 2, 2)},
    ]
    path = tmp_path / "world.jsonl"
    path.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    client = _client(path)
    client.cookies.set(COOKIE, TOKEN)
    early = client.get("/api/state?t=1").json()
    assert (early["world"], early["bounds"], early["map"]) == ("lunar", [-2.0, -2.0, 2.0, 2.0], None)
    assert early["objects"]["s"]["found"] == "red"
    late = client.get("/api/state?t=5").json()
    assert late["map"]["cells"] == "1201"
    assert late["t"] == 5.0
