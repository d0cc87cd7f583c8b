"""The :class:`Transport` over eclipse-zenoh, for agents in separate processes or hosts.

It keeps the meanings of the simulated network (:mod:`alica.comm.transport`):

* **Reliable** messages reach every live subscriber in send order, once, also
  across a partition. Zenoh alone loses what is published while a link is
  down, so the transport does not rely on it: each agent keeps its reliable
  messages (:attr:`ZenohTransport.history` seconds of them) and heartbeats
  the last reliable number per topic; a receiver that sees a gap, or a
  heartbeat ahead of what it has, fetches the missing messages from the
  sender's history with a zenoh query, holds later ones back until the gap is
  filled, and drops duplicates by sequence number.
* **Best-effort** messages keep the latest value per sender and topic.
* **Liveliness tokens** say who is alive: :meth:`ZenohTransport.peers` is the
  set of agents whose token this session sees; a clean exit or a ``kill -9``
  removes it within milliseconds, a partition after the zenoh lease.
* A **restarted** agent (a new process with the same id) is a new
  incarnation: receivers start over with its numbers, and deliver from it
  every reliable message sent after they subscribed.
* **Names are unique.** Each session's liveliness token names its agent and
  incarnation (``{team}/alive/{id}/{incarnation}``). A transport that finds
  another live session with its own id when it opens refuses to
  (:class:`NameTaken`); one that sees an older session with its id appear
  later (a partition healed) reports it (``on_name_taken``) and the agent
  stops. Teammates keep hearing the older one: a duplicate's token leaving
  does not take the name out of :meth:`ZenohTransport.peers`.
* With a **roster** (the team's agent ids), frames, heartbeats and tokens of
  any other name are dropped and counted (``stats.rejected["roster"]``): facts
  from outside the team are never merged.

The bookkeeping is pure and synchronous, in :mod:`alica.comm.reliable`: the
sender's :class:`~alica.comm.reliable.History` and the receiver's
:class:`~alica.comm.reliable.Inbox`; this module is the zenoh shell around
them. Everything arriving is handled by zenoh's threads (callbacks) and a
daemon timer thread (heartbeats, query time-outs), under one lock; the
engine's thread only drains the inbox in :meth:`ZenohTransport.poll`. Always close the
transport (``with ZenohTransport(...) as t:`` or ``close()`` in ``finally``):
a zenoh session with Python callbacks keeps its process alive until closed.

The settings follow ``reference/comms_notes.md``: no multicast scouting and
no gossip (links are the endpoints given), shared memory off, timestamping
on, a lease of 2 s.
"""

from __future__ import annotations

import ipaddress
import json
import re
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field

import zenoh

from alica.clock import Clock, SystemClock
from alica.comm import frames
from alica.comm.codec import encode
from alica.comm.reliable import Frame, History, Inbox
from alica.comm.transport import Envelope, QoS, Transport

_CHUNK = re.compile(r"[^/*$?#\s]+")

_SYNC = ("sync",)
_SYNC_BYTES = encode(_SYNC)
_FRAME_LEN = 8

FUTURE_INCARNATION = 300.0
"""Seconds an incarnation (the sender's ``time.time_ns()`` at its start) may lie ahead of this host's clock.

Hosts of a team keep their clocks within this of each other (NTP); a frame whose incarnation is
further ahead is forged, and taking it would make the sender's real frames look old."""


class NameTaken(ValueError):
    """Another live session of the team has this agent's id."""


def alive_key(team: str, name: str, incarnation: int) -> str:
    """The key of the liveliness token of ``name``'s session ``incarnation`` in ``team``."""
    return f"{team}/alive/{name}/{incarnation}"


def alive_of(key: str) -> tuple[str, int] | None:
    """(name, incarnation) of a liveliness token's key; ``None`` for a key of another shape."""
    parts = key.rsplit("/", 3)
    if len(parts) != 4 or parts[1] != "alive" or not parts[3].isdigit() or len(parts[3]) > 19:
        return None
    try:
        return _check_name("agent id", parts[2]), int(parts[3])
    except ValueError:
        return None


def _check_topic(topic: object) -> str:
    if not isinstance(topic, str) or not topic:
        raise ValueError(f"topic must be a non-empty string, got {topic!r}")
    if not all(_CHUNK.fullmatch(chunk) for chunk in topic.split("/")):
        raise ValueError(
            f"topic must be a non-empty string of '/'-separated names without '*', '$', '?', '#' or spaces, got {topic!r}"
        )
    return topic


def _check_name(what: str, name: object) -> str:
    if not isinstance(name, str) or not _CHUNK.fullmatch(name):
        raise ValueError(f"{what} must be a non-empty name without '/', '*', '$', '?', '#' or spaces, got {name!r}")
    return name


@dataclass(frozen=True, slots=True)
class ZenohStats:
    """What one transport did so far.

    Attributes:
        sent: publish calls.
        delivered: envelopes handed out by :meth:`ZenohTransport.poll`.
        recovered: reliable messages fetched from a sender's history (lost on the way, or sent in a partition).
        duplicates: reliable messages that arrived twice and were dropped.
        superseded: best-effort messages replaced by a newer one before a poll, or older than one delivered.
        lost: reliable messages a sender no longer had in its history when asked for (a very long partition).
        queries: history queries sent.
        undecodable: payloads that could not be decoded (another version, a foreign class).
        rejected: frames dropped because they were not well-formed (too big, undecodable, a field
            of the wrong type or out of bounds, nested too deep), by reason
            (:class:`alica.comm.frames.Reason`, e.g. ``{"topic": 2}``).
    """

    sent: int
    delivered: int
    recovered: int
    duplicates: int
    superseded: int
    lost: int
    queries: int
    undecodable: int
    rejected: dict[str, int] = field(default_factory=dict, hash=False)


class ZenohTransport(Transport):
    """One agent's connection to its team over a zenoh session.

    Args:
        agent_id: the agent's id, unique in the team.
        connect: zenoh endpoints to connect to, e.g. ``("tcp/127.0.0.1:7447",)``.
        listen: zenoh endpoints to listen on.
        team: the key prefix of the team; teams with different prefixes share
            a network without hearing each other.
        mode: ``"peer"`` (default) or ``"client"`` (through a zenoh router).
        lease: zenoh's link lease in seconds: a peer cut off is declared gone
            (its liveliness token dropped) after about this long.
        heartbeat: seconds between two heartbeats with the last reliable
            numbers; a message lost at the tail of a partition is fetched
            at most this long after the link is back.
        history: seconds a sender keeps its reliable messages for receivers
            that missed them (a partition longer than this loses what the
            sender trimmed; :attr:`ZenohStats.lost` counts it).
        history_mb: the most the kept reliable messages may take, in MB; past it,
            the oldest messages of the topic being published go first (a topic
            flooding reliable messages cannot exhaust the agent's memory).
        clock: the time of ``sent_at`` (and of the history); agents of one
            team need comparable clocks, so the default is
            :class:`~alica.clock.SystemClock` (hosts synchronised by NTP).
        config: more zenoh configuration, key path -> JSON-able value, e.g.
            ``{"scouting/multicast/enabled": True}``; applied last.
        query_timeout: seconds before an unanswered history query is sent again.
        roster: the ids of the team's agents; frames, heartbeats and liveliness tokens of other
            names are dropped and counted (``None``: any name is a teammate).
        on_name_taken: called (from a zenoh thread, with the reason) when an older live session with
            this agent's id appears after this one opened; the agent should stop.

    Raises:
        NameTaken: another live session of the team has this id.
        ValueError: a bad id, team, endpoint list, or zenoh configuration.
    """

    def __init__(
        self,
        agent_id: str,
        *,
        connect: Iterable[str] = (),
        listen: Iterable[str] = (),
        team: str = "alica",
        mode: str = "peer",
        lease: float = 2.0,
        heartbeat: float = 0.25,
        history: float = 600.0,
        history_mb: float = 64.0,
        clock: Clock | None = None,
        config: Mapping[str, object] | None = None,
        query_timeout: float = 1.0,
        roster: Iterable[str] | None = None,
        on_name_taken: Callable[[str], None] | None = None,
    ) -> None:
        self._id = _check_name("agent id", agent_id)
        self._roster = None if roster is None else frozenset(_check_name("agent id", n) for n in roster) | {self._id}
        self._on_name_taken = on_name_taken
        self.name_taken: str | None = None
        """Why this agent must stop: an older live session has its id (``None``: its id is its own)."""
        self._team = _check_name("team", team)
        if mode not in ("peer", "client"):
            raise ValueError(f"mode must be 'peer' or 'client', got {mode!r}")
        for name, value in (
            ("lease", lease),
            ("heartbeat", heartbeat),
            ("history", history),
            ("history_mb", history_mb),
        ):
            if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
                unit = "MB" if name == "history_mb" else "seconds"
                raise ValueError(f"{name} must be a number of {unit} > 0, got {value!r}")
        self._clock = clock or SystemClock()
        self._heartbeat = float(heartbeat)
        self._history_s = float(history)
        self._query_timeout = float(query_timeout)
        self._incarnation = time.time_ns()
        self._lock = threading.Lock()
        self._closed = False
        # sending
        self._seq: dict[str, int] = {}
        self._history = History(self._incarnation, seconds=self._history_s, max_bytes=float(history_mb) * 1024 * 1024)
        self._publishers: dict[tuple[str, QoS], zenoh.Publisher] = {}
        # receiving
        self._inbox = Inbox(self._id, quiet=10.0 * float(lease))
        self._alive: dict[str, set[int]] = {}
        """Teammate -> the incarnations whose liveliness token is up (two only while a duplicate stops)."""
        self._counts = dict.fromkeys([name for name in ZenohStats.__slots__ if name != "rejected"], 0)
        self._rejected: dict[str, int] = {}
        self.errors = self._inbox.errors
        """Why payloads could not be decoded (sender, topic, reason) and how often."""
        self._subscribers: list[zenoh.Subscriber[None] | zenoh.LivelinessToken | zenoh.Queryable[None]] = []
        connect, listen = tuple(connect), tuple(listen)
        try:
            self._session = zenoh.open(zenoh_config(connect, listen, mode, lease, config))
        except zenoh.ZError as exc:
            raise ValueError(
                f"zenoh could not open a session listening on {list(listen)} and connecting to {list(connect)}: {exc}"
            ) from None
        try:
            prefix = self._team
            liveliness = self._session.liveliness()
            # One subscriber for every topic, so that zenoh hands over each sender's messages in the order
            # they were sent (two subscribers' callbacks may run at once); poll() filters by topic.
            self._subscribers += [
                liveliness.declare_subscriber(f"{prefix}/alive/*/*", self._on_liveliness, history=True),
                liveliness.declare_token(alive_key(prefix, self._id, self._incarnation)),
                self._session.declare_subscriber(f"{prefix}/m/**", self._on_message),
                self._session.declare_subscriber(f"{prefix}/hb/*", self._on_heartbeat),
                self._session.declare_queryable(f"{prefix}/hist/{self._id}", self._on_query),
            ]
            self._hb_publisher = self._session.declare_publisher(
                f"{prefix}/hb/{self._id}", congestion_control=zenoh.CongestionControl.DROP, express=True
            )
        except BaseException:
            self._session.close()
            raise
        self._sync()
        self._check_unique()
        self._stop = threading.Event()
        self._timer = threading.Thread(target=self._tick, name=f"zenoh-{self._id}", daemon=True)
        self._timer.start()

    @property
    def session(self) -> zenoh.Session:
        """The zenoh session, for more keys of this agent under :attr:`team` (e.g. :class:`~alica.comm.center_feed.CenterFeed`)."""
        return self._session

    @property
    def team(self) -> str:
        """The team's key prefix."""
        return self._team

    # ------------------------------------------------------------------ the Transport interface

    @property
    def agent_id(self) -> str:
        """The id of the agent this transport belongs to."""
        return self._id

    @property
    def tracks_liveliness(self) -> bool:
        """True: :meth:`peers` comes from liveliness tokens, so a teammate that is gone leaves it at once."""
        return True

    def publish(self, topic: str, payload: object, qos: QoS = QoS.BEST_EFFORT) -> None:
        """See :meth:`Transport.publish`; the payload is pickled (:mod:`alica.comm.codec`)."""
        self._check_open("publish")
        _check_topic(topic)
        if not isinstance(qos, QoS):
            raise ValueError(f"qos must be a QoS (QoS.RELIABLE or QoS.BEST_EFFORT), got {qos!r}")
        seq = self._seq[topic] = self._seq.get(topic, 0) + 1
        reliable = qos is QoS.RELIABLE
        now = self._clock.now()
        if reliable:
            inner = encode(payload)
            with self._lock:
                rseq, gseq = self._history.next_numbers(topic)
                data = encode((self._incarnation, self._id, topic, seq, rseq, gseq, now, inner))
                self._history.keep(topic, rseq, now, data)
        else:
            data = encode((self._incarnation, self._id, topic, seq, 0, 0, now, encode(payload)))
        publisher = self._publishers.get((topic, qos))
        if publisher is None:
            publisher = self._publishers[(topic, qos)] = self._session.declare_publisher(
                f"{self._team}/m/{self._id}/{topic}",
                congestion_control=zenoh.CongestionControl.BLOCK if reliable else zenoh.CongestionControl.DROP,
                express=True,
            )
        publisher.put(data)
        if reliable:
            with self._lock:
                self._history.put(topic, rseq)  # the heartbeat announces only what is on its way
        self._counts["sent"] += 1

    def subscribe(self, topic: str) -> None:
        """See :meth:`Transport.subscribe`."""
        self._check_open("subscribe")
        _check_topic(topic)
        now = self._clock.now()
        with self._lock:
            self._inbox.subscribe(topic, now)

    def _sync(self) -> None:
        """Wait (a round trip, at most the query time-out) until every linked peer knows this session's subscriber.

        A query travels the same ordered links as the declarations before it:
        once every peer's history queryable answered, every peer routes
        messages to this session, so what they publish from then on arrives.
        """
        try:
            for _ in self._session.get(
                f"{self._team}/hist/*",
                payload=encode(_SYNC),
                timeout=self._query_timeout,
                consolidation=zenoh.ConsolidationMode.NONE,
            ):
                pass
        except Exception:  # (nobody to ask, or closing: nothing to wait for)
            return

    def _check_unique(self) -> None:
        """Refuse to go on when an older live session of the team has this id (the session closes)."""
        try:
            for reply in self._session.liveliness().get(
                f"{self._team}/alive/{self._id}/*", timeout=self._query_timeout
            ):
                if reply.ok is not None:
                    self._on_liveliness(reply.ok)
        except zenoh.ZError:  # (nobody to ask)
            pass
        if self.name_taken is not None:
            self._session.close()
            raise NameTaken(self.name_taken)

    def poll(self) -> list[Envelope]:
        """See :meth:`Transport.poll`: what arrived, in arrival order (reliable ones in send order per sender)."""
        self._check_open("poll")
        with self._lock:
            out = self._inbox.take()
        self._counts["delivered"] += len(out)
        return out

    def peers(self) -> frozenset[str]:
        """The agents whose liveliness token this session sees (never this agent itself)."""
        with self._lock:
            return frozenset(self._alive)

    def close(self) -> None:
        """Leave the team: the token goes, the session closes. Closing twice is harmless."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._inbox.take()  # (dropped)
        self._stop.set()
        try:
            self._session.close()
        finally:
            self._timer.join(timeout=2.0)

    @property
    def stats(self) -> ZenohStats:
        """Counters of what this transport did (:class:`ZenohStats`)."""
        with self._lock:
            counts = dict(self._counts)
            for name, count in self._inbox.counts.items():
                counts[name] += count
            rejected = frames.by_reason(self._rejected)
        return ZenohStats(**counts, rejected=rejected)

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._closed

    def __repr__(self) -> str:
        return f"ZenohTransport({self._id!r}, team={self._team!r})"

    # ------------------------------------------------------------------ sending heartbeats (timer thread)

    def _tick(self) -> None:
        while not self._stop.wait(self._heartbeat):
            try:
                self._beat()
            except Exception:  # (the session closed under us: the next wait ends the loop)
                if self._stop.is_set():
                    return

    def _beat(self) -> None:
        now = self._clock.now()
        with self._lock:
            if self._closed:
                return
            self._history.trim(now)
            # every reliable counter, also of topics whose history is trimmed: a receiver learns what it lost
            beat = self._history.announced()
            retry = self._inbox.overdue(now, self._query_timeout)
        self._hb_publisher.put(encode((self._incarnation, self._id, beat)))
        for sender in retry:
            self._ask(sender)

    # ------------------------------------------------------------------ receiving (zenoh threads)

    def _on_liveliness(self, sample: zenoh.Sample) -> None:
        token = alive_of(str(sample.key_expr))
        if token is None:
            return
        name, incarnation = token
        put = sample.kind == zenoh.SampleKind.PUT
        if name == self._id:
            if put and incarnation < self._incarnation and self.name_taken is None:
                started = time.strftime("%H:%M:%S", time.localtime(incarnation / 1e9))
                self.name_taken = (
                    f"another agent named {name!r} has been in team {self._team!r} since {started}: give this "
                    "one another --name, or stop the other first (a process that just died leaves the team "
                    "within the zenoh lease)"
                )
                if self._on_name_taken is not None:
                    self._on_name_taken(self.name_taken)
            return
        with self._lock:
            if self._roster is not None and name not in self._roster:
                frames.count(self._rejected, frames.Reason.ROSTER)
                return
            tokens = self._alive.setdefault(name, set())
            if put:
                tokens.add(incarnation)
                return
            tokens.discard(incarnation)
            if tokens:  # a duplicate left: the teammate is the older session, still there
                self._inbox.retire(name, incarnation)
            else:
                del self._alive[name]

    def _check_sender(self, sender: str, incarnation: int) -> None:
        """Refuse a sender outside the roster, and an incarnation from the future (a forgery)."""
        if self._roster is not None and sender not in self._roster:
            raise frames.BadFrame(frames.Reason.ROSTER, f"{sender!r} is not in the team's roster")
        if incarnation > time.time_ns() + int(FUTURE_INCARNATION * 1e9):
            raise frames.BadFrame(frames.Reason.NUMBER, "an incarnation further ahead than hosts' clocks differ")

    def _reject(self, bad: frames.BadFrame) -> None:
        """Count a frame that is not well-formed (lock held); it is dropped."""
        frames.count(self._rejected, bad.reason)

    def _on_message(self, sample: zenoh.Sample) -> None:
        data = sample.payload.to_bytes()
        key = str(sample.key_expr)
        with self._lock:
            if self._closed:
                return
            try:
                frame = frames.frame(frames.load(data, _FRAME_LEN))
                if key != f"{self._team}/m/{frame[1]}/{frame[2]}":
                    raise frames.BadFrame(frames.Reason.SENDER, "the frame's sender and topic are not its key's")
                self._check_sender(frame[1], frame[0])
            except frames.BadFrame as bad:
                self._reject(bad)
                return
            ask = self._receive(frame)
        if ask is not None:
            self._ask(ask)

    def _receive(self, frame: Frame) -> str | None:
        """Take in one well-formed frame (lock held); the sender to ask, if any (``bench/transport.py`` stamps here)."""
        return self._inbox.receive(frame, self._clock.now())

    def _on_heartbeat(self, sample: zenoh.Sample) -> None:
        data = sample.payload.to_bytes()
        with self._lock:
            if self._closed:
                return
            try:
                incarnation, sender, last = frames.heartbeat(frames.load(data, 3))
                if str(sample.key_expr) != f"{self._team}/hb/{sender}":
                    raise frames.BadFrame(frames.Reason.SENDER, "the heartbeat's sender is not its key's")
                self._check_sender(sender, incarnation)
            except frames.BadFrame as bad:
                self._reject(bad)
                return
            ask = self._inbox.heard(sender, incarnation, last, self._clock.now())
        if ask is not None:
            self._ask(ask)

    def _ask(self, sender: str) -> None:
        """Query ``sender``'s history for what this receiver lacks on every topic it subscribed to."""
        with self._lock:
            question = None if self._closed else self._inbox.question(sender)
            if question is None:
                return
            request = (self._id, *question)
            self._counts["queries"] += 1
        try:
            self._session.get(
                f"{self._team}/hist/{sender}",
                lambda reply: self._on_reply(sender, reply),
                payload=encode(request),
                timeout=self._query_timeout,
                consolidation=zenoh.ConsolidationMode.NONE,
            )
        except Exception:  # (closed meanwhile, or the sender gone: the time-out asks again)
            return

    def _on_query(self, query: zenoh.Query) -> None:
        """Answer a receiver's history query: the kept reliable messages it lacks, in send order."""
        payload = query.payload
        data = payload.to_bytes() if payload is not None else b""
        if data == _SYNC_BYTES:
            try:
                query.reply(f"{self._team}/hist/{self._id}", b"")
            except Exception:  # (the asker left)
                pass
            return
        with self._lock:
            if self._closed or not data:
                return
            try:
                _who, incarnation, wanted = frames.question(frames.load(data, 3))
            except frames.BadFrame as bad:
                self._reject(bad)
                return
            kept, start, oldest = self._history.answer(incarnation, wanted)
        answer = encode((self._incarnation, self._id, kept, start, oldest))
        try:
            query.reply(f"{self._team}/hist/{self._id}", answer)
        except Exception:  # (the asker left)
            return

    def _on_reply(self, asked: str, reply: zenoh.Reply) -> None:
        sample = reply.ok
        if sample is None:
            return
        data = sample.payload.to_bytes()
        with self._lock:
            if self._closed:
                return
            try:
                incarnation, sender, kept, start, oldest = frames.answer(frames.load(data, 5, frames.MAX_ANSWER_BYTES))
                if sender != asked:
                    raise frames.BadFrame(frames.Reason.SENDER, "an answer from another sender than the one asked")
                self._check_sender(sender, incarnation)
            except frames.BadFrame as bad:
                self._reject(bad)
                return
            # decoded only once the inbox knows the answer is about the sender's current incarnation
            self._inbox.answered(incarnation, sender, self._frames_of(sender, kept), start, oldest)

    def _frames_of(self, sender: str, kept: tuple[bytes, ...]) -> Iterator[Frame]:
        """The well-formed frames of ``sender`` in a history answer (the others counted and skipped; lock held)."""
        for data in kept:
            try:
                frame = frames.frame(frames.load(data, _FRAME_LEN))
                if frame[1] != sender:
                    raise frames.BadFrame(frames.Reason.SENDER, "a frame of another sender in a history answer")
            except frames.BadFrame as bad:
                self._reject(bad)
                continue
            yield frame

    def _check_open(self, what: str) -> None:
        if self._closed:
            raise ValueError(f"transport of {self._id!r} is closed; it can no longer {what}")


def zenoh_config(
    connect: tuple[str, ...], listen: tuple[str, ...], mode: str, lease: float, extra: Mapping[str, object] | None
) -> zenoh.Config:
    """A zenoh configuration as the team's sessions use it (see the module docstring); ``extra`` goes last.

    Raises:
        ValueError: an endpoint that is not ``proto/address``, or a setting zenoh does not accept.
    """
    for endpoint in (*connect, *listen):
        if not isinstance(endpoint, str) or "/" not in endpoint:
            raise ValueError(f"a zenoh endpoint looks like 'tcp/127.0.0.1:7447', got {endpoint!r}")
    settings: dict[str, object] = {
        "mode": mode,
        "connect/endpoints": list(connect),
        "listen/endpoints": list(listen),
        "scouting/multicast/enabled": False,
        "scouting/gossip/enabled": False,
        "transport/shared_memory/enabled": False,
        "transport/link/tx/lease": int(lease * 1000),
        "timestamping/enabled": {"router": True, "peer": True, "client": True},
        "connect/retry": {"period_init_ms": 100, "period_max_ms": 1000, "period_increase_factor": 2},
    }
    settings.update(extra or {})
    config = zenoh.Config()
    for key, value in settings.items():
        try:
            config.insert_json5(key, json.dumps(value))
        except Exception as exc:  # (zenoh reports a bad key or value as a generic error)
            raise ValueError(f"zenoh configuration {key} = {value!r} is not accepted: {exc}") from None
    return config


def off_loopback(endpoints: Iterable[str]) -> list[str]:
    """The endpoints that reach beyond this machine (``tcp/127.0.0.1:7447`` does not; ``tcp/0.0.0.0:7447`` does).

    Loopback addresses (``127.0.0.0/8``, ``::1``), ``localhost`` and Unix sockets stay on the machine;
    any other address or host name, and the unspecified address (every interface), does not.
    """
    out = []
    for endpoint in endpoints:
        proto, slash, rest = endpoint.partition("/")
        if not slash or proto.startswith("unixsock"):
            continue  # (not an endpoint at all: the session's configuration says so)
        address = re.split(r"[?#]", rest, maxsplit=1)[0]
        host = address.rpartition(":")[0].strip("[]") if ":" in address else address
        if host == "localhost":
            continue
        try:
            if ipaddress.ip_address(host).is_loopback:
                continue
        except ValueError:
            pass
        out.append(endpoint)
    return out


def free_endpoints(count: int, host: str = "127.0.0.1") -> list[str]:
    """``count`` TCP endpoints on ``host`` whose ports are free now (for agents started on loopback).

    Args:
        count: how many.
        host: the address to bind.

    Returns:
        Endpoints such as ``tcp/127.0.0.1:40123``, all different.
    """
    import socket

    sockets = []
    try:
        for _ in range(count):
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            s.bind((host, 0))
            sockets.append(s)
        return [f"tcp/{host}:{s.getsockname()[1]}" for s in sockets]
    finally:
        for s in sockets:
            s.close()
