"""A fake ROS 2 node written from rmw_zenoh's design, independent of ``alica.comm.ros2.rmw``.

It joins a zenoh network on loopback (peer, scouting off, explicit endpoints), subscribes by the
documented data key expression, parses attachments itself, and reads the graph from the
``@ros2_lv/<domain>/**`` liveliness tokens, as ``ros2 node list`` / ``ros2 topic list -v`` would.
"""

from __future__ import annotations

import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import zenoh
import zenoh.ext


@dataclass(frozen=True)
class Received:
    key: str
    payload: bytes
    sequence: int
    timestamp_ns: int
    gid: bytes


@dataclass(frozen=True)
class Endpoint:
    kind: str
    namespace: str
    node: str
    topic: str
    type_name: str
    type_hash: str
    qos: str


def fake_attachment(sequence: int, timestamp_ns: int, gid: bytes) -> bytes:
    return struct.pack("<q", sequence) + struct.pack("<q", timestamp_ns) + bytes([len(gid)]) + gid


def demangle(chunk: str) -> str:
    return "" if chunk == "%" else chunk.replace("%", "/")


class FakeRos2:
    """The ROS 2 side of the tests: a zenoh peer connecting to ``connect``, or listening on ``listen`` (a router's place)."""

    def __init__(self, connect: str | None, domain: int = 0, *, listen: str | None = None) -> None:
        config = zenoh.Config()
        config.insert_json5("mode", '"peer"')
        config.insert_json5("connect/endpoints", f'["{connect}"]' if connect is not None else "[]")
        config.insert_json5("listen/endpoints", f'["{listen}"]' if listen is not None else "[]")
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("scouting/gossip/enabled", "false")
        self.session = zenoh.open(config)
        self.domain = domain
        self.received: list[Received] = []
        self._lock = threading.Lock()
        self._events = threading.Condition()
        self._generation = 0
        """Moves on with every sample and every token that comes or goes: :meth:`wait` wakes on it."""
        self._handles: list[object] = [
            self.session.liveliness().declare_subscriber(f"@ros2_lv/{domain}/**", lambda _sample: self._moved())
        ]

    def _moved(self) -> None:
        with self._events:
            self._generation += 1
            self._events.notify_all()

    def subscribe(self, key: str, *, history: bool = False) -> None:
        """Subscribe to a data key, e.g. ``0/robot1/pose/geometry_msgs::msg::dds_::PoseStamped_/*``."""

        def on_sample(sample: zenoh.Sample) -> None:
            raw = sample.attachment.to_bytes() if sample.attachment is not None else b""
            sequence, stamp = struct.unpack("<qq", raw[:16])
            gid = raw[17 : 17 + raw[16]]
            with self._lock:
                self.received.append(Received(str(sample.key_expr), sample.payload.to_bytes(), sequence, stamp, gid))
            self._moved()

        if history:
            self._handles.append(
                zenoh.ext.declare_advanced_subscriber(
                    self.session, key, on_sample, history=zenoh.ext.HistoryConfig(detect_late_publishers=True)
                )
            )
        else:
            self._handles.append(self.session.declare_subscriber(key, on_sample))

    def put(self, key: str, payload: bytes, attachment: bytes | None) -> None:
        """Publish as a reliable ROS 2 publisher keeping all samples does: blocking, never dropping, when the
        network is congested (a burst of 100 from a test on a loaded machine must all arrive)."""
        self.session.put(key, payload, attachment=attachment, congestion_control=zenoh.CongestionControl.BLOCK)

    def tokens(self) -> list[str]:
        replies = self.session.liveliness().get(f"@ros2_lv/{self.domain}/**", timeout=2.0)
        return sorted(str(reply.ok.key_expr) for reply in replies if reply.ok is not None)

    def nodes(self) -> set[tuple[str, str, str]]:
        """(enclave, namespace, name) of every node token."""
        found = set()
        for token in self.tokens():
            parts = token.split("/")
            if len(parts) == 9 and parts[5] == "NN":
                found.add((demangle(parts[6]), demangle(parts[7]), parts[8]))
        return found

    def endpoints(self) -> list[Endpoint]:
        found = []
        for token in self.tokens():
            parts = token.split("/")
            if len(parts) == 13 and parts[5] in ("MP", "MS"):
                found.append(Endpoint(parts[5], demangle(parts[7]), parts[8], demangle(parts[9]), *parts[10:13]))
        return found

    def wait(self, condition: Callable[[], bool], timeout: float = 5.0) -> bool:
        """Whether ``condition`` holds within ``timeout`` s: looked at again whenever a sample or a token arrives."""
        deadline = time.monotonic() + timeout
        while True:
            with self._events:
                seen = self._generation
            if condition():
                return True
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            with self._events:
                self._events.wait_for(lambda: self._generation != seen, remaining)
        return condition()

    def close(self) -> None:
        for handle in self._handles:
            handle.undeclare()  # type: ignore[attr-defined]
        self.session.close()
