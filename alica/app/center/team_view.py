"""What the control center draws of a team, folded one event at a time.

:class:`TeamView` starts from a trace's header and takes the events in time
order (:meth:`TeamView.apply`); :meth:`TeamView.snapshot` gives, at any point,
the JSON-ready state the page draws. The replay folds a trace's events with it
(from checkpoints, :class:`alica.app.center.replay.Replay`), the live view the
events of a running team as they come.

The snapshot::

    {"t": 12.5,                   # the time of the last event applied (or the time asked for)
     "world": "lunar",            # blocks | lunar | none, from the header
     "bounds": [x0, y0, x1, y1],  # the field in metres, or None
     "agents": {NAME: {"role", "alive", "behaviour", "pose": {"x", "y", "yaw"} or None,
                       "key", "plan", "task", "state", "plans": [{"key", "plan", "task", "state"}, ...]}},
     "objects": {NAME: {"x", "y", "z", "kind", "sample_kind"?, "size"?, "radius"?,
                        "found"?: KIND, "found_as"?: TEAM_NAME}},
     "map": None or {"t", "origin": [x, y], "resolution", "width", "height",
                     "cells": "0012...",   # width * height digits, rows from the lowest y, each from the lowest x:
                     "free", "occupied"},  # 0 unknown, 1 free, 2 occupied; and the counts of free and occupied cells
     "operator": {"proposals": {PROBLEM: {"generation", "leader", "cost", "goal", "steps", "tasks", "error"?, "t"}},
                  "goals": {PROBLEM: GOAL},   # set by the operator
                  "running": {PROBLEM: {"generation", "version", "cost", "steps", "leader", "t"}}},
     "tracks"?: {NAME: [[t, x, y], ...]}}  # only with snapshot(since=...) of a view that keeps tracks

Tracks: a view built with ``tracks=True`` keeps each robot's poses as ``[t, x, y]``
and ``snapshot(since=T)`` gives those after ``T`` (``since=-inf`` all of them), so a
live page can ask for what it has not got yet. ``snapshot()`` leaves them out: the
replay's page collects tracks from the trace's ``pose`` events itself.

A ``found`` event (the team read a sample) marks the nearest ``sample`` object within
:data:`FOUND_WITHIN` metres of where the team believes it is (``found``: its kind,
``found_as``: the team's name of it); without such an object it becomes an object of
its own, named by the team's name, of kind ``sample``.

The operator's side comes from ``proposal`` events (a plan waiting for review),
``operator`` events (a goal; an accept, decline or modify answers the proposal of
its generation) and the leader's ``planner`` events that share a plan.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from alica.engine.trace import decode_cells
from alica.errors import TraceFormatError

FOUND_WITHIN = 1.0
"""Metres between a ``found`` event's position and the sample object it names."""

_NO_NODE: dict[str, Any] = {"key": None, "plan": None, "task": None, "state": None}


def header_roles(meta: Mapping[str, Any]) -> dict[str, str]:
    """Agent -> role, as a trace header's ``agents`` names them."""
    agents = meta.get("agents")
    if not isinstance(agents, dict):
        return {}
    return {
        str(name): str(info["role"])
        for name, info in agents.items()
        if isinstance(info, dict) and isinstance(info.get("role"), str)
    }


def _world(meta: Mapping[str, Any]) -> str:
    world = meta.get("world")
    return world if world in ("blocks", "lunar") else "none"


class TeamView:
    """The team's state, updated one event at a time.

    Args:
        meta: the trace header's fields (``agents``, ``world``, ``bounds``...); ``{}`` will do.
        roles: agent -> role; by default the header's.
        agents: the agents to show from the start (in this order), besides the header's; any
            other agent (not ``-``) is added when its first event comes.
        tracks: keep each robot's poses for ``snapshot(since=...)``.
        entries: plan -> task -> the state its entry point starts in (from the plan files,
            :func:`alica.app.center.plan_view.entry_states`): a plan node without a transition yet
            is in the entry state of the agent's task there.
    """

    def __init__(
        self,
        meta: Mapping[str, Any],
        roles: Mapping[str, str] | None = None,
        agents: Iterable[str] = (),
        *,
        tracks: bool = False,
        entries: Mapping[str, Mapping[str, str]] | None = None,
    ) -> None:
        self.entries = {plan: dict(tasks) for plan, tasks in (entries or {}).items()}
        self.roles = dict(header_roles(meta) if roles is None else roles)
        self.world = _world(meta)
        bounds = meta.get("bounds")
        self.bounds = list(bounds) if isinstance(bounds, list) else None
        self.keep_tracks = tracks
        self.t = 0.0
        self.agents: dict[str, dict[str, Any]] = {}
        self.nodes: dict[str, dict[str, dict[str, Any]]] = {}
        self.objects: dict[str, dict[str, Any]] = {}
        self.map: dict[str, Any] | None = None
        self.tracks: dict[str, list[list[float]]] = {}
        self.proposals: dict[str, dict[str, Any]] = {}
        """Planning problem -> the plan its leader proposes and the operator has not decided on (``--review``)."""
        self.goals: dict[str, str] = {}
        """Planning problem -> the goal the operator set."""
        self.running: dict[str, dict[str, Any]] = {}
        """Planning problem -> the plan the leader shared last (generation, version, cost, steps, leader, t)."""
        for name in (*sorted(self.roles), *agents):
            self._agent(name)

    def _agent(self, name: str) -> dict[str, Any]:
        who = self.agents.get(name)
        if who is None:
            who = self.agents[name] = {"role": self.roles.get(name), "alive": True, "behaviour": None, "pose": None}
            self.nodes[name] = {}
        return who

    def copy(self) -> TeamView:
        """An independent copy (the map, which is replaced and never changed, is shared)."""
        other = TeamView.__new__(TeamView)
        other.roles = self.roles
        other.entries = self.entries  # replaced after a reload (LiveHub), never changed in place
        other.world = self.world
        other.bounds = self.bounds
        other.keep_tracks = self.keep_tracks
        other.t = self.t
        other.agents = {a: {**who, "pose": who["pose"]} for a, who in self.agents.items()}
        other.nodes = {a: {k: dict(n) for k, n in nodes.items()} for a, nodes in self.nodes.items()}
        other.objects = {n: dict(o) for n, o in self.objects.items()}
        other.map = self.map
        other.tracks = {a: list(points) for a, points in self.tracks.items()}
        other.proposals = dict(self.proposals)  # the proposals themselves are replaced, never changed
        other.goals = dict(self.goals)
        other.running = dict(self.running)
        return other

    def apply(self, event: Mapping[str, Any]) -> None:
        """Take one event (events come in time order).

        An allocation enters a plan node (its task is the agent's entry there), a transition
        sets the node's state and leaves the nodes below it, a crash marks the agent dead and a
        recovery starts it from nothing; ``pose``, ``object``, ``found`` and ``map`` events move
        robots and objects and replace the map. A ``map`` event whose cells do not decode is
        left out. Events of other kinds change nothing but the time.

        Traces do not record a plan's initial state: until its first transition a node's
        state is ``None``; :meth:`snapshot` fills it in from a node below it
        (``KEY/STATE/CHILD`` names it), else from the entry point of the agent's task
        (``entries``), else leaves it ``None``.
        """
        kind = event.get("event")
        t = event.get("t")
        if isinstance(t, (int, float)):
            self.t = float(t)
        if kind == "object":
            self._object(event)
            return
        if kind == "found":
            self._found(event)
            return
        if kind == "map":
            self._map(event)
            return
        if kind in ("proposal", "operator") or (kind == "planner" and event.get("what") == "plan"):
            self._operator(kind, event)
        name = event.get("agent")
        if not isinstance(name, str) or name in ("-", "operator") or kind == "trace":
            return
        who = self._agent(name)
        nodes = self.nodes[name]
        key = str(event.get("key", ""))
        if kind == "fault" and event.get("fault") in ("crash", "recover"):
            who["alive"] = event["fault"] == "recover"
            if event["fault"] == "recover":
                nodes.clear()
                who["behaviour"] = None
        elif kind == "allocation" and isinstance(event.get("entries"), dict):
            node = nodes.get(key)
            if node is None or event.get("reason") == "initial":
                node = nodes[key] = {"key": key, "plan": event.get("plan"), "task": None, "state": None}
            node["plan"] = event.get("plan", node["plan"])
            node["task"] = event["entries"].get(name)
        elif kind == "transition":
            node = nodes.setdefault(key, {"key": key, "plan": event.get("plan"), "task": None, "state": None})
            node["state"] = event.get("target")
            for below in [k for k in nodes if k.startswith(key + "/")]:
                del nodes[below]
        elif kind == "behaviour":
            who["behaviour"] = f"{event.get('behaviour')} ({event.get('status')})"
        elif kind == "pose":
            who["pose"] = {k: event[k] for k in ("x", "y", "yaw") if k in event}
            x, y = event.get("x"), event.get("y")
            if self.keep_tracks and isinstance(x, (int, float)) and isinstance(y, (int, float)):
                self.tracks.setdefault(name, []).append([self.t, float(x), float(y)])
        elif kind == "role" and "role" in event:
            who["role"] = event["role"]

    def _object(self, event: Mapping[str, Any]) -> None:
        name = event.get("name")
        if not isinstance(name, str):
            return
        obj = self.objects.setdefault(name, {})
        for k in ("x", "y", "z", "kind", "sample_kind", "size", "radius"):
            if k in event:
                obj[k] = event[k]

    def _found(self, event: Mapping[str, Any]) -> None:
        name, x, y = event.get("name"), event.get("x"), event.get("y")
        if not isinstance(name, str) or not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
            return
        kind = str(event.get("kind") or "")
        best, nearest = None, FOUND_WITHIN
        for other, obj in self.objects.items():
            if obj.get("found_as") == name:
                best = other
                break
            if obj.get("kind") != "sample" or "found_as" in obj or "x" not in obj or "y" not in obj:
                continue
            d = math.hypot(float(obj["x"]) - x, float(obj["y"]) - y)
            if d <= nearest:
                best, nearest = other, d
        if best is None:
            best = name
            self.objects[name] = {"x": x, "y": y, "z": 0.0, "kind": "sample"}
        self.objects[best].update(found=kind, found_as=name)

    def _map(self, event: Mapping[str, Any]) -> None:
        try:
            cells = decode_cells(event)
            origin = [float(v) for v in event["origin"]]
            resolution = float(event["resolution"])
        except (TraceFormatError, KeyError, TypeError, ValueError):
            return
        self.map = {
            "t": self.t,
            "origin": origin,
            "resolution": resolution,
            "width": int(event["width"]),
            "height": int(event["height"]),
            "cells": cells.translate(_DIGITS).decode("ascii"),
            "free": cells.count(1),
            "occupied": cells.count(2),
        }

    def _operator(self, kind: str, event: Mapping[str, Any]) -> None:
        """The operator's side: proposals waiting for a decision, goals set, the plans shared."""
        if kind == "proposal" and isinstance(event.get("problem"), str):
            fields: tuple[str, ...] = ("generation", "leader", "cost", "goal", "steps", "tasks", "error", "t")
            self.proposals[event["problem"]] = {k: event[k] for k in fields if k in event}
        elif kind == "operator" and isinstance(event.get("problem"), str):
            problem = event["problem"]
            if event.get("what") == "goal" and isinstance(event.get("goal"), str):
                self.goals[problem] = event["goal"]
            waiting = self.proposals.get(problem)
            if event.get("what") in ("accept", "decline", "modify") and waiting is not None:
                if waiting.get("generation") == event.get("generation"):
                    del self.proposals[problem]
        elif kind == "planner":
            problem = str(event.get("key", "")).rsplit("/", 1)[-1]
            fields = ("generation", "version", "cost", "steps", "t")
            self.running[problem] = {**{k: event[k] for k in fields if k in event}, "leader": event.get("agent")}

    def snapshot(self, t: float | None = None, since: float | None = None) -> dict[str, Any]:
        """The state as JSON-ready data (the module docstring has its fields).

        Args:
            t: the time to report (a replay asks for a time between two events); the last event's by default.
            since: with a view that keeps tracks, add ``tracks``: each robot's poses after ``since``.
        """
        agents: dict[str, dict[str, Any]] = {}
        for name, who in self.agents.items():
            plans = sorted((dict(n) for n in self.nodes[name].values()), key=lambda n: n["key"].count("/"))
            for node in plans:
                if node["state"] is None:  # no transition yet: a node below names the state it runs in
                    below = next((n["key"] for n in plans if n["key"].startswith(node["key"] + "/")), None)
                    if below is not None:
                        node["state"] = below[len(node["key"]) + 1 :].split("/", 1)[0]
                    elif node["task"] is not None:  # the entry state of the agent's task, from the plan file
                        node["state"] = self.entries.get(str(node["plan"]), {}).get(str(node["task"]))
            deepest = plans[-1] if plans else _NO_NODE
            agents[name] = {
                **who,
                "pose": None if who["pose"] is None else dict(who["pose"]),
                **{k: deepest[k] for k in ("key", "plan", "task", "state")},
                "plans": plans,
            }
        out: dict[str, Any] = {
            "t": self.t if t is None else t,
            "world": self.world,
            "bounds": self.bounds,
            "agents": agents,
            "objects": {n: dict(o) for n, o in self.objects.items()},
            "map": None if self.map is None else dict(self.map),
            "operator": {"proposals": dict(self.proposals), "goals": dict(self.goals), "running": dict(self.running)},
        }
        if since is not None and self.keep_tracks:
            out["tracks"] = {a: [p for p in points if p[0] > since] for a, points in self.tracks.items()}
        return out


_DIGITS = bytes(ord("1") if i == 1 else ord("2") if i == 2 else ord("0") for i in range(256))
"""Cell byte -> digit: 1 free, 2 occupied, anything else unknown (0)."""
