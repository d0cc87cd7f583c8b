"""What the zenoh transport takes from the network: every decoded frame checked for shape, types and bounds.

A peer on the network can send any bytes. Before the transport or its
:class:`~alica.comm.reliable.Inbox` uses a frame, a heartbeat, a history
question or a history answer, the functions here check it: the right tuple,
topics and names that are bounded strings, numbers that are ints within
bounds, times that are finite, dicts and lists of bounded length, payloads of
bounded size and nesting. A bad one raises :class:`BadFrame` with a
:class:`Reason`; the transport counts it in ``stats.rejected`` and drops it.
Nothing here recurses, hashes or compares what it has not checked first
(a tuple nested a million deep crashes CPython when hashed).
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping
from typing import Any

from alica.comm.codec import MAX_DEPTH as _CODEC_DEPTH
from alica.comm.codec import CodecError, TooDeep, decode

MAX_FRAME_BYTES = 16 * 1024 * 1024
"""The largest frame, heartbeat or history question taken in, in bytes."""
MAX_ANSWER_BYTES = 256 * 1024 * 1024
"""The largest history answer taken in, in bytes (a sender keeps up to ``history_mb``, 64 MB by default)."""
MAX_TOPIC = 256
"""The longest topic, in characters."""
MAX_NAME = 128
"""The longest sender name, in characters."""
MAX_NUMBER = 2**63 - 1
"""The largest incarnation or sequence number (an incarnation is the sender's ``time.time_ns()``)."""
MAX_TOPICS = 1024
"""The most topics in one heartbeat, history question or answer."""
MAX_DEPTH = _CODEC_DEPTH
"""The deepest nesting of a payload (tuples, lists, dicts, sets, dataclasses); the codec refuses deeper pickles."""
MAX_ITEMS = 1_000_000
"""The most values in one payload, all levels together."""


class Reason(enum.Enum):
    """Why a frame was dropped (the keys of ``stats.rejected``)."""

    SIZE = "size"
    """More bytes than the bound."""
    UNDECODABLE = "undecodable"
    """Not a pickle the codec takes (damaged, or naming a class that is not a message)."""
    SHAPE = "shape"
    """Not a tuple of the right length, or a field of the wrong type (a dict that is a list, ...)."""
    TOPIC = "topic"
    """A topic that is not a non-empty string of at most :data:`MAX_TOPIC` characters."""
    SENDER = "sender"
    """A sender that is not a non-empty name of at most :data:`MAX_NAME` characters, or not the one of the key."""
    NUMBER = "number"
    """An incarnation or sequence number that is not an int in bounds, or a time that is not finite."""
    NESTING = "nesting"
    """A payload nested deeper than :data:`MAX_DEPTH`, or with more than :data:`MAX_ITEMS` values."""
    ROSTER = "roster"
    """A sender, or a liveliness token's name, that is not in the team's roster."""


class BadFrame(ValueError):
    """What came from the network is not a frame to use; :attr:`reason` says why."""

    def __init__(self, reason: Reason, detail: str) -> None:
        super().__init__(f"{reason.value}: {detail}")
        self.reason = reason


def load(data: object, size: int, limit: int = MAX_FRAME_BYTES) -> tuple[Any, ...]:
    """The tuple of ``size`` items encoded in ``data``, its nesting checked.

    Raises:
        BadFrame: too big, undecodable, too deep, or not a tuple of ``size`` items.
    """
    if not isinstance(data, bytes):
        raise BadFrame(Reason.SHAPE, f"bytes expected, got {type(data).__name__}")
    if len(data) > limit:
        raise BadFrame(Reason.SIZE, f"{len(data)} bytes, at most {limit}")
    try:
        value = decode(data)
    except TooDeep as exc:  # (found in the pickle's opcodes, before the unpickler built anything)
        raise BadFrame(Reason.NESTING, str(exc)) from None
    except CodecError as exc:
        raise BadFrame(Reason.UNDECODABLE, str(exc)) from None
    check_nesting(value)
    if type(value) is not tuple or len(value) != size:
        raise BadFrame(Reason.SHAPE, f"a tuple of {size} items expected")
    return value


def check_nesting(value: object, depth: int = MAX_DEPTH, items: int = MAX_ITEMS) -> None:
    """Check, without recursion, that ``value`` nests at most ``depth`` deep and holds at most ``items`` values.

    Raises:
        BadFrame: (:attr:`Reason.NESTING`) it does not.
    """
    stack: list[tuple[object, int]] = [(value, 0)]
    seen = 0
    while stack:
        item, level = stack.pop()
        seen += 1
        if seen > items:
            raise BadFrame(Reason.NESTING, f"more than {items} values")
        children: Any
        if isinstance(item, str | bytes | bytearray | int | float | complex | enum.Enum) or item is None:
            continue
        if isinstance(item, tuple | list | set | frozenset):
            children = item
        elif isinstance(item, dict):
            children = [*item.keys(), *item.values()]
        elif dataclasses.is_dataclass(item) and not isinstance(item, type):
            children = [getattr(item, f.name, None) for f in dataclasses.fields(item)]
        else:
            continue
        if level >= depth:
            raise BadFrame(Reason.NESTING, f"nested deeper than {depth}")
        stack.extend((child, level + 1) for child in children)


def number(value: object, what: str, low: int = 0) -> int:
    """``value`` when it is an int in [``low``, :data:`MAX_NUMBER`] (no bool)."""
    if type(value) is not int or not low <= value <= MAX_NUMBER:
        raise BadFrame(Reason.NUMBER, f"{what} must be an int in [{low}, {MAX_NUMBER}]")
    return value


def moment(value: object, what: str) -> float:
    """``value`` as a float when it is a finite int or float (no bool)."""
    if type(value) not in (int, float) or not math.isfinite(value):  # type: ignore[arg-type]
        raise BadFrame(Reason.NUMBER, f"{what} must be a finite number")
    return float(value)  # type: ignore[arg-type]


def topic(value: object) -> str:
    """``value`` when it is a topic: a non-empty ``str`` of at most :data:`MAX_TOPIC` characters."""
    if type(value) is not str or not 0 < len(value) <= MAX_TOPIC:
        raise BadFrame(Reason.TOPIC, f"a topic is a non-empty string of at most {MAX_TOPIC} characters")
    return value


def sender(value: object) -> str:
    """``value`` when it is a sender: a non-empty ``str`` of at most :data:`MAX_NAME` characters, no '/'."""
    if type(value) is not str or not 0 < len(value) <= MAX_NAME or "/" in value:
        raise BadFrame(Reason.SENDER, f"a sender is a non-empty name of at most {MAX_NAME} characters")
    return value


def numbers_by_topic(value: object, what: str) -> dict[str, int]:
    """``value`` when it is a dict of at most :data:`MAX_TOPICS` topics to numbers."""
    if type(value) is not dict or len(value) > MAX_TOPICS:
        raise BadFrame(Reason.SHAPE, f"{what} must be a dict of at most {MAX_TOPICS} topics")
    return {topic(key): number(item, what) for key, item in value.items()}


def frame(value: tuple[Any, ...]) -> tuple[int, str, str, int, int, int, float, bytes]:
    """A message frame (see :data:`alica.comm.reliable.Frame`), its fields checked.

    Raises:
        BadFrame: a field of the wrong type or out of bounds.
    """
    if type(value) is not tuple or len(value) != 8:
        raise BadFrame(Reason.SHAPE, "a frame is a tuple of 8 items")
    incarnation, who, name, seq, rseq, gseq, sent_at, data = value
    checked_rseq = number(rseq, "rseq")
    checked_gseq = number(gseq, "gseq")
    if (checked_rseq == 0) != (checked_gseq == 0):
        raise BadFrame(Reason.NUMBER, "rseq and gseq are both 0 (best-effort) or both positive")
    if not isinstance(data, bytes):
        raise BadFrame(Reason.SHAPE, "a frame's payload is bytes")
    return (
        number(incarnation, "incarnation"),
        sender(who),
        topic(name),
        number(seq, "seq", 1),
        checked_rseq,
        checked_gseq,
        moment(sent_at, "sent_at"),
        data,
    )


def heartbeat(value: tuple[Any, ...]) -> tuple[int, str, dict[str, int]]:
    """A heartbeat (incarnation, sender, last reliable number per topic), checked."""
    incarnation, who, last = value
    return number(incarnation, "incarnation"), sender(who), numbers_by_topic(last, "a heartbeat's numbers")


def question(value: tuple[Any, ...]) -> tuple[str, int, dict[str, tuple[int | None, float]]]:
    """A history question (asker, incarnation, per topic (next number or ``None``, since)), checked."""
    who, incarnation, wanted = value
    if type(wanted) is not dict or len(wanted) > MAX_TOPICS:
        raise BadFrame(Reason.SHAPE, f"a question asks about at most {MAX_TOPICS} topics, in a dict")
    checked: dict[str, tuple[int | None, float]] = {}
    for key, entry in wanted.items():
        if type(entry) is not tuple or len(entry) != 2:
            raise BadFrame(Reason.SHAPE, "a question's entry is (next number or None, since)")
        first, since = entry
        checked[topic(key)] = (None if first is None else number(first, "next"), moment(since, "since"))
    return sender(who), number(incarnation, "incarnation"), checked


def answer(value: tuple[Any, ...]) -> tuple[int, str, tuple[bytes, ...], dict[str, int], dict[str, int]]:
    """A history answer (incarnation, sender, encoded frames, start and oldest per topic), checked."""
    incarnation, who, frames, start, oldest = value
    if type(frames) is not tuple or not all(isinstance(data, bytes) for data in frames):
        raise BadFrame(Reason.SHAPE, "an answer's frames are a tuple of bytes")
    return (
        number(incarnation, "incarnation"),
        sender(who),
        frames,
        numbers_by_topic(start, "an answer's start"),
        numbers_by_topic(oldest, "an answer's oldest"),
    )


def count(rejected: dict[str, int], reason: Reason) -> None:
    """Add one to ``rejected`` for ``reason``."""
    rejected[reason.value] = rejected.get(reason.value, 0) + 1


def by_reason(rejected: Mapping[str, int]) -> dict[str, int]:
    """A copy of ``rejected`` with its reasons in :class:`Reason` order."""
    return {reason.value: rejected[reason.value] for reason in Reason if reason.value in rejected}
