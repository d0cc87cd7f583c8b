"""A live run for the control center's tests: ``alica run ... --center`` in a process, and its WebSocket.

Every wait is bounded: the process is read until its address line, and the
WebSocket's messages are read with a deadline until the event a test waits for.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from typing import Any

from alica.io import plans_dir

TOKEN = "live-token"
BLOCKS = [
    str(plans_dir() / "blocksworld" / "mission.yaml"),
    "--agents",
    "r1:Manipulator,r2:Manipulator",
    "--world",
    "blocks",
    "--stacks",
    "a,b;c",
]
"""Two manipulators and the blocks a on b and c, planning the mission's goal at run time."""


@dataclass
class Live:
    """A running ``alica run --center``: its address and the events its page has been sent."""

    url: str
    process: subprocess.Popen[str]
    socket: Any = None
    events: list[dict[str, Any]] = field(default_factory=list)
    state: dict[str, Any] = field(default_factory=dict)
    hello: dict[str, Any] = field(default_factory=dict)
    stack: ExitStack = field(default_factory=ExitStack)

    @property
    def base(self) -> str:
        return self.url.split("?", 1)[0]

    def request(self, path: str, payload: dict[str, Any] | None = None, token: str | None = TOKEN) -> tuple[int, Any]:
        """GET (or POST ``payload`` as JSON) ``path``; the status and the decoded JSON (or text)."""
        data = None if payload is None else json.dumps(payload).encode()
        request = urllib.request.Request(self.base + path, data=data, method="GET" if data is None else "POST")
        request.add_header("Content-Type", "application/json")
        if token is not None:
            request.add_header("Authorization", f"Bearer {token}")
        try:
            with urllib.request.urlopen(request, timeout=20) as response:
                status, body = response.status, response.read().decode()
        except urllib.error.HTTPError as exc:
            status, body = exc.code, exc.read().decode()
        try:
            return status, json.loads(body)
        except ValueError:
            return status, body

    def connect(self) -> dict[str, Any]:
        """Open the page's WebSocket; returns the hello message (meta, state, events so far)."""
        from websockets.sync.client import connect

        ws_url = "ws" + self.base[len("http") :] + "ws"
        self.socket = self.stack.enter_context(
            connect(ws_url, additional_headers={"Authorization": f"Bearer {TOKEN}"}, open_timeout=20)
        )
        self.hello = self._receive(20.0)
        return self.hello

    def _receive(self, timeout: float) -> dict[str, Any]:
        message = json.loads(self.socket.recv(timeout=timeout))
        self.events.extend(message["events"])
        self.state = message["state"]
        return message

    def until(self, wanted: Callable[[dict[str, Any]], bool], timeout: float = 60.0, start: int = 0) -> dict[str, Any]:
        """The first event from index ``start`` on that ``wanted`` accepts, reading messages until it comes."""
        deadline = time.monotonic() + timeout
        seen = start
        while True:
            for event in self.events[seen:]:
                if wanted(event):
                    return event
            seen = len(self.events)
            left = deadline - time.monotonic()
            if left <= 0:
                kinds = sorted({e["event"] for e in self.events})
                raise AssertionError(f"no such event within {timeout} s; {len(self.events)} events of kinds {kinds}")
            self._receive(left)

    def until_state(self, wanted: Callable[[dict[str, Any]], bool], timeout: float = 60.0) -> dict[str, Any]:
        """Read messages until the pushed state satisfies ``wanted``."""
        deadline = time.monotonic() + timeout
        while not (self.state and wanted(self.state)):
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"the state did not come within {timeout} s: {self.state.get('status')}")
            self._receive(left)
        return self.state


ADDRESS = re.compile(r"http://127\.0\.0\.1:(\d+)/\?token=(\S+)")
"""The one line a control center prints to open."""


def stop(process: subprocess.Popen[str]) -> None:
    """SIGTERM, then kill if the process is not gone within 20 s."""
    process.terminate()
    try:
        process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait(timeout=20)


@contextmanager
def serving(argv: list[str], stream: str = "stdout") -> Iterator[tuple[str, subprocess.Popen[str]]]:
    """Start ``alica ARGV`` in a process, read its address line from ``stream``, and stop it afterwards."""
    process = subprocess.Popen(
        [sys.executable, "-m", "alica.app.cli", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        source = process.stdout if stream == "stdout" else process.stderr
        assert source is not None
        line = source.readline().strip()
        if not ADDRESS.fullmatch(line):
            process.kill()
            _, err = process.communicate(timeout=20)
            raise AssertionError(f"no address line, got {line!r}; stderr: {(err or '')[-2000:]}")
        yield line, process
    finally:
        stop(process)


@contextmanager
def live_run(*args: str, command: str = "run") -> Iterator[Live]:
    """Start ``alica COMMAND ARGS --center`` on a free port and stop it afterwards (SIGTERM, then kill)."""
    argv = [command, *args, "--center", "--center-port", "0", "--center-token", TOKEN]
    with serving(argv) as (line, process):
        live = Live(line, process)
        try:
            yield live
        finally:
            live.stack.close()
