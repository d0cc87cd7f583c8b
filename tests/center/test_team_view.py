"""The team view's fold, one event at a time, and the replay's checkpoints: the same state as a fold from the start."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.center.replay import Replay
from alica.app.center.team_view import TeamView
from alica.app.center.trace_file import Trace, load_trace
from alica.engine.trace import MAP_ENCODING, encode_cells

HEADER: dict[str, Any] = {
    "version": 2,
    "world": "lunar",
    "bounds": [-5.0, -5.0, 5.0, 5.0],
    "agents": {"a": {"role": "Scout", "plan": "Top"}, "b": {"role": "Carrier", "plan": "Top"}},
}


def _map(t: float, cells: bytes, width: int, height: int) -> dict[str, Any]:
    return {
        "t": t,
        "agent": "-",
        "event": "map",
        "origin": [-1.0, -2.0],
        "resolution": 0.5,
        "width": width,
        "height": height,
        "encoding": MAP_ENCODING,
        "cells": encode_cells(cells, width, height),
    }


def test_allocations_and_transitions_enter_and_leave_plan_nodes() -> None:
    view = TeamView(HEADER)
    assert list(view.snapshot()["agents"]) == ["a", "b"]
    view.apply({"t": 0.0, "agent": "a", "event": "allocation", "key": "Top", "plan": "Top", "entries": {"a": "Go"}})
    view.apply({"t": 0.1, "agent": "a", "event": "allocation", "key": "Top/S1/P", "plan": "P", "entries": {"a": "T"}})
    a = view.snapshot()["agents"]["a"]
    assert (a["key"], a["plan"], a["task"], a["state"]) == ("Top/S1/P", "P", "T", None)
    assert [p["key"] for p in a["plans"]] == ["Top", "Top/S1/P"]
    assert a["plans"][0]["state"] == "S1"  # no transition yet: the node below names the state
    view.apply({"t": 1.0, "agent": "a", "event": "transition", "key": "Top", "plan": "Top", "target": "S2"})
    a = view.snapshot()["agents"]["a"]
    assert (a["key"], a["plan"], a["task"], a["state"]) == ("Top", "Top", "Go", "S2")
    assert [p["key"] for p in a["plans"]] == ["Top"]
    view.apply({"t": 1.5, "agent": "a", "event": "behaviour", "behaviour": "Drive", "status": "running"})
    assert view.snapshot()["agents"]["a"]["behaviour"] == "Drive (running)"
    assert view.snapshot()["t"] == 1.5


def test_a_crash_and_a_recovery() -> None:
    view = TeamView(HEADER)
    view.apply({"t": 0.0, "agent": "b", "event": "allocation", "key": "Top", "plan": "Top", "entries": {"b": "Go"}})
    view.apply({"t": 0.5, "agent": "b", "event": "behaviour", "behaviour": "Drive", "status": "running"})
    view.apply({"t": 1.0, "agent": "b", "event": "fault", "fault": "crash"})
    b = view.snapshot()["agents"]["b"]
    assert b["alive"] is False and b["plan"] == "Top"
    view.apply({"t": 2.0, "agent": "b", "event": "fault", "fault": "recover"})
    b = view.snapshot()["agents"]["b"]
    assert b["alive"] is True
    assert (b["plan"], b["plans"], b["behaviour"]) == (None, [], None)
    view.apply({"t": 2.5, "agent": "-", "event": "fault", "fault": "partition"})  # the team's: no agent of its own
    assert "-" not in view.snapshot()["agents"]


def test_poses_tracks_and_an_agent_first_seen_in_an_event() -> None:
    view = TeamView(HEADER, tracks=True)
    view.apply({"t": 0.5, "agent": "a", "event": "pose", "x": 1.0, "y": 2.0, "yaw": 0.5})
    view.apply({"t": 1.0, "agent": "robot", "event": "pose", "x": 3.0, "y": 4.0, "yaw": 0.0})
    view.apply({"t": 1.5, "agent": "a", "event": "pose", "x": 1.5, "y": 2.5, "yaw": 0.5})
    snap = view.snapshot(since=0.5)
    assert snap["agents"]["a"]["pose"] == {"x": 1.5, "y": 2.5, "yaw": 0.5}
    assert snap["agents"]["robot"]["role"] is None
    assert snap["tracks"] == {"a": [[1.5, 1.5, 2.5]], "robot": [[1.0, 3.0, 4.0]]}
    assert len(view.snapshot(since=float("-inf"))["tracks"]["a"]) == 2
    assert "tracks" not in view.snapshot()
    assert "tracks" not in TeamView(HEADER).snapshot(since=0.0)  # a view without tracks has none to give


def test_objects_move_and_found_samples_are_marked() -> None:
    view = TeamView(HEADER)
    view.apply(
        {"t": 0.1, "agent": "-", "event": "object", "name": "s1", "kind": "sample", "sample_kind": "red-black-red"}
        | {"x": 4.0, "y": 1.0, "z": 0.05, "size": 0.1, "radius": 0.03}
    )
    view.apply({"t": 0.1, "agent": "-", "event": "object", "name": "r", "kind": "rock", "x": 4.2, "y": 1.0, "z": 0.0})
    view.apply(
        {"t": 2.0, "agent": "-", "event": "object", "name": "s1", "kind": "sample", "x": 3.0, "y": 1.0, "z": 0.3}
    )
    objects = view.snapshot()["objects"]
    assert objects["s1"] == {
        "x": 3.0,
        "y": 1.0,
        "z": 0.3,
        "kind": "sample",
        "sample_kind": "red-black-red",
        "size": 0.1,
        "radius": 0.03,
    }
    view.apply(
        {"t": 3.0, "agent": "-", "event": "found", "name": "red_black_red", "kind": "red-black-red", "x": 3.2, "y": 1.1}
    )
    view.apply({"t": 3.5, "agent": "-", "event": "found", "name": "far_one", "kind": "", "x": -4.0, "y": -4.0})
    objects = view.snapshot()["objects"]
    assert (objects["s1"]["found"], objects["s1"]["found_as"]) == ("red-black-red", "red_black_red")
    assert "found" not in objects["r"]  # a rock is no sample, however near
    assert objects["far_one"] == {"x": -4.0, "y": -4.0, "z": 0.0, "kind": "sample", "found": "", "found_as": "far_one"}
    view.apply(
        {"t": 4.0, "agent": "-", "event": "found", "name": "far_one", "kind": "green-red-green", "x": -4.0, "y": -4.0}
    )
    assert view.snapshot()["objects"]["far_one"]["found"] == "green-red-green"  # its kind, once known


def test_the_latest_map_decoded_as_digits() -> None:
    view = TeamView(HEADER)
    assert view.snapshot()["map"] is None
    view.apply(_map(5.0, bytes([0, 1, 2, 1, 1, 0]), 3, 2))
    grid = view.snapshot()["map"]
    assert grid == {
        "t": 5.0,
        "origin": [-1.0, -2.0],
        "resolution": 0.5,
        "width": 3,
        "height": 2,
        "cells": "012110",
        "free": 3,
        "occupied": 1,
    }
    view.apply(_map(10.0, bytes([2, 2, 2, 2]), 2, 2))
    assert view.snapshot()["map"]["cells"] == "2222"
    broken = _map(15.0, bytes([1]), 1, 1) | {"cells": "not base64!"}
    view.apply(broken)
    assert view.snapshot()["map"]["t"] == 10.0  # a map that does not decode is left out


def test_the_world_kind_and_a_header_without_agents() -> None:
    assert TeamView({"world": "blocks"}).snapshot()["world"] == "blocks"
    bare = TeamView({}).snapshot()
    assert (bare["world"], bare["bounds"], bare["agents"], bare["objects"]) == ("none", None, {}, {})
    assert TeamView({"world": "mars"}).snapshot()["world"] == "none"


def test_the_snapshot_is_json_and_a_copy_not_a_view() -> None:
    view = TeamView(HEADER)
    view.apply({"t": 0.5, "agent": "a", "event": "pose", "x": 1.0, "y": 2.0, "yaw": 0.5})
    snap = view.snapshot()
    json.dumps(snap)
    snap["agents"]["a"]["pose"]["x"] = 99.0
    assert view.snapshot()["agents"]["a"]["pose"]["x"] == 1.0
    copy = view.copy()
    copy.apply({"t": 1.0, "agent": "a", "event": "pose", "x": 5.0, "y": 5.0, "yaw": 0.0})
    assert view.snapshot()["agents"]["a"]["pose"]["x"] == 1.0


# -- the replay's checkpoints ------------------------------------------------------------

AGENTS = ["a", "b", "c"]
KEYS = ["Top", "Top/S1/P", "Top/S2/Q", "Top/S1/P/X/R"]

_allocation = st.builds(
    lambda agent, key, plan, task, reason: {
        "agent": agent,
        "event": "allocation",
        "key": key,
        "plan": plan,
        "entries": {agent: task},
        "reason": reason,
    },
    st.sampled_from(AGENTS),
    st.sampled_from(KEYS),
    st.sampled_from(["Top", "P", "Q", "R", "Gen_1"]),
    st.sampled_from(["Go", "T", "Wait"]),
    st.sampled_from(["initial", "reuse"]),
)
_transition = st.builds(
    lambda agent, key, target: {"agent": agent, "event": "transition", "key": key, "plan": "P", "target": target},
    st.sampled_from(AGENTS),
    st.sampled_from(KEYS),
    st.sampled_from(["S1", "S2", "X", "Done"]),
)
_fault = st.builds(
    lambda agent, fault: {"agent": agent, "event": "fault", "fault": fault},
    st.sampled_from([*AGENTS, "-"]),
    st.sampled_from(["crash", "recover", "partition"]),
)
_pose = st.builds(
    lambda agent, x, y: {"agent": agent, "event": "pose", "x": x, "y": y, "yaw": 0.0},
    st.sampled_from(AGENTS),
    st.floats(-5, 5, allow_nan=False),
    st.floats(-5, 5, allow_nan=False),
)
_object = st.builds(
    lambda name, kind, x: {"agent": "-", "event": "object", "name": name, "kind": kind, "x": x, "y": 0.0, "z": 0.0},
    st.sampled_from(["s1", "s2", "rock"]),
    st.sampled_from(["sample", "rock"]),
    st.floats(-5, 5, allow_nan=False),
)
_found = st.builds(
    lambda name, x: {"agent": "-", "event": "found", "name": name, "kind": "red", "x": x, "y": 0.0},
    st.sampled_from(["red_1", "red_2"]),
    st.floats(-5, 5, allow_nan=False),
)
_grid = st.builds(
    lambda cells: _map(0.0, bytes(cells), 2, 2),
    st.lists(st.integers(0, 2), min_size=4, max_size=4),
)
_behaviour = st.builds(
    lambda agent, status: {"agent": agent, "event": "behaviour", "behaviour": "B", "status": status},
    st.sampled_from(AGENTS),
    st.sampled_from(["running", "success"]),
)
_event = st.one_of(_allocation, _transition, _fault, _pose, _object, _found, _grid, _behaviour)


@st.composite
def _traces(draw: st.DrawFn) -> list[dict[str, Any]]:
    kinds = draw(st.lists(_event, max_size=60))
    gaps = draw(st.lists(st.sampled_from([0.0, 0.1, 0.5, 2.0]), min_size=len(kinds), max_size=len(kinds)))
    t, events = 0.0, []
    for event, gap in zip(kinds, gaps, strict=True):
        t = round(t + gap, 3)
        events.append({**event, "t": t})
    return events


@settings(max_examples=150, deadline=None)
@given(events=_traces(), every=st.integers(1, 7), times=st.lists(st.floats(-1.0, 80.0, allow_nan=False), max_size=8))
def test_a_checkpointed_state_equals_the_fold_from_the_start(
    events: list[dict[str, Any]], every: int, times: list[float]
) -> None:
    replay = Replay(Trace("drawn.jsonl", events, dict(HEADER)), checkpoint_every=every)
    for t in [*times, *(e["t"] for e in events)]:
        assert replay.state(t) == replay.full_state(t)


def test_checkpoints_of_a_lunar_run_agree_with_the_full_fold(lunar_trace: Path) -> None:
    replay = Replay(load_trace(lunar_trace), checkpoint_every=16)
    assert len(replay.events) > 16 * 3  # several checkpoints
    end = replay.state(replay.meta()["end"])
    assert end["map"] is not None and end["map"]["occupied"] > 0
    assert any("found" in o for o in end["objects"].values())
    for t in sorted({e["t"] for e in replay.events}):
        assert replay.state(t) == replay.full_state(t)


def test_a_checkpoint_period_below_one_is_refused() -> None:
    with pytest.raises(ValueError, match="at least 1"):
        Replay(Trace("x.jsonl", [], {}), checkpoint_every=0)
