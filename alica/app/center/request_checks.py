"""What the control center checks of a request before a route sees it (issue 37, findings 9 and 10).

The token gate (:class:`alica.app.center.server.TokenGate`) says *who* may
ask; this middleware, inside it, says *what* may be asked:

* **Origin.** A browser sends the operator's cookie to every port of the
  host, so a page served on another local port could open the live feed or
  post goals with it. The WebSocket and every POST must therefore come from
  the center's own page: a request whose ``Origin`` names another host or
  port is refused (403; a WebSocket is closed unaccepted, 1008). A request
  without ``Origin`` (curl, a script) is let through: it is no browser page.
* **POST bodies** are JSON objects: ``Content-Type: application/json``
  (else 415), at most :data:`MAX_BODY` bytes (else 413, also for a chunked
  body), nested at most :data:`MAX_NESTING` deep and without ``NaN`` or
  ``Infinity`` (else 400). The body is read here once and handed on.
"""

from __future__ import annotations

import ipaddress
import json
from collections.abc import Iterable
from urllib.parse import urlsplit

from starlette.responses import PlainTextResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

MAX_BODY = 1024 * 1024
"""The largest POST body taken, in bytes."""
MAX_NESTING = 64
"""The deepest nesting of a POST body's JSON (arrays and objects)."""

_LOOPBACK = ("localhost", "127.0.0.1", "[::1]")


def _header(scope: Scope, name: bytes) -> str | None:
    for key, value in scope.get("headers", ()):
        if key == name:
            return str(value.decode("latin-1"))
    return None


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def own_origins(scope: Scope) -> set[str]:
    """The ``host:port`` a page of this center is served from, as the request reached it."""
    origins: set[str] = set()
    server = scope.get("server")
    if server is not None:
        host, port = str(server[0]), server[1]
        shown = f"[{host}]" if ":" in host else host
        origins.add(f"{shown}:{port}" if port is not None else shown)
        if port is not None and _is_loopback(host):
            origins.update(f"{alias}:{port}" for alias in _LOOPBACK)
    host_header = _header(scope, b"host")
    if host_header:
        origins.add(host_header.lower())
    return origins


def _with_port(netloc: str, scheme: str) -> str:
    """``host:port`` of an origin's network location, the scheme's default port made explicit."""
    if netloc.endswith("]") or ":" not in netloc.rsplit("]", 1)[-1]:
        return f"{netloc}:{443 if scheme == 'https' else 80}"
    return netloc


def origin_allowed(origin: str | None, own: Iterable[str]) -> bool:
    """Whether a request with header ``Origin: origin`` comes from one of the center's ``own`` origins."""
    if origin is None:
        return True
    parts = urlsplit(origin.strip().lower())
    if parts.scheme not in ("http", "https") or not parts.netloc:
        return False
    mine = {_with_port(o, "http") for o in own}
    return _with_port(parts.netloc, parts.scheme) in mine


def json_problem(body: bytes) -> str | None:
    """Why ``body`` is not a JSON document to take (too deep, ``NaN``/``Infinity``, not JSON); ``None`` if it is."""
    depth = 0
    in_string = escaped = False
    for byte in body:  # bracket depth outside strings: no recursion, so no depth can crash the check
        if in_string:
            if escaped:
                escaped = False
            elif byte == 0x5C:  # backslash
                escaped = True
            elif byte == 0x22:  # quote
                in_string = False
        elif byte == 0x22:
            in_string = True
        elif byte in (0x5B, 0x7B):
            depth += 1
            if depth > MAX_NESTING:
                return f"the request's JSON nests deeper than {MAX_NESTING}"
        elif byte in (0x5D, 0x7D):
            depth -= 1

    def refuse(constant: str) -> float:
        raise ValueError(f"{constant} is not a number this center takes")

    try:
        json.loads(body, parse_constant=refuse)
    except ValueError as exc:
        return f"the request's body is not JSON to take: {exc}"
    return None


class RequestChecks:
    """ASGI middleware: the Origin of WebSockets and POSTs, and POST bodies (see the module docstring)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        kind = scope["type"]
        if kind not in ("http", "websocket") or (kind == "http" and scope.get("method") != "POST"):
            await self.app(scope, receive, send)
            return
        if not origin_allowed(_header(scope, b"origin"), own_origins(scope)):
            if kind == "websocket":
                await send({"type": "websocket.close", "code": 1008})
                return
            await _refuse(scope, receive, send, 403, "403: a request from a page of another origin")
            return
        if kind == "websocket":
            await self.app(scope, receive, send)
            return
        media = (_header(scope, b"content-type") or "").split(";", 1)[0].strip().lower()
        if media != "application/json":
            await _refuse(scope, receive, send, 415, "415: the body must be application/json")
            return
        length = _header(scope, b"content-length")
        if length is not None and (not length.strip().isdigit() or int(length) > MAX_BODY):
            await _refuse(scope, receive, send, 413, f"413: the body is larger than {MAX_BODY} bytes")
            return
        body = bytearray()
        more = True
        while more:
            message = await receive()
            if message["type"] != "http.request":
                return  # the client left
            body += message.get("body", b"")
            more = bool(message.get("more_body", False))
            if len(body) > MAX_BODY:
                await _refuse(scope, receive, send, 413, f"413: the body is larger than {MAX_BODY} bytes")
                return
        problem = json_problem(bytes(body))
        if problem is not None:
            await _refuse(scope, receive, send, 400, f"400: {problem}")
            return
        await self.app(scope, _replay(bytes(body), receive), send)


async def _refuse(scope: Scope, receive: Receive, send: Send, status: int, text: str) -> None:
    await PlainTextResponse(text + "\n", status_code=status)(scope, receive, send)


def _replay(body: bytes, receive: Receive) -> Receive:
    """A ``receive`` that gives ``body`` once, then what the client sends (its disconnect)."""
    given = False

    async def again() -> Message:
        nonlocal given
        if not given:
            given = True
            return {"type": "http.request", "body": body, "more_body": False}
        return await receive()

    return again
