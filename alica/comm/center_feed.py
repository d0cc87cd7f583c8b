"""What a control center sees of a team of processes over zenoh, and how it talks to it.

Two sides, both on zenoh keys under the team's prefix (``--key-prefix``):

* **An agent** (:class:`CenterFeed`, sharing its :class:`ZenohTransport`'s session)
  publishes every trace event as JSON on ``{prefix}/center/events/{name}``
  (best effort, and only while some session subscribes: zenoh tells the
  publisher whether a subscriber matches, so with no center the cost is one
  ``json.dumps`` per event to keep it); keeps the last :data:`KEEP` events and
  answers the query ``{prefix}/center/history/{name}`` with its trace header
  and those events (``dropped`` counts the older ones it no longer has); and
  receives the operator's commands on ``{prefix}/center/operator``, queued for
  the agent's own thread (:meth:`CenterFeed.commands`).
* **A center** (:class:`CenterLink`) opens a zenoh *client* session to one or
  more agents' listen endpoints (an agent in peer mode routes for its
  clients: the whole team is reached through one of them), learns who is
  there from the agents' liveliness tokens (``{prefix}/alive/*``, without a
  token of its own: the center is no teammate), asks every agent it sees for
  its history, receives the events, and publishes commands.

Every published event carries the attachment ``"INCARNATION SEQ"``: the
agent's process (a restarted agent is a new incarnation) and the event's
number, so a center drops what it already had from a history answer.

**Operator commands are signed** when the team has credentials
(:class:`~alica.comm.credentials.TeamKeys`): the center's command carries the
attachment ``"SIGNER AT SIGNATURE"`` (the center's identity, its
``time.time_ns()``, and its signature of the team's prefix, the time and the
command); an agent takes only commands signed by the team's center, at most
:data:`COMMAND_SKEW` seconds off its clock, and each signature once. A
command reaches agents through the one the center is connected to, so zenoh's
access control cannot tell who sent it; the signature does. Commands over
:data:`MAX_COMMAND` bytes, malformed or unsigned ones are dropped and counted
(:attr:`CenterFeed.refused`).
"""

from __future__ import annotations

import json
import queue
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any, Self, cast

import zenoh

from alica.comm.zenoh_transport import ZenohTransport, _check_name, alive_of, zenoh_config

if TYPE_CHECKING:
    from alica.comm.credentials import TeamKeys

KEEP = 50_000
"""The events an agent keeps for a center that joins late (the older ones are dropped, and counted)."""
EVENTS = "center/events"
HISTORY = "center/history"
OPERATOR = "center/operator"
MAX_COMMAND = 1024 * 1024
"""The largest operator's command an agent takes, in bytes."""
COMMAND_SKEW = 300.0
"""Seconds a signed command's time may differ from the agent's clock (hosts' clocks kept by NTP)."""


def _signed_text(prefix: str, at: int, data: bytes) -> bytes:
    """What the center signs: the team, the time, and the command (so a signature is good for one of each)."""
    return b"%s\n%d\n%s" % (prefix.encode(), at, data)


_Declared = zenoh.Publisher | zenoh.Subscriber[None] | zenoh.Queryable[None] | zenoh.MatchingListener[None]
"""What a feed or a center declared on a session, undeclared when it closes."""


class CenterFeed:
    """One agent's events for control centers, and the operator's commands to it.

    Args:
        transport: the agent's transport; the feed declares its keys on its session.
        header: the agent's trace header, sent first in every history answer.
        start: the team's start (seconds since the epoch), sent with the history.
        keep: how many events to keep for late centers.
        keys: the team's credentials: take only commands signed by the team's center (``None``: any command).

    Call it with each trace event (an observer); close it before the transport.
    """

    def __init__(
        self,
        transport: ZenohTransport,
        header: Mapping[str, Any],
        start: float,
        keep: int = KEEP,
        keys: TeamKeys | None = None,
    ) -> None:
        if keep < 1:
            raise ValueError(f"keep must be at least 1 event, got {keep}")
        self.name = transport.agent_id
        prefix = self._prefix = transport.team
        self._keys = keys
        self._signatures: dict[bytes, int] = {}
        """Signatures of the commands taken, and their times (forgotten after :data:`COMMAND_SKEW`)."""
        self.refused = 0
        """Operator's commands dropped: too big, not JSON objects, or not signed by the team's center."""
        session = transport.session
        self._header = json.dumps(dict(header), sort_keys=True, default=str)
        self._start = float(start)
        self._incarnation = time.time_ns()
        self._kept: deque[str] = deque(maxlen=keep)
        self._count = 0
        self._lock = threading.Lock()
        self._commands: queue.SimpleQueue[dict[str, Any]] = queue.SimpleQueue()
        self.published = 0
        """Events put on zenoh (only while a center listened)."""
        self._publisher = session.declare_publisher(
            f"{prefix}/{EVENTS}/{self.name}", congestion_control=zenoh.CongestionControl.DROP
        )
        # zenoh's stubs (eclipse-zenoh 1.10) call matching_status a bool, but it is a MatchingStatus
        # (whose truth is always True): its ``matching`` says whether a subscriber matches
        self._listened = cast(zenoh.MatchingStatus, self._publisher.matching_status).matching
        self._declared: list[_Declared] = [
            self._publisher.declare_matching_listener(self._on_matching),
            session.declare_queryable(f"{prefix}/{HISTORY}/{self.name}", self._on_query),
            session.declare_subscriber(f"{prefix}/{OPERATOR}", self._on_command),
            self._publisher,
        ]

    @property
    def listened(self) -> bool:
        """Whether a center subscribes to this agent's events now."""
        return self._listened

    def __call__(self, event: Mapping[str, Any]) -> None:
        """Keep one trace event, and publish it while a center listens."""
        text = json.dumps(event, sort_keys=True, default=str)
        with self._lock:
            self._count += 1
            number = self._count
            self._kept.append(text)
        if self._listened:
            try:
                self._publisher.put(text, attachment=f"{self._incarnation} {number}")
                self.published += 1
            except Exception:  # (the session closed under us: the agent is stopping)
                return

    def commands(self, wait: float = 0.0) -> list[dict[str, Any]]:
        """The operator's commands received since the last call, in arrival order (for the agent's thread).

        Args:
            wait: seconds to wait for a first command when none is there (0: do not wait).
        """
        out = []
        if wait > 0:
            try:
                out.append(self._commands.get(timeout=wait))
            except queue.Empty:
                return out
        while True:
            try:
                out.append(self._commands.get_nowait())
            except queue.Empty:
                return out

    def close(self) -> None:
        """Undeclare the feed's keys (closing the transport's session does it too)."""
        for declared in self._declared:
            try:
                declared.undeclare()
            except Exception:  # (already gone with the session)
                pass
        self._declared = []

    # -- zenoh's threads ----------------------------------------------------------

    def _on_matching(self, status: zenoh.MatchingStatus) -> None:
        self._listened = status.matching

    def _on_query(self, query: zenoh.Query) -> None:
        with self._lock:
            events = list(self._kept)
            count = self._count
        answer = (
            f'{{"agent":{json.dumps(self.name)},"incarnation":{self._incarnation},"start":{self._start!r},'
            f'"count":{count},"dropped":{count - len(events)},"header":{self._header},"events":[{",".join(events)}]}}'
        )
        try:
            query.reply(query.key_expr, answer)
        except Exception:  # (the asker left)
            return

    def _on_command(self, sample: zenoh.Sample) -> None:
        data = sample.payload.to_bytes()
        command: object = None
        if len(data) <= MAX_COMMAND and (self._keys is None or self._signed(data, sample.attachment)):
            try:
                command = json.loads(data)
            except (ValueError, UnicodeDecodeError, RecursionError):
                command = None
        if isinstance(command, dict):
            self._commands.put(command)
        else:
            with self._lock:
                self.refused += 1

    def _signed(self, data: bytes, attachment: zenoh.ZBytes | None) -> bool:
        """Whether ``data`` carries a fresh signature of the team's center (its first use)."""
        keys = self._keys
        if keys is None or attachment is None:
            return False
        try:
            signer, at_text, signature_hex = attachment.to_bytes().decode("ascii").split(" ")
            at, signature = int(at_text), bytes.fromhex(signature_hex)
        except (ValueError, UnicodeDecodeError):
            return False
        now = time.time_ns()
        skew = int(COMMAND_SKEW * 1e9)
        if signer != keys.center or abs(at - now) > skew or len(signature) > 256:
            return False
        if not keys.verifies(signer, _signed_text(self._prefix, at, data), signature):
            return False
        with self._lock:
            self._signatures = {sig: t for sig, t in self._signatures.items() if now - t <= skew}
            if signature in self._signatures:
                return False  # replayed
            self._signatures[signature] = at
        return True


class CenterLink:
    """A control center's session with a team of processes (see the module docstring).

    Args:
        connect: agents' listen endpoints (``tcp/127.0.0.1:7447``); a client session uses the first it reaches.
        prefix: the team's key prefix.
        on_history: called with each agent's history answer (a dict: agent, incarnation, start, count,
            dropped, header, events), from a zenoh thread.
        on_event: called with ``(agent, event)`` for each event published after the history, from a zenoh thread.
        on_gone: called with an agent's name when its liveliness token goes.
        config: more zenoh configuration (key path -> JSON-able value).
        query_timeout: seconds before an unanswered history query is sent again.
        keys: the team's credentials (the center's identity): commands go signed.

    Raises:
        ValueError: a bad prefix or endpoint, or zenoh could not open the session.
    """

    def __init__(
        self,
        connect: Iterable[str],
        prefix: str,
        on_history: Callable[[dict[str, Any]], None],
        on_event: Callable[[str, dict[str, Any]], None],
        on_gone: Callable[[str], None] | None = None,
        *,
        config: Mapping[str, object] | None = None,
        query_timeout: float = 2.0,
        keys: TeamKeys | None = None,
    ) -> None:
        self.prefix = _check_name("key prefix", prefix)
        self._keys = keys
        self.connect = tuple(connect)
        if not self.connect:
            raise ValueError("give at least one endpoint of an agent of the team, e.g. tcp/127.0.0.1:7447")
        self._on_history = on_history
        self._on_event = on_event
        self._on_gone = on_gone
        self._timeout = float(query_timeout)
        self._lock = threading.Lock()
        self._closed = False
        self._tokens: dict[str, set[int]] = {}
        """Agent -> the incarnations whose liveliness token the session sees now."""
        self._known: dict[str, tuple[int, int]] = {}
        """Agent -> (incarnation, number of the last event handed on)."""
        self._waiting: dict[str, list[tuple[int, int, dict[str, Any]]]] = {}
        """Agent -> events that arrived before its history answer: (incarnation, number, event)."""
        self._asked: dict[str, float] = {}
        self.missed = 0
        """Events published while this center listened that never arrived (best effort drops them on congestion)."""
        try:
            self._session = zenoh.open(zenoh_config(self.connect, (), "client", 2.0, config))
        except zenoh.ZError as exc:
            raise ValueError(f"zenoh could not open a session to {list(self.connect)}: {exc}") from None
        try:
            self._declared: list[_Declared] = [
                self._session.declare_subscriber(f"{prefix}/{EVENTS}/*", self._on_sample),
                self._session.liveliness().declare_subscriber(f"{prefix}/alive/*/*", self._on_alive, history=True),
            ]
            self._publisher = self._session.declare_publisher(
                f"{prefix}/{OPERATOR}", congestion_control=zenoh.CongestionControl.BLOCK
            )
        except BaseException:
            self._session.close()
            raise
        self._stop = threading.Event()
        self._timer = threading.Thread(target=self._retry, name="alica-center-link", daemon=True)
        self._timer.start()

    def send(self, command: Mapping[str, Any]) -> None:
        """Publish an operator's command to every agent reached (signed when the center has the team's keys)."""
        data = json.dumps(dict(command), sort_keys=True, default=str).encode()
        if self._keys is None:
            self._publisher.put(data)
            return
        at = time.time_ns()
        signature = self._keys.sign(_signed_text(self.prefix, at, data))
        self._publisher.put(data, attachment=f"{self._keys.name} {at} {signature.hex()}")

    @property
    def alive(self) -> frozenset[str]:
        """Agents whose liveliness token the session sees now."""
        with self._lock:
            return frozenset(self._tokens)

    def agents_reached(self) -> int:
        """How many agents answered a history query so far."""
        with self._lock:
            return len(self._known)

    def close(self) -> None:
        """Close the session (always call it: zenoh's callback threads keep a process alive)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
        self._stop.set()
        try:
            self._session.close()
        finally:
            self._timer.join(timeout=2.0)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    # -- zenoh's threads ----------------------------------------------------------

    def _on_alive(self, sample: zenoh.Sample) -> None:
        token = alive_of(str(sample.key_expr))
        if token is None:
            return
        name, incarnation = token
        put = sample.kind == zenoh.SampleKind.PUT
        with self._lock:
            tokens = self._tokens.setdefault(name, set())
            if put:
                tokens.add(incarnation)
            else:
                tokens.discard(incarnation)
                if not tokens:
                    del self._tokens[name]
            gone = name not in self._tokens
        if put:
            self._ask(name)
        elif gone and self._on_gone is not None:
            self._on_gone(name)

    def _ask(self, name: str) -> None:
        with self._lock:
            if self._closed:
                return
            self._asked[name] = time.monotonic()
        try:
            self._session.get(
                f"{self.prefix}/{HISTORY}/{name}",
                self._on_reply,
                timeout=self._timeout,
                consolidation=zenoh.ConsolidationMode.NONE,
            )
        except Exception:  # (closing; or the agent left: the retry asks again while it is alive)
            return

    def _retry(self) -> None:
        while not self._stop.wait(0.25):
            now = time.monotonic()
            with self._lock:
                due = [n for n, at in self._asked.items() if n in self._tokens and now - at > self._timeout]
            for name in due:
                self._ask(name)

    def _on_reply(self, reply: zenoh.Reply) -> None:
        sample = reply.ok
        if sample is None:
            return
        try:
            answer = json.loads(sample.payload.to_bytes())
            name, incarnation, count = str(answer["agent"]), int(answer["incarnation"]), int(answer["count"])
            if not isinstance(answer["events"], list):
                return
        except (ValueError, KeyError, TypeError, UnicodeDecodeError):
            return
        with self._lock:
            self._asked.pop(name, None)
            known = self._known.get(name)
            if self._closed or (known is not None and known[0] >= incarnation):
                return  # a second answer of the same process (a retry crossed it)
            self._known[name] = (incarnation, count)
            later = [(n, e) for inc, n, e in self._waiting.pop(name, []) if inc == incarnation and n > count]
            self._on_history(answer)
            for number, event in sorted(later, key=lambda item: item[0]):
                self._known[name] = (incarnation, number)
                self._on_event(name, event)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        name = str(sample.key_expr).rsplit("/", 1)[-1]
        try:
            event = json.loads(sample.payload.to_bytes())
            raw = sample.attachment.to_bytes().decode() if sample.attachment is not None else ""
            incarnation, number = (int(part) for part in raw.split())
        except (ValueError, UnicodeDecodeError):
            return
        if not isinstance(event, dict):
            return
        ask = False
        with self._lock:
            if self._closed:
                return
            known = self._known.get(name)
            if known is None or incarnation > known[0]:
                # its history is not here yet (or this is a new process of it): hold the event, ask
                self._waiting.setdefault(name, []).append((incarnation, number, event))
                ask = name not in self._asked
                if ask:
                    self._asked[name] = time.monotonic()
            elif incarnation == known[0] and number > known[1]:
                self.missed += number - known[1] - 1  # best effort: lost on the way (a congested link)
                self._known[name] = (incarnation, number)
                self._on_event(name, event)
        if ask:
            self._ask(name)
