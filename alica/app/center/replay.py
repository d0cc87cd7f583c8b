"""What a replay shows at a moment: the team's state computed from a trace's events up to a time."""

from __future__ import annotations

import bisect
from typing import Any

from alica.app.center.trace_file import Trace

FAULT_KINDS = frozenset({"fault", "failure"})
"""Events the "next fault" button jumps to: injected faults (crash, recover, partition) and plan failures."""

REPLAN_KINDS = frozenset({"replan"})
"""Events the "next replan" button jumps to: the leader plans again after a failed step or a changed team."""


class Replay:
    """A trace indexed by time.

    Args:
        trace: the loaded trace.
    """

    def __init__(self, trace: Trace) -> None:
        self.trace = trace
        self.events = trace.events
        self.times = [float(e["t"]) for e in self.events]

    def agents(self) -> list[str]:
        """The agents named in the header or in the events (not the team's own ``-``)."""
        named = [str(a) for a in self.trace.meta.get("agents", []) if isinstance(a, str)]
        seen = dict.fromkeys(named)
        for e in self.events:
            agent = e.get("agent")
            if isinstance(agent, str) and agent != "-":
                seen.setdefault(agent)
        return list(seen)

    def meta(self) -> dict[str, Any]:
        """Agents, start, end and duration, event kinds with their counts, and whether poses are present."""
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
        """Every agent's role, task, alive, plan and state, and its last pose, from the events up to ``t``."""
        roles = self.trace.meta.get("roles", {})
        agents: dict[str, dict[str, Any]] = {
            a: {
                "role": roles.get(a) if isinstance(roles, dict) else None,
                "task": None,
                "alive": True,
                "plan": None,
                "state": None,
                "key": None,
                "behaviour": None,
                "pose": None,
            }
            for a in self.agents()
        }
        for e in self.events[: bisect.bisect_right(self.times, t)]:
            kind = e["event"]
            who = agents.get(str(e.get("agent")))
            if kind == "fault" and e.get("fault") in ("crash", "recover") and who is not None:
                who["alive"] = e["fault"] == "recover"
            elif who is None:
                continue
            elif kind == "allocation" and isinstance(e.get("entries"), dict):
                _enter(who, e)
                who["task"] = e["entries"].get(e["agent"])
                who["state"] = None
            elif kind == "transition":
                _enter(who, e)
                who["state"] = e.get("target")
            elif kind == "behaviour":
                who["behaviour"] = f"{e.get('behaviour')} ({e.get('status')})"
            elif kind == "pose":
                who["pose"] = {k: e[k] for k in ("x", "y", "yaw") if k in e}
            elif kind == "role" and "role" in e:
                who["role"] = e["role"]
        return {"t": t, "agents": agents}


def _enter(who: dict[str, Any], event: dict[str, Any]) -> None:
    """Make the event's plan the agent's current plan when it is as deep as or deeper than the last one."""
    key = str(event.get("key", ""))
    last = who["key"] or ""
    if key.count("/") >= last.count("/") or not last.startswith(key):
        who["key"], who["plan"] = key, event.get("plan", who["plan"])
