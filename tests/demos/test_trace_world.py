"""The world in a trace (docs/trace.md): poses at a low rate, objects that moved, the team map; both demos' headers."""

from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

import numpy as np

from alica.app.demos.blocksworld import DemoConfig, run_demo
from alica.app.demos.lunar import LunarConfig, run_lunar
from alica.app.trace_world import KEYFRAME_EVERY, WorldTrace, coarsened
from alica.engine import TraceRecorder, read_trace
from alica.engine.trace import VERSION, decode_cells

TICK = 1 / 30


class _Robot:
    def __init__(self, x: float) -> None:
        self.pose = (x, 0.0, 0.0)
        self.spec = SimpleNamespace(kind="scout")


class _Thing:
    def __init__(self, kind: str, x: float, movable: bool) -> None:
        self.kind, self.movable, self.size, self.radius, self.sample_kind = kind, movable, 0.1, 0.05, None
        self.at = (x, 0.0, 0.0)

    def position(self) -> np.ndarray:
        return np.asarray(self.at)


def _slots(times: list[float], period: float) -> list[int]:
    return [math.floor(t / period + 1e-6) for t in times]


def test_a_moving_robot_is_posed_once_a_period_and_a_still_one_every_keyframe():
    world = SimpleNamespace(
        robots={"mover": _Robot(0.0), "sitter": _Robot(5.0)},
        objects={
            "rock": _Thing("rock", 3.0, False),
            "s": _Thing("sample", 4.0, True),
            "ground": _Thing("terrain", 0, False),
        },
    )
    recorder = TraceRecorder()
    sample = WorldTrace(recorder, world, pose_hz=2.0)
    now = 0.0
    sample(now)
    for _ in range(int(25 / TICK)):
        now += TICK
        world.robots["mover"].pose = (now * 0.5, 0.0, 0.0)  # half a metre a second
        if 10.0 <= now < 10.5:
            world.objects["s"].at = (4.0 + (now - 10.0), 0.0, 0.0)  # carried for half a second
        sample(now)
    moving = [e["t"] for e in recorder.of("pose", agent="mover")]
    slots = _slots(moving, 0.5)
    assert slots == list(range(len(slots))) and len(slots) >= 50  # one pose at the first tick of every half second
    assert all(t - slot * 0.5 <= TICK + 1e-6 for t, slot in zip(moving, slots, strict=True))
    still = [e["t"] for e in recorder.of("pose", agent="sitter")]
    assert len(still) == 3 and all(b - a >= KEYFRAME_EVERY - 1e-6 for a, b in itertools.pairwise(still))
    assert [e["name"] for e in recorder.of("object") if e["t"] == 0.0] == ["rock", "s"]  # all but the terrain
    later = [e for e in recorder.of("object") if e["t"] > 0]
    assert later and {e["name"] for e in later} == {"s"} and later[-1]["x"] == 4.5


def test_a_map_is_coarsened_keeping_obstacles():
    fine = np.full((8, 8), -1, dtype=np.int8)
    fine[0, 0] = 0
    fine[0, 1] = 1
    fine[5, 5] = 0
    coarse, resolution = coarsened(fine, 0.05, 0.2)
    assert resolution == 0.2 and coarse.shape == (2, 2)
    assert coarse.tolist() == [[1, -1], [-1, 0]]


def test_the_blocks_demo_traces_its_header_poses_and_blocks(tmp_path):
    config = DemoConfig(agents=2, start=[["a", "c"], ["b"], ["d"]], goal=[["d", "c", "b", "a"]], seed=3, time_limit=120)
    result = run_demo(config, out=tmp_path)
    trace = read_trace(tmp_path / "trace.jsonl")
    assert result.success and trace.version == VERSION and not trace.notes
    meta = trace.meta
    assert meta["world"] == "blocks" and meta["root"] == "BlocksWorldMission" and meta["seed"] == 3
    assert meta["plans"] == ["alica:plans/blocksworld/mission.yaml"] and len(meta["bounds"]) == 4
    assert meta["agents"] == {name: {"role": "Manipulator", "plan": "BlocksWorldMission"} for name in ("r1", "r2")}
    for robot in ("r1", "r2"):
        slots = _slots([e["t"] for e in trace.of("pose", agent=robot)], 0.5)
        assert slots and len(slots) == len(set(slots))  # at most one pose a half second
    first = [e for e in trace.of("object") if e["t"] == trace.of("object")[0]["t"]]
    assert {e["name"] for e in first if e["kind"] == "block"} == {"a", "b", "c", "d"}
    assert len(trace.of("object")) > len(first)  # the blocks the team moved


def test_the_lunar_demo_traces_poses_maps_and_found_samples(tmp_path):
    config = LunarConfig(size=16.0, rocks=6, samples=2, seed=1, time_limit=30.0)
    run_lunar(config, out=tmp_path)
    trace = read_trace(tmp_path / "trace.jsonl")
    meta = trace.meta
    assert meta["world"] == "lunar" and meta["bounds"] == [-8.0, -8.0, 8.0, 8.0] and meta["pose_hz"] == 2.0
    assert set(meta["agents"]) == {"scout", "stummel", "amparo"}
    poses = trace.of("pose", agent="amparo")
    slots = _slots([e["t"] for e in poses], 0.5)
    assert len(slots) == len(set(slots)) and len(slots) >= 20 and all(e["alive"] for e in poses)
    maps = trace.of("map")
    assert maps and all(b["t"] - a["t"] >= 5.0 - 1e-6 for a, b in itertools.pairwise(maps))
    last = maps[-1]
    cells = decode_cells(last)
    assert len(cells) == last["width"] * last["height"] and last["resolution"] >= 0.2 - 1e-9
    assert set(cells) >= {0, 1, 2}  # unknown, free and occupied cells
    assert {e["kind"] for e in trace.of("object")} >= {"sample", "rock", "collection_point"}
    assert trace.of("found")
