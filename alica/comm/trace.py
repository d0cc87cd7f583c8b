"""Trace events of the simulated network, as plain JSON-able dicts for an observer.

Every event has ``t`` (simulated time) and ``event``: ``send``, ``deliver``
and ``drop`` (message events, with ``topic``, ``sender``, ``seq`` and, for
deliver and drop, ``receiver``; drops have a ``reason``: ``loss``,
``partition``, ``crash``, ``closed`` or ``superseded``), and ``partition``,
``heal``, ``crash``, ``recover`` (fault events). Message events are built
only when the network traces messages, so a run without tracing pays nothing
for them.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from alica.comm.faults import Partition
from alica.comm.transport import Envelope

logger = logging.getLogger(__name__)

Observer = Callable[[dict[str, object]], None]
"""Receives one JSON-able dict per trace event; it must not call back into the network."""


class Tracer:
    """Builds trace events and hands them to the observer.

    Args:
        observer: receives the events, or ``None`` to drop them.
        messages: also report message events (send, deliver, drop).
    """

    __slots__ = ("messages", "observer")

    def __init__(self, observer: Observer | None, messages: bool) -> None:
        self.observer = observer
        self.messages = observer is not None and messages

    def fault(self, event: dict[str, object]) -> None:
        """Report a fault event (always, when there is an observer)."""
        logger.debug("network event %s", event)
        if self.observer is not None:
            self.observer(event)

    def partition(self, cut: Partition, t: float) -> None:
        """Report that ``cut`` began at ``t``."""
        self.fault(
            {
                "t": t,
                "event": "partition",
                "id": cut.handle.id,
                "groups": cut.describe(),
                "start": cut.start,
                "end": cut.end,
            }
        )

    def message(self, t: float, event: str, envelope: Envelope, receiver: str | None, **extra: object) -> None:
        """Report a message event; call only when :attr:`messages` is true.

        Args:
            t: when it happened.
            event: ``send``, ``deliver`` or ``drop``.
            envelope: the message.
            receiver: the receiving agent, ``None`` for ``send``.
            **extra: more fields, e.g. ``reason`` or ``qos``.
        """
        record: dict[str, object] = {
            "t": t,
            "event": event,
            "topic": envelope.topic,
            "sender": envelope.sender,
            "seq": envelope.seq,
        }
        if receiver is not None:
            record["receiver"] = receiver
        record.update(extra)
        if self.observer is not None:
            self.observer(record)
