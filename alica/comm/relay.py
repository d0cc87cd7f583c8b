"""A TCP relay in front of an agent's endpoint: cut it to make a partition, heal it to end one.

Tests and ``alica run --processes --partition`` need partitions without
touching the host's network (no ``ip link``, no root). Each link between two
agents then goes through its own :class:`LinkRelay`: one agent connects to
the relay's endpoint instead of the other's, and the relay forwards the
bytes. :meth:`LinkRelay.cut` closes every connection and refuses new ones
(zenoh sees the link die, exactly as when a cable is pulled and the lease
ends, only sooner); :meth:`LinkRelay.heal` lets zenoh's reconnection through
again.
"""

from __future__ import annotations

import socket
import threading


def _address(endpoint: str) -> tuple[str, int]:
    """``("127.0.0.1", 7447)`` from ``tcp/127.0.0.1:7447`` (or ``tls/...``: TLS goes through the relay untouched)."""
    proto, _, rest = endpoint.partition("/")
    host, _, port = rest.rpartition(":")
    if proto not in ("tcp", "tls") or not host or not port.isdigit():
        raise ValueError(f"a relay forwards to a TCP endpoint such as 'tcp/127.0.0.1:7447', got {endpoint!r}")
    return host, int(port)


class LinkRelay:
    """Forwards TCP connections from its own port to ``target``, until cut.

    Args:
        target: the endpoint it forwards to, ``tcp/HOST:PORT``.
        host: the address it listens on.

    Attributes:
        endpoint: the endpoint to connect to instead of ``target``.
    """

    def __init__(self, target: str, host: str = "127.0.0.1") -> None:
        self._target = _address(target)
        self._server = socket.create_server((host, 0))
        self.endpoint = f"{target.partition('/')[0]}/{host}:{self._server.getsockname()[1]}"
        self._lock = threading.Lock()
        self._open: set[socket.socket] = set()
        self._cut = False
        self._closed = False
        threading.Thread(target=self._accept, name=f"relay-{self.endpoint}", daemon=True).start()

    @property
    def is_cut(self) -> bool:
        """Whether the relay is cut now."""
        return self._cut

    def cut(self) -> None:
        """Close every forwarded connection and refuse new ones until :meth:`heal`."""
        with self._lock:
            self._cut = True
            sockets = list(self._open)
            self._open.clear()
        for s in sockets:
            _shut(s)

    def heal(self) -> None:
        """Forward new connections again (the agents reconnect by themselves)."""
        with self._lock:
            self._cut = False

    def close(self) -> None:
        """Stop relaying for good."""
        with self._lock:
            self._closed = True
        self.cut()
        self._server.close()

    def _accept(self) -> None:
        while True:
            try:
                client, _ = self._server.accept()
            except OSError:
                return
            with self._lock:
                refuse = self._cut or self._closed
            if refuse:
                _shut(client)
                continue
            try:
                upstream = socket.create_connection(self._target, timeout=2.0)
                upstream.settimeout(None)
            except OSError:
                _shut(client)
                continue
            for s in (client, upstream):
                s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._open.update((client, upstream))
            for a, b in ((client, upstream), (upstream, client)):
                threading.Thread(target=self._pump, args=(a, b), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket) -> None:
        try:
            while True:
                data = source.recv(65536)
                if not data:
                    break
                sink.sendall(data)
        except OSError:
            pass
        finally:
            with self._lock:
                self._open.discard(source)
                self._open.discard(sink)
            _shut(source)
            _shut(sink)


def _shut(s: socket.socket) -> None:
    try:
        s.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
    s.close()
