"""Lamport stamps: the order in which last-writer-wins registers resolve conflicts.

Every write carries a :class:`Stamp` ``(counter, writer)``. Stamps are totally
ordered: first by the Lamport counter, then by the writer id compared as a
string. Because a replica's counter is always one more than the largest
counter it has seen (its own writes and everything merged), a write made after
a merge is larger than every write merged so far.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True, order=True)
class Stamp:
    """When and by whom a write was made.

    Ordering compares ``counter`` first, then ``writer`` as a string, so any
    two distinct stamps are ordered the same way on every replica.

    Args:
        counter: the Lamport counter of the write, at least 1.
        writer: the id of the agent that made the write, a non-empty string.

    Raises:
        ValueError: ``counter`` is not a positive int or ``writer`` is not a
            non-empty string.
    """

    counter: int
    writer: str

    def __post_init__(self) -> None:
        if type(self.counter) is not int or self.counter < 1:
            raise ValueError(f"a stamp counter must be an int >= 1, got {self.counter!r}")
        if type(self.writer) is not str or not self.writer:
            raise ValueError(f"a stamp writer must be a non-empty agent id string, got {self.writer!r}")

    def __str__(self) -> str:
        return f"{self.counter}@{self.writer}"


def newer(counter: int, writer: str, other_counter: int, other_writer: str) -> bool | None:
    """Whether stamp ``(counter, writer)`` is larger than the other one.

    A tuple-free comparison for the merge loop.

    Args:
        counter: counter of the first stamp.
        writer: writer of the first stamp.
        other_counter: counter of the second stamp.
        other_writer: writer of the second stamp.

    Returns:
        ``True`` if the first is larger, ``False`` if smaller, ``None`` if the
        stamps are equal.
    """
    if counter != other_counter:
        return counter > other_counter
    if writer != other_writer:
        return writer > other_writer
    return None


class LamportClock:
    """A Lamport counter owned by one agent.

    Args:
        writer: the agent id put into every stamp this clock makes.

    Raises:
        ValueError: ``writer`` is not a non-empty string.
    """

    __slots__ = ("_counter", "_writer")

    def __init__(self, writer: str) -> None:
        if type(writer) is not str or not writer:
            raise ValueError(f"an agent id must be a non-empty string, got {writer!r}")
        self._writer = writer
        self._counter = 0

    @property
    def writer(self) -> str:
        """The agent id of this clock."""
        return self._writer

    @property
    def counter(self) -> int:
        """The largest counter seen or used so far (0 before anything)."""
        return self._counter

    def peek(self) -> Stamp:
        """The stamp the next local write will get, without using it."""
        return Stamp(self._counter + 1, self._writer)

    def tick(self) -> Stamp:
        """Use and return the stamp of a new local write."""
        self._counter += 1
        return Stamp(self._counter, self._writer)

    def observe(self, counter: int) -> None:
        """Remember a counter seen in a merged write (Lamport rule)."""
        self._counter = max(self._counter, counter)

    def __repr__(self) -> str:
        return f"LamportClock({self._writer!r}, {self._counter})"
