"""Trace format version 2: the header, the reader's errors, version-1 traces, round trips (docs/trace.md)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.engine import JsonlTrace, read_trace, trace_header
from alica.engine.trace import VERSION, decode_cells, encode_cells
from alica.errors import TraceFormatError
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")
EVENTS = [
    {"t": 0.5, "agent": "scout", "event": "allocation", "key": "LunarMission", "utility": 0.5},
    {"t": 1.0, "agent": "scout", "event": "transition", "plan": "LunarMission", "to": "Explore"},
    {"t": 2.0, "agent": "-", "event": "fault", "fault": "crash", "who": "scout"},
]


def header() -> dict:
    return trace_header(plans=["mission.yaml"], root="LunarMission", agents={"scout": "Scout"}, seed=7)


def write(path: Path, *lines: str) -> Path:
    path.write_text("".join(f"{line}\n" for line in lines), encoding="utf-8")
    return path


def test_a_trace_written_with_its_header_reads_back_the_same(tmp_path):
    path = tmp_path / "run.jsonl"
    with JsonlTrace(path, header=header()) as trace:
        for event in EVENTS:
            trace(event)
    first = json.loads(path.read_text(encoding="utf-8").splitlines()[0])
    assert first["event"] == "trace" and first["format"] == "alica-trace" and first["version"] == VERSION
    read = read_trace(path)
    assert read.version == VERSION and not read.notes
    assert read.meta["agents"] == {"scout": {"role": "Scout", "plan": "LunarMission"}}
    assert read.meta["seed"] == 7 and read.meta["world"] == "none" and read.meta["bounds"] is None
    assert read.events == EVENTS
    assert read.agents == ["scout"] and read.duration == 2.0
    assert read.of("fault", who="scout") == [EVENTS[2]]


def test_a_header_refuses_an_unknown_world():
    with pytest.raises(ValueError, match="world must be one of"):
        trace_header(plans=[], root="P", agents={}, seed=0, world="mars")


def test_a_version_1_trace_is_read_with_a_note_that_poses_and_maps_are_missing(tmp_path):
    path = write(tmp_path / "old.jsonl", *(json.dumps(e, sort_keys=True) for e in EVENTS))
    read = read_trace(path)
    assert read.version == 1 and read.events == EVENTS
    assert read.agents == ["scout"] and read.meta["agents"]["scout"]["role"] is None
    (note,) = read.notes
    assert note.startswith(f"{path}: note: a version-1 trace") and "no robot poses, objects or maps" in note


@pytest.mark.parametrize(
    ("lines", "message"),
    [
        (["{}", "not json"], r":1: error: an event without t, agent, event"),
        ([json.dumps(EVENTS[0]), "{oops"], r":2: error: not JSON \(Expecting property name"),
        ([json.dumps(EVENTS[0]), "", "[1, 2]"], r":3: error: a JSON list, not an object"),
        ([json.dumps({**EVENTS[0], "t": "soon"})], r":1: error: t is 'soon', not a number"),
        ([json.dumps({**EVENTS[0], "t": 10**400})], r":1: error: t is 1000.*, not a number"),
        ([json.dumps(EVENTS[0]).replace("0.5", "NaN")], r":1: error: t is nan, not a number"),
        ([json.dumps({**header(), "format": "rosbag"})], r":1: error: unknown trace format 'rosbag'"),
        (
            [json.dumps({**header(), "version": VERSION + 1})],
            rf":1: error: trace format version {VERSION + 1} was written by a newer alica.*\(fix: upgrade alica\)",
        ),
        ([json.dumps({**header(), "version": "2"})], r":1: error: trace version '2' is not a whole number"),
        ([json.dumps(header()), json.dumps(EVENTS[0]), json.dumps(header())], r":3: error: a second trace header"),
        ([""], r":1: error: the trace holds no events"),
    ],
)
def test_bad_traces_get_file_line_and_a_fix(tmp_path, lines, message):
    path = write(tmp_path / "trace.jsonl", *lines)
    with pytest.raises(TraceFormatError, match=message) as caught:
        read_trace(path)
    assert str(caught.value).startswith(str(path)) and "(fix: " in str(caught.value)


def test_a_missing_file_is_an_error_not_a_traceback(tmp_path):
    with pytest.raises(TraceFormatError, match=r"missing.jsonl: error: no such file"):
        read_trace(tmp_path / "missing.jsonl")


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    st.lists(
        st.one_of(
            st.text(max_size=40),
            st.builds(
                json.dumps,
                st.recursive(
                    st.none() | st.booleans() | st.floats() | st.integers(-(10**500), 10**500) | st.text(max_size=5),
                    lambda c: (
                        st.lists(c, max_size=3)
                        | st.dictionaries(st.sampled_from(["t", "agent", "event", "format", "version"]), c, max_size=5)
                    ),
                    max_leaves=8,
                ),
            ),
        ),
        max_size=5,
    )
)
def test_garbage_lines_give_a_trace_or_a_trace_format_error(tmp_path, lines):
    path = tmp_path / "garbage.jsonl"
    path.write_bytes("\n".join(lines).encode("utf-8", errors="replace"))
    try:
        read = read_trace(path)
    except TraceFormatError as exc:
        assert ": error: " in str(exc)
    else:
        assert read.version in (1, VERSION) and all("event" in e for e in read.events)


def test_map_cells_round_trip():
    cells = bytes([0, 1, 2, 2, 1, 0])
    event = {"t": 5.0, "encoding": "zlib-u8", "width": 3, "height": 2, "cells": encode_cells(cells, 3, 2)}
    assert decode_cells(event) == cells
    with pytest.raises(TraceFormatError, match="6 cells, expected 4"):
        decode_cells({**event, "height": 1, "width": 4})


def test_alica_run_writes_the_header_first(tmp_path, capsys):
    path = tmp_path / "run.jsonl"
    args = ["run", LUNAR, "--stand-ins", "--agents", "scout,stummel", "--ticks", "20", "--seed", "4"]
    main([*args, "--trace", str(path)])
    capsys.readouterr()
    read = read_trace(path)
    assert read.version == VERSION and read.meta["root"] == "LunarMission" and read.meta["seed"] == 4
    assert read.meta["plans"] == [LUNAR] and read.meta["world"] == "none"
    assert read.meta["agents"] == {
        "scout": {"role": "Scout", "plan": "LunarMission"},
        "stummel": {"role": "Stummel", "plan": "LunarMission"},
    }
    assert not read.of("pose") and read.of("allocation")


def test_alica_run_in_the_blocks_world_traces_poses_at_the_rate_asked(tmp_path, capsys):
    path = tmp_path / "run.jsonl"
    plan = str(PLANS / "blocksworld" / "mission.yaml")
    args = ["run", plan, "--agents", "r1:Manipulator", "--world", "blocks", "--stacks", "a,b", "--ticks", "60"]
    main([*args, "--trace", str(path), "--pose-rate", "4"])
    capsys.readouterr()
    read = read_trace(path)
    assert read.meta["world"] == "blocks" and len(read.meta["bounds"]) == 4 and read.meta["pose_hz"] == 4.0
    times = [e["t"] for e in read.of("pose", agent="r1")]
    slots = [math.floor(t / 0.25 + 1e-6) for t in times]  # a pose in a quarter second at most, when it moved
    assert times and len(slots) == len(set(slots))
    assert {e["name"] for e in read.of("object")} >= {"a", "b"}


def test_alica_run_refuses_a_pose_rate_of_zero(tmp_path, capsys):
    args = ["run", LUNAR, "--stand-ins", "--agents", "scout", "--ticks", "1", "--pose-rate", "0"]
    assert main([*args, "--trace", str(tmp_path / "t.jsonl")]) == 1
    assert "--pose-rate must be a positive number" in capsys.readouterr().err
