"""Issue 37, findings 9 and 10: the control center checks where a request comes from and what it carries.

Before: a page on another local port could open the live feed and post goals with the operator's
cookie (no Origin check, ``text/plain`` accepted), a 64 MB body was read, deep JSON and ``t=nan``
gave 500, request headers had no time-out, two centers on one host shared one cookie, and a trace
header could make the center read any plan path.
"""

from __future__ import annotations

import io
import json
import shutil
import socket
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from alica.app.center.header_timeout import HeaderTimeout
from alica.app.center.live import LiveHub
from alica.app.center.plan_view import _load_library
from alica.app.center.replay import Replay
from alica.app.center.request_checks import MAX_BODY
from alica.app.center.server import cookie_name, live_app, replay_app, serve_in_thread
from alica.app.center.team_view import TeamView
from alica.app.center.trace_file import load_trace

TOKEN = "hardening-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
JSON = {**AUTH, "Content-Type": "application/json"}
GOAL = {"problem": "P", "goal": "on(a, b)"}


@pytest.fixture
def client() -> Iterator[TestClient]:
    header: dict[str, Any] = {"agents": {"r1": {"role": "Worker", "plan": "Top"}}, "world": "none"}
    app = live_app(LiveHub(header, TeamView(header)), {}, TOKEN, {"trees": {}, "agents": {}, "notes": []})
    with TestClient(app) as test_client:
        yield test_client


@pytest.mark.parametrize("origin", ["http://127.0.0.1:9999", "http://evil.example", "null", "http://testserver:81"])
def test_a_websocket_from_another_origin_is_closed_unaccepted(client, origin):
    with (
        pytest.raises(WebSocketDisconnect) as closed,
        client.websocket_connect("/ws", headers={**AUTH, "Origin": origin}),
    ):
        pass
    assert closed.value.code == 1008


@pytest.mark.parametrize("origin", [None, "http://testserver", "http://testserver:80"])
def test_a_websocket_from_the_centers_own_page_or_no_browser_is_accepted(client, origin):
    headers = AUTH if origin is None else {**AUTH, "Origin": origin}
    with client.websocket_connect("/ws", headers=headers) as ws:
        assert "state" in ws.receive_json()


def test_a_post_from_another_origin_is_refused(client):
    response = client.post("/api/check", json=GOAL, headers={**JSON, "Origin": "http://127.0.0.1:9999"})
    assert response.status_code == 403 and "another origin" in response.text
    assert client.post("/api/check", json=GOAL, headers={**JSON, "Origin": "http://testserver"}).status_code == 200


@pytest.mark.parametrize("media", ["text/plain", "application/x-www-form-urlencoded", "multipart/form-data", None])
def test_a_post_that_is_not_json_is_refused(client, media):
    headers = dict(AUTH) if media is None else {**AUTH, "Content-Type": media}
    response = client.post("/api/goal", content=json.dumps(GOAL), headers=headers)
    assert response.status_code == 415


def test_a_post_body_over_the_cap_is_refused_also_when_chunked(client):
    big = b'{"goal": "' + b"a" * MAX_BODY + b'"}'
    assert client.post("/api/goal", content=big, headers=JSON).status_code == 413

    def chunks() -> Iterator[bytes]:  # no Content-Length: counted while read
        for start in range(0, len(big), 65536):
            yield big[start : start + 65536]

    assert client.post("/api/goal", content=chunks(), headers=JSON).status_code == 413


@pytest.mark.parametrize(
    "body",
    [
        b"[" * 100_000 + b"]" * 100_000,  # before: 500 (RecursionError)
        b'{"a": ' * 65 + b"1" + b"}" * 65,
        b'{"problem": "P", "goal": NaN}',
        b'{"problem": "P", "t": Infinity}',
        b'{"problem": -Infinity}',
        b"{not json",
    ],
)
def test_deep_json_nan_and_infinity_get_400_never_500(client, body):
    response = client.post("/api/facts", content=body, headers=JSON)
    assert response.status_code == 400, response.text


def test_json_within_the_bounds_passes_the_checks(client):
    nested = {"problem": "P", "goal": "on(a, b)", "x": json.loads("[" * 60 + "]" * 60)}
    assert client.post("/api/check", json=nested, headers=JSON).status_code == 200
    with_text = {"problem": "P", "goal": "NaN [[[[ Infinity"}  # inside strings: text, not numbers nor nesting
    assert client.post("/api/check", json=with_text, headers=JSON).status_code == 200


def test_the_replay_refuses_nan_and_infinity_with_400(recorded_trace):
    app = replay_app(Replay(load_trace(recorded_trace)), TOKEN, {"trees": {}, "agents": {}, "notes": []})
    with TestClient(app) as replay:
        for value in ("nan", "inf", "-inf", "NaN"):
            response = replay.get(f"/api/state?t={value}", headers=AUTH)
            assert response.status_code == 400 and "finite" in response.text, value
        assert replay.get("/api/state?t=1.5", headers=AUTH).status_code == 200


def test_each_center_has_its_own_cookie(recorded_trace):
    app = replay_app(Replay(load_trace(recorded_trace)), TOKEN, {"trees": {}, "agents": {}, "notes": []})
    for port in (8765, 8766):
        with TestClient(app, base_url=f"http://127.0.0.1:{port}") as browser:
            browser.get(f"/?token={TOKEN}")
            assert browser.cookies.get(cookie_name(port)) == TOKEN
            assert [c.name for c in browser.cookies.jar] == [f"alica_center_token_{port}"]


def test_a_connection_whose_headers_are_late_is_closed(monkeypatch, recorded_trace):
    monkeypatch.setattr(HeaderTimeout, "header_timeout", 0.5)
    app = replay_app(Replay(load_trace(recorded_trace)), TOKEN, {"trees": {}, "agents": {}, "notes": []})
    server = serve_in_thread(app, "127.0.0.1", 0, TOKEN, out=io.StringIO())
    try:
        port = server.servers[0].sockets[0].getsockname()[1]
        with socket.create_connection(("127.0.0.1", port), timeout=10) as slow:
            slow.sendall(b"GET /api/meta HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # and never the end of the headers
            assert slow.recv(1024) == b""  # closed by the server well before the 10 s time-out of this read
        with socket.create_connection(("127.0.0.1", port), timeout=10) as prompt:
            prompt.sendall(
                f"GET /api/meta HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {TOKEN}\r\n\r\n".encode()
            )
            assert prompt.recv(1024).startswith(b"HTTP/1.1 200")
    finally:
        server.should_exit = True


def test_plan_files_outside_the_trace_folder_and_the_plan_path_are_not_read(tmp_path):
    trace = tmp_path / "runs" / "run.jsonl"
    trace.parent.mkdir()
    secret = tmp_path / "secret.yaml"
    secret.write_text("private_key: 1\n", encoding="utf-8")
    (trace.parent / "link.yaml").symlink_to(secret)
    for given in ("/etc/passwd", str(secret), "../secret.yaml", "link.yaml", "/nonexistent/x.yaml"):
        library, note = _load_library(given, trace)
        assert library is None
        assert "outside the trace's folder" in note and "private_key" not in note, given
        assert "not found" not in note  # the same words whether the file exists or not


def test_plan_files_in_the_trace_folder_and_the_shipped_plans_still_load(tmp_path):
    from alica.io import plans_dir

    shutil.copytree(plans_dir(), tmp_path / "plans")
    (tmp_path / "plans" / ".alica-project").touch()
    trace = tmp_path / "plans" / "run.jsonl"
    library, note = _load_library("examples/formation.yaml", trace)  # as given, relative to the trace's folder
    assert library is not None, note
    library, note = _load_library(str(plans_dir() / "examples" / "formation.yaml"), trace)
    assert library is not None, note


@pytest.fixture
def recorded_trace(tmp_path: Path) -> Path:
    """A short trace of the formation example (the center's tests have one per session; this folder has none)."""
    from alica.app.cli import main
    from alica.io import plans_dir

    path = tmp_path / "formation.jsonl"
    argv = ["run", str(plans_dir() / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot", "--stand-ins"]
    assert main([*argv, "--time-limit", "2", "--trace", str(path)]) in (0, 1)
    return path
