"""What a replay shows at a moment: the team's state computed from a trace's events up to a time."""

from __future__ import annotations

import bisect
from collections.abc import Mapping
from typing import Any

from alica.app.center.team_view import TeamView
from alica.app.center.trace_file import Trace

CHECKPOINT_EVERY = 200
"""Events between two checkpoints of the replay's fold: ``state(t)`` folds fewer than this many."""

FAULT_KINDS = frozenset({"fault", "failure"})
"""Events the "next fault" button jumps to: injected faults (crash, recover, partition) and plan failures."""

REPLAN_KINDS = frozenset({"replan"})
"""Events the "next replan" button jumps to: the leader plans again after a failed step or a changed team."""


class Replay:
    """A trace indexed by time.

    Args:
        trace: the loaded trace.
        checkpoint_every: events between two checkpoints of :meth:`state`'s fold.
        entries: plan -> task -> entry state, from the trace's plan files (see :class:`TeamView`).
    """

    def __init__(
        self,
        trace: Trace,
        checkpoint_every: int = CHECKPOINT_EVERY,
        entries: Mapping[str, Mapping[str, str]] | None = None,
    ) -> None:
        if checkpoint_every < 1:
            raise ValueError(f"checkpoint_every must be at least 1, got {checkpoint_every}")
        self.every = checkpoint_every
        self.entries = entries
        self.trace = trace
        self.events = trace.events
        self.times = [float(e["t"]) for e in self.events]
        self._meta = self._describe()
        self._checkpoints = self._checkpoint()

    def agents(self) -> list[str]:
        """The agents named in the header or in the events (not the team's own ``-``)."""
        seen: dict[str, None] = dict.fromkeys(sorted(self.trace.roles))
        for e in self.events:
            agent = e.get("agent")
            if isinstance(agent, str) and agent not in ("-", "operator"):
                seen.setdefault(agent)
        return list(seen)

    def meta(self) -> dict[str, Any]:
        """Agents, start, end and duration, event kinds with their counts, and whether poses are present."""
        return self._meta

    def _describe(self) -> dict[str, Any]:
        kinds: dict[str, int] = {}
        for e in self.events:
            kinds[e["event"]] = kinds.get(e["event"], 0) + 1
        start = self.times[0] if self.times else 0.0
        end = self.times[-1] if self.times else 0.0
        return {
            "file": self.trace.path,
            "agents": self.agents(),
            "start": start,
            "end": end,
            "duration": end - start,
            "events": len(self.events),
            "kinds": dict(sorted(kinds.items())),
            "poses": "pose" in kinds,
            "header": self.trace.meta,
            "notes": self.trace.notes,
        }

    def window(self, start: float | None, end: float | None, kinds: set[str] | None) -> list[dict[str, Any]]:
        """The events with ``start <= t <= end`` of the given kinds (all kinds when ``None``)."""
        lo = 0 if start is None else bisect.bisect_left(self.times, start)
        hi = len(self.times) if end is None else bisect.bisect_right(self.times, end)
        return [e for e in self.events[lo:hi] if kinds is None or e["event"] in kinds]

    def next_time(self, after: float, kinds: frozenset[str]) -> float | None:
        """The time of the first event of ``kinds`` strictly after ``after``, or ``None``."""
        for i in range(bisect.bisect_right(self.times, after), len(self.events)):
            e = self.events[i]
            if e["event"] in kinds:
                return self.times[i]
        return None

    def state(self, t: float) -> dict[str, Any]:
        """The team at ``t``: :meth:`TeamView.snapshot` of the events up to ``t`` (without tracks).

        Every agent's role, task, alive, plan and state, its last pose, and the objects and
        the latest map. An agent's plans are the plan nodes it entered (keyed by their path,
        ``Top/State/Child``): an allocation enters a node (its task is the agent's entry
        there), a transition sets the node's state and leaves the nodes below it, a recovery
        starts from nothing. The agent's plan, task and state are those of its deepest node;
        ``plans`` lists them all, top first.

        The fold starts from the latest checkpoint at or before ``t`` (a copy of the view
        every ``checkpoint_every`` events), so it folds fewer than that many events.
        """
        count = bisect.bisect_right(self.times, t)
        index = min(count // self.every, len(self._checkpoints) - 1)
        view = self._checkpoints[index].copy()
        for e in self.events[index * self.every : count]:
            view.apply(e)
        return view.snapshot(t=t)

    def full_state(self, t: float) -> dict[str, Any]:
        """:meth:`state` folded from the first event, without checkpoints (slow; for checking them)."""
        view = self._fresh_view()
        for e in self.events[: bisect.bisect_right(self.times, t)]:
            view.apply(e)
        return view.snapshot(t=t)

    def _fresh_view(self) -> TeamView:
        return TeamView(self.trace.meta, self.trace.roles, self.agents(), entries=self.entries)

    def _checkpoint(self) -> list[TeamView]:
        view = self._fresh_view()
        checkpoints = [view.copy()]
        for i, e in enumerate(self.events, start=1):
            view.apply(e)
            if i % self.every == 0:
                checkpoints.append(view.copy())
        return checkpoints
