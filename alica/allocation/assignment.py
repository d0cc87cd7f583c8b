"""The values allocation produces: an assignment of agents to entry points, and a result."""

from __future__ import annotations

import itertools
from bisect import bisect_left
from collections.abc import Iterable, Mapping
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Assignment:
    """Which entry point of a plan each agent takes (``None``: the agent idles).

    The entries are kept sorted by agent; the constructor sorts them and rejects
    an agent listed twice.

    Args:
        plan: the plan's name.
        entries: ``(agent, entry point name or None)`` pairs.
        utility: the assignment's utility U.

    Raises:
        ValueError: an agent appears more than once.
    """

    plan: str
    entries: tuple[tuple[str, str | None], ...]
    utility: float

    def __post_init__(self) -> None:
        entries = tuple(sorted(self.entries, key=lambda pair: pair[0]))
        for (first, _), (second, _) in itertools.pairwise(entries):
            if first == second:
                raise ValueError(f"assignment of plan '{self.plan}' lists agent '{first}' twice")
        object.__setattr__(self, "entries", entries)

    @classmethod
    def of(
        cls, plan: str, entries: Mapping[str, str | None] | Iterable[tuple[str, str | None]], utility: float
    ) -> Assignment:
        """Build an assignment from a mapping or pairs in any order.

        Args:
            plan: the plan's name.
            entries: agent -> entry point name (``None`` for idle).
            utility: the assignment's utility.

        Returns:
            The assignment, entries sorted by agent.
        """
        pairs = entries.items() if isinstance(entries, Mapping) else entries
        return cls(plan, tuple(pairs), utility)

    def entry_of(self, agent: str) -> str | None:
        """The entry point ``agent`` takes, ``None`` if it idles.

        Raises:
            KeyError: the agent is not part of the assignment.
        """
        index = bisect_left(self.entries, agent, key=lambda pair: pair[0])
        if index < len(self.entries) and self.entries[index][0] == agent:
            return self.entries[index][1]
        raise KeyError(f"agent '{agent}' is not in the assignment of plan '{self.plan}'")

    def agents_of(self, entry_point: str) -> tuple[str, ...]:
        """The agents that take ``entry_point``, sorted."""
        return tuple(agent for agent, entry in self.entries if entry == entry_point)

    @property
    def agents(self) -> tuple[str, ...]:
        """Every agent of the assignment (idle ones included), sorted."""
        return tuple(agent for agent, _ in self.entries)

    @property
    def idle(self) -> tuple[str, ...]:
        """The agents that idle, sorted."""
        return tuple(agent for agent, entry in self.entries if entry is None)

    def as_dict(self) -> dict[str, str | None]:
        """Agent -> entry point name (``None`` for idle), in agent order."""
        return dict(self.entries)

    def __str__(self) -> str:
        parts = ", ".join(f"{agent}->{entry if entry is not None else '-'}" for agent, entry in self.entries)
        return f"{self.plan}[{parts}] U={self.utility:.6f}"


@dataclass(frozen=True, slots=True)
class AllocationResult:
    """What a search returns.

    Args:
        assignment: the optimal assignment, ``None`` when no valid one exists.
        expansions: search nodes expanded (for :func:`~alica.allocation.exhaustive`:
            complete assignments enumerated).
        why: when ``assignment`` is ``None``, what prevents an assignment.
    """

    assignment: Assignment | None
    expansions: int
    why: str = ""
