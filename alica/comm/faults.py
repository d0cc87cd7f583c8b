"""Partitions of the simulated network: who cannot talk to whom, and when."""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

_REST = -1
"""Group index of the agents a partition does not list: they form one group together."""


@dataclass(frozen=True, slots=True)
class PartitionHandle:
    """Names one partition of a network, to heal it later.

    Attributes:
        id: the partition's number in its network, from 1.
    """

    id: int


class Partition:
    """One partition: a split of the agents into groups over a time interval.

    Agents in different groups cannot talk while ``start <= t < end``. The
    interval is kept after it is over while messages in flight may still need
    it; ``end`` is ``None`` until healed.

    Args:
        handle: the partition's handle.
        groups: group index per listed agent.
        start: when the cut begins.
        end: when it ends, or ``None`` for "until healed".
    """

    __slots__ = ("end", "groups", "handle", "start")

    def __init__(self, handle: PartitionHandle, groups: dict[str, int], start: float, end: float | None) -> None:
        self.handle = handle
        self.groups = groups
        self.start = start
        self.end = end

    def separates(self, a: str, b: str, t: float) -> bool:
        """True when ``a`` and ``b`` are in different groups and the cut holds at ``t``."""
        if t < self.start or (self.end is not None and t >= self.end):
            return False
        groups = self.groups
        return groups.get(a, _REST) != groups.get(b, _REST)

    def over(self, t: float) -> bool:
        """True when the cut has ended (or was cancelled) by time ``t``."""
        return self.end is not None and (self.end <= t or self.end <= self.start)

    def describe(self) -> list[list[str]]:
        """The listed groups as sorted lists of names, in a deterministic order."""
        by_group: dict[int, list[str]] = {}
        for name, index in self.groups.items():
            by_group.setdefault(index, []).append(name)
        return sorted(sorted(names) for names in by_group.values())


def group_map(groups: Iterable[Iterable[str]], known: Collection[str]) -> dict[str, int]:
    """Check the groups of a partition and number them.

    Args:
        groups: groups of agent ids; agents not listed form one more group.
        known: the attached agent ids.

    Returns:
        Group index per listed agent id.

    Raises:
        ValueError: no group, a bare string instead of a group, an unknown
            agent, or an agent in two groups.
    """
    if isinstance(groups, str):
        raise ValueError("partition groups must be a list of groups of agent ids, e.g. [['a', 'b'], ['c']]")
    mapping: dict[str, int] = {}
    count = 0
    for index, group in enumerate(groups):
        count += 1
        if isinstance(group, str):
            raise ValueError(
                f"partition group {group!r} is a string; give each group as a list of agent ids, e.g. [{group!r}]"
            )
        names = list(group)
        for name in names:
            if not isinstance(name, str):
                raise ValueError(f"partition groups hold agent ids (strings), got {name!r}")
        for name in sorted(names):
            if name not in known:
                raise ValueError(f"partition names unknown agent {name!r}; attach it to the network first")
            if name in mapping:
                raise ValueError(f"agent {name!r} is in two partition groups; put each agent in one group only")
            mapping[name] = index
    if count == 0:
        raise ValueError("partition needs at least one group of agent ids")
    return mapping


def check_time(name: str, value: object, now: float) -> float:
    """Validate a point in time that must not lie in the past.

    Args:
        name: what the value is, for the message.
        value: the time in seconds.
        now: the current time.

    Returns:
        The time as a float.

    Raises:
        ValueError: not a finite number, or earlier than now.
    """
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite time in seconds, got {value!r}")
    if value < now:
        raise ValueError(f"{name}={value} lies in the past (now is {now}); give a time >= now, or None for now")
    return float(value)


def describe_fault(record: Mapping[str, Any]) -> str:
    """One line for a fault record (``fault``, ``agent``, ``t``; a partition's ``groups``, ``start``, ``end``).

    Times print as given, in the form of ``alica run``'s options:
    ``crash scout@2``, ``partition scout|amparo,stummel@1-4`` (``@1`` alone when the cut lasts until healed).
    """
    kind = str(record.get("fault", "fault"))
    if kind == "partition" and "start" in record:
        groups = "|".join(",".join(group) for group in record.get("groups", ()))
        end = record.get("end")
        span = f"{record['start']:g}" + (f"-{end:g}" if end is not None else "")
        return f"partition {groups}@{span}"
    agent = record.get("agent", "-")
    return f"{kind}{f' {agent}' if agent != '-' else ''}@{float(record.get('t', 0.0)):g}"
