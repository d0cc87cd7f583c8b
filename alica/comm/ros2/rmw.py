"""ROS 2's rmw_zenoh wire format over eclipse-zenoh: a node, its publishers and subscribers.

A process on this module appears in the ROS 2 graph of ``rmw_zenoh_cpp`` nodes without a ROS
installation. It reproduces, from rmw_zenoh's ``docs/design.md`` and ``reference/ros2_zenoh.md``:

* **data keys** ``<domain>/<topic without the leading '/'>/<pkg::msg::dds_::Type_>/<type hash>``
  (the hash is ``RIHS01_<64 hex>`` from Jazzy, the literal ``TypeHashNotSupported`` on Humble);
* the **attachment** of every put, 33 bytes: int64 LE sequence number, int64 LE source timestamp
  (ns), one byte with the GID length (16), the 16-byte GID;
* **liveliness tokens** for nodes (``NN``), publishers (``MP``) and subscribers (``MS``), where a
  ``/`` inside a component is ``%`` and an empty namespace or enclave is ``%``, with the compact
  QoS form ``reliability:durability:history,depth:deadline:lifespan:liveliness`` (a default
  value is left empty, e.g. ``::,10:,:,:,,``).

Payloads are CDR bytes built elsewhere; this layer does not decode them. What a remote peer sends
(payload size, attachment) is checked here; a malformed sample is counted in
:attr:`Ros2Node.dropped` and dropped in zenoh's thread, never raised there.
"""

from __future__ import annotations

import logging
import os
import re
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import zenoh
import zenoh.ext

log = logging.getLogger(__name__)

ADMIN_SPACE = "@ros2_lv"
ROUTER = "tcp/127.0.0.1:7447"
"""rmw_zenohd's default endpoint on the local host."""
GID_SIZE = 16
ATTACHMENT_SIZE = 8 + 8 + 1 + GID_SIZE
MAX_PAYLOAD = 64 * 1024 * 1024
"""The largest payload a subscriber hands on (bytes); bigger ones are dropped and counted."""

_ENDPOINT = re.compile(r"(tcp|udp|tls|quic|ws)/(\[[0-9a-fA-F:.]+\]|[A-Za-z0-9.\-]+):(\d{1,5})")
_NAME = re.compile(r"[A-Za-z_~{}][A-Za-z0-9_/~{}]*|")


@dataclass(frozen=True, slots=True)
class Qos:
    """The QoS of a ROS 2 endpoint that rmw_zenoh carries (deadline, lifespan, liveliness stay default).

    Attributes:
        reliable: RELIABLE (default) or BEST_EFFORT.
        transient_local: TRANSIENT_LOCAL (late subscribers get the last ``depth`` samples) or VOLATILE.
        depth: history KEEP_LAST depth.
    """

    reliable: bool = True
    transient_local: bool = False
    depth: int = 10

    def __post_init__(self) -> None:
        if not 1 <= self.depth <= 100_000:
            raise ValueError(f"QoS depth must be within 1..100000, got {self.depth}")

    def text(self) -> str:
        """rmw_zenoh's compact form for liveliness tokens; defaults (RELIABLE=1, VOLATILE=2, KEEP_LAST=1) are empty."""
        reliability = "" if self.reliable else "2"
        durability = "1" if self.transient_local else ""
        return f"{reliability}:{durability}:,{self.depth}:,:,:,,"


DEFAULT = Qos()
LATCHED = Qos(reliable=True, transient_local=True, depth=1)
SENSOR = Qos(reliable=False, depth=5)


def mangle(name: str) -> str:
    """A name as a single key chunk: ``/`` becomes ``%``, an empty name is ``%``."""
    return name.replace("/", "%") if name else "%"


def fully_qualified(namespace: str, topic: str) -> str:
    """The fully qualified topic name: ``topic`` if it starts with ``/``, else under ``namespace``.

    Raises:
        ValueError: an empty topic, or a name ROS 2 would refuse.
    """
    if not topic or topic == "/":
        raise ValueError(f"a topic name must not be empty, got {topic!r}")
    for what, name in (("namespace", namespace.strip("/")), ("topic", topic.strip("/"))):
        if not _NAME.fullmatch(name) or "//" in name:
            raise ValueError(f"ROS 2 {what} {name!r} has characters other than letters, digits, '_' and '/'")
    if topic.startswith("/"):
        return topic.rstrip("/")
    ns = namespace.strip("/")
    return f"/{ns}/{topic.rstrip('/')}" if ns else f"/{topic.rstrip('/')}"


def topic_key(domain: int, topic_fqn: str, dds_type: str, type_hash: str) -> str:
    """The data key expression, e.g. ``0/robot1/pose/geometry_msgs::msg::dds_::PoseStamped_/RIHS01_...``."""
    return f"{domain}/{topic_fqn.lstrip('/')}/{dds_type}/{type_hash}"


def attachment(sequence: int, timestamp_ns: int, gid: bytes) -> bytes:
    """The 33-byte attachment of a put: sequence, source timestamp (ns), GID length, GID.

    Raises:
        ValueError: a GID that is not 16 bytes.
    """
    if len(gid) != GID_SIZE:
        raise ValueError(f"a GID has {GID_SIZE} bytes, got {len(gid)}")
    return struct.pack("<qqB", sequence, timestamp_ns, GID_SIZE) + gid


def parse_attachment(data: bytes) -> tuple[int, int, bytes]:
    """(sequence, timestamp_ns, gid) of an attachment.

    Raises:
        ValueError: not 33 bytes, or a GID length other than 16.
    """
    if len(data) != ATTACHMENT_SIZE:
        raise ValueError(f"an rmw_zenoh attachment has {ATTACHMENT_SIZE} bytes, got {len(data)}")
    sequence, timestamp, size = struct.unpack_from("<qqB", data)
    if size != GID_SIZE:
        raise ValueError(f"an rmw_zenoh attachment's GID has {GID_SIZE} bytes, got a length of {size}")
    return sequence, timestamp, bytes(data[17:])


def node_token(domain: int, session_id: str, node_id: int, namespace: str, name: str, enclave: str = "") -> str:
    """The liveliness token of a node (``NN``); the node id is repeated as the entity id."""
    return f"{ADMIN_SPACE}/{domain}/{session_id}/{node_id}/{node_id}/NN/{mangle(enclave)}/{mangle(namespace)}/{name}"


def endpoint_token(
    domain: int,
    session_id: str,
    node_id: int,
    entity_id: int,
    kind: str,
    namespace: str,
    node: str,
    topic_fqn: str,
    dds_type: str,
    type_hash: str,
    qos: Qos,
    enclave: str = "",
) -> str:
    """The liveliness token of a publisher (``kind="MP"``) or a subscriber (``"MS"``).

    Raises:
        ValueError: another kind.
    """
    if kind not in ("MP", "MS"):
        raise ValueError(f"an endpoint token's kind is 'MP' or 'MS', got {kind!r}")
    return (
        f"{ADMIN_SPACE}/{domain}/{session_id}/{node_id}/{entity_id}/{kind}/{mangle(enclave)}/{mangle(namespace)}/"
        f"{node}/{mangle(topic_fqn)}/{dds_type}/{type_hash}/{qos.text()}"
    )


def open_session(router: str | None, *, listen: list[str] | None = None) -> zenoh.Session:
    """A zenoh session: a client of ``router`` (e.g. :data:`ROUTER`), or with ``None`` a peer that scouts nothing.

    Raises:
        ValueError: an endpoint that is not ``proto/host:port``, or zenoh refusing the configuration.
    """
    for endpoint in ([router] if router is not None else []) + list(listen or []):
        match = _ENDPOINT.fullmatch(endpoint)
        if match is None or not 0 < int(match.group(3)) < 65536:
            raise ValueError(f"a zenoh endpoint looks like 'tcp/127.0.0.1:7447', got {endpoint!r}")
    config = zenoh.Config()
    settings: dict[str, str] = {
        "mode": '"client"' if router is not None else '"peer"',
        "connect/endpoints": f'["{router}"]' if router is not None else "[]",
        "listen/endpoints": "[" + ",".join(f'"{e}"' for e in listen or []) + "]",
        "scouting/multicast/enabled": "false",
        "scouting/gossip/enabled": "false",
        "timestamping/enabled": '{"router": true, "peer": true, "client": true}',
    }
    try:
        for key, value in settings.items():
            config.insert_json5(key, value)
        return zenoh.open(config)
    except zenoh.ZError as exc:
        raise ValueError(f"zenoh could not open a session (router {router!r}, listen {listen}): {exc}") from None


class Ros2Publisher:
    """One ROS 2 publisher; made by :meth:`Ros2Node.publisher`.

    A TRANSIENT_LOCAL publisher is zenoh's advanced publisher (``zenoh.ext``) with a cache of
    ``depth`` samples and publisher detection, as rmw_zenoh declares it; advanced subscribers
    (``history``) get those samples when they join.
    """

    def __init__(self, node: Ros2Node, key: str, qos: Qos, gid: bytes, token: zenoh.LivelinessToken) -> None:
        self.key = key
        self.qos = qos
        self.gid = gid
        self._token = token
        self._sequence = 0
        self._lock = threading.Lock()
        congestion = zenoh.CongestionControl.BLOCK if qos.reliable else zenoh.CongestionControl.DROP
        self._publisher: zenoh.Publisher | zenoh.ext.AdvancedPublisher
        if qos.transient_local:
            self._publisher = zenoh.ext.declare_advanced_publisher(
                node.session,
                key,
                congestion_control=congestion,
                cache=zenoh.ext.CacheConfig(qos.depth),
                publisher_detection=True,
            )
        else:
            self._publisher = node.session.declare_publisher(key, congestion_control=congestion)

    def put(self, payload: bytes, timestamp_ns: int | None = None) -> int:
        """Publish CDR ``payload`` with its attachment; returns the sequence number (1, 2, ...)."""
        with self._lock:
            self._sequence += 1
            sequence = self._sequence
            stamp = time.time_ns() if timestamp_ns is None else timestamp_ns
            self._publisher.put(payload, attachment=attachment(sequence, stamp, self.gid))
        return sequence

    def close(self) -> None:
        """Undeclare the publisher and its token."""
        self._token.undeclare()
        self._publisher.undeclare()


class Ros2Node:
    """A ROS 2 node on a zenoh session in rmw_zenoh's format; ``close()`` undeclares everything.

    Args:
        session: a session from :func:`open_session` (the node does not close it).
        name: the node's name.
        namespace: its namespace (``""`` or ``/robot1``).
        domain: the ROS domain id.
        enclave: the security enclave (``""`` for none).

    Raises:
        ValueError: a bad name, namespace or domain.
    """

    def __init__(
        self, session: zenoh.Session, name: str, namespace: str = "", *, domain: int = 0, enclave: str = ""
    ) -> None:
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise ValueError(f"a ROS 2 node name has letters, digits and '_', got {name!r}")
        if not 0 <= domain <= 232:
            raise ValueError(f"a ROS 2 domain id is within 0..232, got {domain}")
        fully_qualified(namespace, "x")
        self.session = session
        self.name = name
        self.namespace = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self.domain = domain
        self.enclave = enclave
        self.session_id = str(session.zid())
        self.dropped = 0
        """Samples a subscriber dropped: an attachment, or a payload, that was malformed or too big."""
        self._lock = threading.Lock()
        self._ids = 0
        self.node_id = self._next_id()
        self._token = session.liveliness().declare_token(
            node_token(domain, self.session_id, self.node_id, self.namespace, name, enclave)
        )
        self._publishers: list[Ros2Publisher] = []
        self._subscribers: list[
            tuple[zenoh.Subscriber[None] | zenoh.ext.AdvancedSubscriber[None], zenoh.LivelinessToken]
        ] = []
        self._closed = False

    def _next_id(self) -> int:
        self._ids += 1
        return self._ids

    def _endpoint(self, kind: str, topic: str, dds_type: str, type_hash: str, qos: Qos) -> tuple[str, str]:
        """The endpoint's topic key expression and its liveliness token's (declared by the caller)."""
        if self._closed:
            raise RuntimeError(f"node {self.name!r} is closed")
        fqn = fully_qualified(self.namespace, topic)
        entity = self._next_id()
        token = endpoint_token(
            self.domain,
            self.session_id,
            self.node_id,
            entity,
            kind,
            self.namespace,
            self.name,
            fqn,
            dds_type,
            type_hash,
            qos,
            self.enclave,
        )
        return topic_key(self.domain, fqn, dds_type, type_hash), token

    def publisher(self, topic: str, dds_type: str, type_hash: str, qos: Qos = DEFAULT) -> Ros2Publisher:
        """A publisher on ``topic`` (relative to the namespace without a leading ``/``), with its ``MP`` token."""
        key, token_key = self._endpoint("MP", topic, dds_type, type_hash, qos)
        token = self.session.liveliness().declare_token(token_key)
        gid = os.urandom(GID_SIZE)
        publisher = Ros2Publisher(self, key, qos, gid, token)
        self._publishers.append(publisher)
        return publisher

    def subscribe(
        self,
        topic: str,
        dds_type: str,
        type_hash: str,
        callback: Callable[[bytes, tuple[int, int, bytes] | None], None],
        qos: Qos = DEFAULT,
    ) -> None:
        """Call ``callback(payload, attachment or None)`` from zenoh's thread for each sample on ``topic``.

        A TRANSIENT_LOCAL subscriber is an advanced subscriber asking for the publishers' history.
        A sample with a malformed attachment or a payload over :data:`MAX_PAYLOAD` is dropped and
        counted in :attr:`dropped`; an exception from ``callback`` is logged, not raised.
        """
        key, token_key = self._endpoint("MS", topic, dds_type, type_hash, qos)

        def on_sample(sample: zenoh.Sample) -> None:
            try:
                extra = sample.attachment
                meta = None if extra is None else parse_attachment(extra.to_bytes())
                payload = sample.payload.to_bytes()
                if len(payload) > MAX_PAYLOAD:
                    raise ValueError(f"payload of {len(payload)} bytes")
            except ValueError as exc:
                with self._lock:
                    self.dropped += 1
                log.debug("node %s dropped a sample on %s: %s", self.name, key, exc)
                return
            try:
                callback(payload, meta)
            except Exception:
                log.exception("node %s: the callback of %s raised", self.name, key)

        subscriber: zenoh.Subscriber[None] | zenoh.ext.AdvancedSubscriber[None]
        if qos.transient_local:
            subscriber = zenoh.ext.declare_advanced_subscriber(
                self.session,
                key,
                on_sample,
                history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=qos.depth),
            )
        else:
            subscriber = self.session.declare_subscriber(key, on_sample)
        # the token after the subscription: a publisher that sees it may publish at once, and the session sends
        # its declarations in order, so the router knows the subscription first
        token = self.session.liveliness().declare_token(token_key)
        self._subscribers.append((subscriber, token))

    def close(self) -> None:
        """Undeclare the publishers, subscribers and tokens of this node (the session stays open)."""
        if self._closed:
            return
        self._closed = True
        for publisher in self._publishers:
            publisher.close()
        for subscriber, token in self._subscribers:
            token.undeclare()
            subscriber.undeclare()
        self._token.undeclare()
