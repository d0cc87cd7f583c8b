"""uvicorn's HTTP/1.1 protocol with a time-out on request headers (uvicorn has none; issue 37, finding 10).

A client that opens a connection and sends its request's headers slowly, or
never finishes them, holds the connection for as long as it likes under
plain uvicorn: enough such clients use up the server. :class:`HeaderTimeout`
closes a connection whose request headers are not complete
:attr:`HeaderTimeout.header_timeout` seconds after the connection opened
or the request's first bytes came. Idle kept-alive connections are uvicorn's
own affair (its ``timeout_keep_alive``).
"""

from __future__ import annotations

import asyncio

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

HEADER_TIMEOUT = 10.0
"""Seconds a client has to send a request's headers."""


class HeaderTimeout(H11Protocol):
    """:class:`H11Protocol` that closes connections whose request headers are late (pass as ``Config(http=...)``)."""

    header_timeout = HEADER_TIMEOUT
    """Seconds a client has to send a request's headers (a class attribute: tests shorten it)."""

    _header_task: asyncio.TimerHandle | None = None

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        super().connection_made(transport)
        self._arm()

    def data_received(self, data: bytes) -> None:
        if self._header_task is None and self.conn.their_state is h11.IDLE:
            self._arm()  # a kept-alive connection's next request begins
        super().data_received(data)
        if self.conn.their_state is not h11.IDLE:
            self._disarm()  # the headers are in

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)

    def _arm(self) -> None:
        self._disarm()
        self._header_task = self.loop.call_later(self.header_timeout, self._late)

    def _disarm(self) -> None:
        if self._header_task is not None:
            self._header_task.cancel()
            self._header_task = None

    def _late(self) -> None:
        self._header_task = None
        if self.conn.their_state is h11.IDLE and not self.transport.is_closing():
            self.transport.close()
