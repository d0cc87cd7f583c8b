"""The control center's web server: a Starlette app behind a Jupyter-style token.

Every request (page, API, static file) must carry the token: as the query
parameter ``token=``, as the cookie the first visit sets, or as an
``Authorization: Bearer`` header. Without it the answer is 403 (a WebSocket is
closed unaccepted). Inside the gate, :class:`~alica.app.center.request_checks.RequestChecks`
checks the Origin of WebSockets and POSTs and the POST bodies, and the server
closes connections whose request headers are late
(:class:`~alica.app.center.header_timeout.HeaderTimeout`).
"""

from __future__ import annotations

import asyncio
import hmac
import json
import math
import socket
import sys
import threading
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any, TextIO

from starlette.applications import Starlette
from starlette.datastructures import MutableHeaders
from starlette.middleware import Middleware
from starlette.requests import HTTPConnection, Request
from starlette.responses import HTMLResponse, JSONResponse, PlainTextResponse, Response
from starlette.routing import Route, WebSocketRoute
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from starlette.websockets import WebSocket, WebSocketDisconnect

from alica.app.center import operator
from alica.app.center.live import LiveHub
from alica.app.center.replay import FAULT_KINDS, REPLAN_KINDS, Replay
from alica.app.center.request_checks import RequestChecks
from alica.engine import PlanDecision
from alica.errors import AlicaError
from alica.lang.walk import literals

COOKIE = "alica_center_token"
"""The start of the token cookie's name; :func:`cookie_name` adds the center's port."""


def cookie_name(port: object) -> str:
    """The token cookie of the center on ``port``: two centers on one host keep their own (a cookie has no port)."""
    return f"{COOKIE}_{port}"


class TokenGate:
    """ASGI middleware that refuses every HTTP request and WebSocket without the token.

    An HTTP request without it gets 403; a WebSocket is closed before it is accepted
    (code 1008, policy violation). A page request with the token in its query gets a
    cookie with it, so the page's own requests need not carry it.
    """

    def __init__(self, app: ASGIApp, token: str) -> None:
        self.app = app
        self.token = token

    def _given(self, scope: Scope) -> tuple[str | None, bool]:
        connection = HTTPConnection(scope)
        query = connection.query_params.get("token")
        if query is not None:
            return query, True
        auth = connection.headers.get("authorization", "")
        if auth.lower().startswith("bearer "):
            return auth[7:].strip(), False
        return connection.cookies.get(cookie_name(_port(scope))), False

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        given, from_query = self._given(scope)
        if given is None or not hmac.compare_digest(given.encode(), self.token.encode()):
            if scope["type"] == "websocket":
                await send({"type": "websocket.close", "code": 1008})
                return
            refused = PlainTextResponse("403: this page needs the token printed by 'alica center'\n", status_code=403)
            await refused(scope, receive, send)
            return
        if not from_query or scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        cookie = f"{cookie_name(_port(scope))}={self.token}; HttpOnly; Path=/; SameSite=strict"

        async def send_with_cookie(message: Message) -> None:
            if message["type"] == "http.response.start":
                MutableHeaders(scope=message).append("set-cookie", cookie)
            await send(message)

        await self.app(scope, receive, send_with_cookie)


def _port(scope: Scope) -> object:
    server = scope.get("server")
    return server[1] if server else None


def _middleware(token: str) -> list[Middleware]:
    """The token gate, then the request checks."""
    return [Middleware(TokenGate, token=token), Middleware(RequestChecks)]


def _static(name: str) -> str:
    return resources.files("alica.app.center").joinpath("static", name).read_text(encoding="utf-8")


STATIC_TYPES = {".js": "text/javascript", ".css": "text/css", ".html": "text/html"}


async def _static_file(request: Request) -> Response:
    name = request.path_params["name"]
    suffix = name[name.rfind(".") :] if "." in name else ""
    if "/" in name or suffix not in STATIC_TYPES:
        return PlainTextResponse("not found\n", status_code=404)
    try:
        text = _static(name)
    except (FileNotFoundError, OSError):
        return PlainTextResponse("not found\n", status_code=404)
    return Response(text, media_type=STATIC_TYPES[suffix])


def _number(request: Request, name: str) -> float | None:
    raw = request.query_params.get(name)
    if raw in (None, ""):
        return None
    try:
        value = float(raw)
    except ValueError:
        raise ValueError(f"'{name}' must be a number, not {raw!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"'{name}' must be a finite number, not {raw!r}")
    return value


def replay_app(replay: Replay, token: str, trees: dict[str, Any] | None = None) -> Starlette:
    """The app of a trace replay: the page and ``/api/meta``, ``/api/events``, ``/api/state``, ``/api/next``, ``/api/trees``.

    Args:
        trees: the agents' plan trees (:func:`~alica.app.center.plan_view.trace_trees`); by default
            from the header's plan files, loaded with the installed skills.
    """
    from alica.app.center.plan_view import trace_trees

    if trees is None:
        trees = trace_trees(replay.trace.meta, replay.trace.path)

    async def page(request: Request) -> Response:
        return HTMLResponse(_static("replay.html"))

    async def meta(request: Request) -> Response:
        return JSONResponse({**replay.meta(), "plan_notes": trees["notes"]})

    async def plan_trees(request: Request) -> Response:
        return JSONResponse(trees)

    async def events(request: Request) -> Response:
        try:
            start, end = _number(request, "start"), _number(request, "end")
        except ValueError as exc:
            return JSONResponse({"error": str(exc)}, status_code=400)
        raw = request.query_params.get("kinds")
        kinds = {k for k in raw.split(",") if k} if raw else None
        return JSONResponse({"events": replay.window(start, end, kinds)})

    async def state(request: Request) -> Response:
        try:
            t = _number(request, "t")
        except ValueError as exc:
            return JSONResponse({"error": str(exc)}, status_code=400)
        return JSONResponse(replay.state(replay.meta()["end"] if t is None else t))

    async def next_event(request: Request) -> Response:
        kind = request.query_params.get("kind", "")
        kinds = {"fault": FAULT_KINDS, "replan": REPLAN_KINDS}.get(kind)
        if kinds is None:
            return JSONResponse({"error": "kind must be 'fault' or 'replan'"}, status_code=400)
        try:
            after = _number(request, "after")
        except ValueError as exc:
            return JSONResponse({"error": str(exc)}, status_code=400)
        return JSONResponse({"kind": kind, "t": replay.next_time(-1e300 if after is None else after, kinds)})

    routes = [
        Route("/", page),
        Route("/api/meta", meta),
        Route("/api/events", events),
        Route("/api/state", state),
        Route("/api/next", next_event),
        Route("/api/trees", plan_trees),
        Route("/static/{name}", _static_file),
    ]
    return Starlette(routes=routes, middleware=_middleware(token))


def plan_app(file: str, trees: dict[str, dict[str, Any]], svgs: dict[str, str], token: str) -> Starlette:
    """The app of the plan-file view: the page, ``/api/plan`` (the trees as JSON) and ``/api/plan.svg``."""

    async def page(request: Request) -> Response:
        return HTMLResponse(_static("plan.html"))

    async def plan(request: Request) -> Response:
        return JSONResponse({"file": file, "roots": list(trees), "trees": trees})

    async def plan_svg(request: Request) -> Response:
        root = request.query_params.get("root") or next(iter(svgs))
        if root not in svgs:
            return PlainTextResponse(f"no plan tree '{root}' in {file}\n", status_code=404)
        return Response(svgs[root], media_type="image/svg+xml")

    routes = [
        Route("/", page),
        Route("/api/plan", plan),
        Route("/api/plan.svg", plan_svg),
        Route("/static/{name}", _static_file),
    ]
    return Starlette(routes=routes, middleware=_middleware(token))


HELLO_EVENTS = 2000
"""The latest events a page gets when it connects to a live team (the rest: ``/api/events?since=``)."""


def _update(kind: str, events: list[dict[str, Any]], walls: list[float], count: int, state: str) -> str:
    """A message to the live page, the state's JSON spliced in as it is (it is shared by every page)."""
    return (
        f'{{"type":"{kind}","count":{count},"events":{json.dumps(events)},"walls":{json.dumps(walls)},"state":{state}}}'
    )


NO_RELOAD = (
    "this control center cannot load the team's plan files again: it was started without them "
    "(alica run PLAN --center and alica run --processes --center can reload)"
)


def live_app(
    hub: LiveHub,
    known: dict[str, dict[str, Any]],
    token: str,
    trees: dict[str, Any] | None = None,
    *,
    reload: Callable[[Any], dict[str, Any]] | None = None,
) -> Starlette:
    """The app of a live team: the page, ``/ws`` (events and state as they happen), and the operator's API.

    Args:
        hub: the running team's events and command queue.
        known: the planning problems the operator may set goals for (:func:`operator.problems`).
        token: the access token.
        trees: the agents' plan trees before any reload (the hub serves them, then those of each library the
            team adopts); by default from the header's plan files (as the run's command line named them),
            loaded with the header's skill modules and plan folders.
        reload: the operator's reload action, called with the team on the team's thread (``POST /api/reload``):
            it loads the plan files again and gives them to the team (:meth:`LiveSession.reload
            <alica.app.center.live.LiveSession.reload>`, :meth:`RemoteTeam.reload
            <alica.app.center.team_feed.RemoteTeam.reload>`); without, the action says why it cannot.
    """

    if trees is None:
        from alica.app.center.plan_view import trace_trees
        from alica.app.trace_sources import viewer_sources

        sources = viewer_sources(hub.header)
        trees = trace_trees(hub.header, Path.cwd() / "live", sources.loader)
        trees["notes"] = [*sources.notes, *trees["notes"]]
    hub.serve_trees(trees)

    def meta() -> dict[str, Any]:
        plans = hub.header.get("plans") or []
        return {
            "mode": "live",
            "file": Path(str(plans[0])).name if plans else "",
            "header": hub.header,
            "agents": sorted(hub.header.get("agents") or {}),
            "problems": known,
            "status": hub.status,
            "plan_notes": hub.trees()["notes"],
            "reload": reload is not None,
        }

    async def page(request: Request) -> Response:
        return HTMLResponse(_static("live.html"))

    async def meta_route(request: Request) -> Response:
        return JSONResponse(meta())

    async def state(request: Request) -> Response:
        return Response(hub.snapshot_json(), media_type="application/json")

    async def plan_trees(request: Request) -> Response:
        return JSONResponse(hub.trees())

    async def events(request: Request) -> Response:
        try:
            since = int(request.query_params.get("since", "0"))
        except ValueError:
            return JSONResponse({"error": "'since' must be a whole number of events"}, status_code=400)
        found, walls, count = hub.since(max(since, 0))
        return JSONResponse({"events": found, "walls": walls, "count": count})

    async def feed(socket: WebSocket) -> None:
        await socket.accept()
        listener = hub.listen()
        closed = asyncio.Event()

        async def read() -> None:  # the page says nothing; this notices when it goes
            try:
                while True:
                    await socket.receive_text()
            except (WebSocketDisconnect, RuntimeError):
                closed.set()
                listener.wake.set()

        reader = asyncio.create_task(read())
        try:
            found, walls, count = hub.since(0)
            start = max(0, len(found) - HELLO_EVENTS)
            hello = _update("hello", found[start:], walls[start:], count, hub.snapshot_json())
            await socket.send_text(hello[:-1] + f',"meta":{json.dumps(meta())}}}')
            while not closed.is_set():
                await listener.wake.wait()
                listener.wake.clear()
                listener.pending = False
                if closed.is_set():
                    break
                found, walls, count = hub.since(count)
                await socket.send_text(_update("update", found, walls, count, hub.snapshot_json()))
        except (WebSocketDisconnect, RuntimeError, OSError):
            pass
        finally:
            hub.forget(listener)
            reader.cancel()

    async def body(request: Request) -> dict[str, Any]:
        try:
            data = await request.json()
        except ValueError:
            raise AlicaError("the request's body must be a JSON object") from None
        if not isinstance(data, dict):
            raise AlicaError("the request's body must be a JSON object")
        return data

    async def act(command: Callable[[Any], Any]) -> Response:
        try:
            result = await asyncio.wrap_future(hub.submit(command))
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=409)
        return JSONResponse({"ok": True, "result": result})

    async def check(request: Request) -> Response:
        try:
            data = await body(request)
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        return JSONResponse(operator.check_goal(known, str(data.get("problem", "")), str(data.get("goal", ""))))

    async def goal(request: Request) -> Response:
        try:
            data = await body(request)
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        problem, text = str(data.get("problem", "")), str(data.get("goal", ""))
        checked = operator.check_goal(known, problem, text)
        if not checked["ok"]:
            return JSONResponse(checked, status_code=400)
        return await act(lambda team: team.set_goal(problem, text))

    async def facts(request: Request) -> Response:
        try:
            data = await body(request)
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        text = str(data.get("facts", ""))
        checked = operator.check_facts(text)
        if not checked["ok"]:
            return JSONResponse(checked, status_code=400)
        return await act(lambda team: team.set_facts(literals(text), by_operator=True))

    async def decide(request: Request) -> Response:
        try:
            problem, generation, action, order, pins = operator.decision(await body(request))
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        try:
            choice = PlanDecision(action, order, pins)  # type: ignore[arg-type]  # checked by operator.decision
        except ValueError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        return await act(lambda team: team.decide_plan(problem, generation, choice))

    async def reload_plans(request: Request) -> Response:
        try:
            await body(request)  # nothing to say but the request's shape: a JSON object, as every action
        except AlicaError as exc:
            return JSONResponse({"ok": False, "error": str(exc)}, status_code=400)
        if reload is None:
            return JSONResponse({"ok": False, "error": NO_RELOAD}, status_code=409)
        return await act(reload)

    routes = [
        Route("/", page),
        Route("/api/meta", meta_route),
        Route("/api/state", state),
        Route("/api/events", events),
        Route("/api/trees", plan_trees),
        Route("/api/check", check, methods=["POST"]),
        Route("/api/goal", goal, methods=["POST"]),
        Route("/api/facts", facts, methods=["POST"]),
        Route("/api/decide", decide, methods=["POST"]),
        Route("/api/reload", reload_plans, methods=["POST"]),
        WebSocketRoute("/ws", feed),
        Route("/static/{name}", _static_file),
    ]
    return Starlette(routes=routes, middleware=_middleware(token))


def bind(host: str, port: int) -> socket.socket:
    """A listening socket on ``host:port``; port 0 picks a free port.

    Raises:
        AlicaError: the address cannot be bound (in use, unknown host, not allowed).
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host, port))
        sock.listen(128)
    except OSError as exc:
        sock.close()
        raise AlicaError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    return sock


def address(host: str, sock: socket.socket, token: str) -> str:
    """The one line to open: ``http://HOST:PORT/?token=TOKEN`` with the port really bound."""
    port = sock.getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}/?token={token}"


def serve(app: Starlette, host: str, port: int, token: str, out: TextIO = sys.stdout) -> None:
    """Bind, print the address line, and serve until interrupted."""
    import uvicorn

    from alica.app.center.header_timeout import HeaderTimeout

    sock = bind(host, port)
    print(address(host, sock, token), file=out, flush=True)
    config = uvicorn.Config(app, log_level="warning", access_log=False, lifespan="off", http=HeaderTimeout)
    uvicorn.Server(config).run(sockets=[sock])


def serve_in_thread(app: Starlette, host: str, port: int, token: str, out: TextIO = sys.stdout) -> Any:
    """Bind, serve from a thread of its own, print the address line once the server listens.

    Returns:
        The ``uvicorn.Server``; set its ``should_exit`` to stop it.

    Raises:
        AlicaError: the address cannot be bound, or the server did not start within 10 s.
    """
    import uvicorn

    from alica.app.center.header_timeout import HeaderTimeout

    sock = bind(host, port)
    config = uvicorn.Config(
        app, log_level="warning", access_log=False, lifespan="off", ws="websockets-sansio", http=HeaderTimeout
    )
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, name="alica-center", daemon=True)
    thread.start()
    deadline = time.monotonic() + 10.0
    while not server.started:
        if not thread.is_alive() or time.monotonic() > deadline:
            raise AlicaError(f"the control center did not start on {host}:{sock.getsockname()[1]}")
        time.sleep(0.01)  # waiting for the server's own thread to listen (start-up, not simulated time)
    print(address(host, sock, token), file=out, flush=True)
    return server
