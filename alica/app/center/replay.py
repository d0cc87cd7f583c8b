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
        self._meta = self._describe()

    def agents(self) -> list[str]:
        """The agents named in the header or in the events (not the team's own ``-``)."""
        seen: dict[str, None] = dict.fromkeys(sorted(self.trace.roles))
        for e in self.events:
            agent = e.get("agent")
            if isinstance(agent, str) and agent != "-":
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
        """Every agent's role, task, alive, plan and state, and its last pose, from the events up to ``t``.

        An agent's plans are the plan nodes it entered (keyed by their path, ``Top/State/Child``):
        an allocation enters a node (its task is the agent's entry there), a transition sets the
        node's state and leaves the nodes below it, a recovery starts from nothing. The agent's
        plan, task and state are those of its deepest node; ``plans`` lists them all, top first.
        """
        roles = self.trace.roles
        agents: dict[str, dict[str, Any]] = {
            a: {
                "role": roles.get(a),
                "alive": True,
                "behaviour": None,
                "pose": None,
            }
            for a in self.agents()
        }
        nodes: dict[str, dict[str, dict[str, Any]]] = {a: {} for a in agents}
        for e in self.events[: bisect.bisect_right(self.times, t)]:
            kind = e["event"]
            name = str(e.get("agent"))
            who = agents.get(name)
            if who is None:
                continue
            key = str(e.get("key", ""))
            if kind == "fault" and e.get("fault") in ("crash", "recover"):
                who["alive"] = e["fault"] == "recover"
                if e["fault"] == "recover":
                    nodes[name].clear()
                    who["behaviour"] = None
            elif kind == "allocation" and isinstance(e.get("entries"), dict):
                node = nodes[name].get(key)
                if node is None or e.get("reason") == "initial":
                    node = nodes[name][key] = {"key": key, "plan": e.get("plan"), "task": None, "state": None}
                node["plan"] = e.get("plan", node["plan"])
                node["task"] = e["entries"].get(name)
            elif kind == "transition":
                node = nodes[name].setdefault(key, {"key": key, "plan": e.get("plan"), "task": None, "state": None})
                node["state"] = e.get("target")
                for below in [k for k in nodes[name] if k.startswith(key + "/")]:
                    del nodes[name][below]
            elif kind == "behaviour":
                who["behaviour"] = f"{e.get('behaviour')} ({e.get('status')})"
            elif kind == "pose":
                who["pose"] = {k: e[k] for k in ("x", "y", "yaw") if k in e}
            elif kind == "role" and "role" in e:
                who["role"] = e["role"]
        for name, who in agents.items():
            plans = sorted(nodes[name].values(), key=lambda n: n["key"].count("/"))
            deepest = plans[-1] if plans else {"key": None, "plan": None, "task": None, "state": None}
            who.update({k: deepest[k] for k in ("key", "plan", "task", "state")}, plans=plans)
        return {"t": t, "agents": agents}
