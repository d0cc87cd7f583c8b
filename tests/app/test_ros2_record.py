"""``--record DIR``: a run as a rosbag2 folder that rosbags opens; poses, /tf, the map, markers and diagnostics decode."""

from __future__ import annotations

import json
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from alica.app.cli import main

STORES = {"humble": get_typestore(Stores.ROS2_HUMBLE), "jazzy": get_typestore(Stores.ROS2_JAZZY)}
SMALL_LUNAR = ["--size", "16", "--rocks", "6", "--samples", "2", "--time-limit", "40", "--no-progress", "--json"]


def _read(folder: Path, distro: str) -> dict[str, list[tuple[int, Any]]]:
    out: dict[str, list[tuple[int, Any]]] = {}
    with AnyReader([folder], default_typestore=STORES[distro]) as reader:
        for connection, stamp, raw in reader.messages():
            out.setdefault(connection.topic, []).append((stamp, reader.deserialize(raw, connection.msgtype)))
    return out


def test_the_lunar_demo_records_a_bag_whose_poses_map_and_markers_decode(tmp_path: Path, capsys: Any) -> None:
    folder = tmp_path / "lunar_bag"
    main(["demo", "lunar", "--seed", "1", "--record", str(folder), *SMALL_LUNAR])
    summary = json.loads(capsys.readouterr().out)
    assert (folder / "metadata.yaml").is_file() and (folder / "lunar_bag_0.mcap").is_file()
    with Reader(folder) as bag:
        types = {c.topic: c.msgtype for c in bag.connections}
        assert bag.message_count == sum(1 for _ in bag.messages())
    robots = ("scout", "stummel", "amparo")
    assert types["/tf"] == "tf2_msgs/msg/TFMessage"
    for robot in robots:
        assert types[f"/{robot}/pose"] == "geometry_msgs/msg/PoseStamped"
        assert types[f"/{robot}/team_map"] == "nav_msgs/msg/OccupancyGrid"
        assert types[f"/{robot}/markers"] == "visualization_msgs/msg/MarkerArray"
        assert types[f"/{robot}/diagnostics"] == "diagnostic_msgs/msg/DiagnosticArray"
    messages = _read(folder, "jazzy")
    poses = messages["/scout/pose"]
    stamps = [stamp for stamp, _ in poses]
    assert stamps == sorted(stamps) and len(poses) >= 10 * 30  # 10 Hz over the run
    assert all(m.header.frame_id == "map" for _, m in poses)
    assert {t.child_frame_id for _, m in messages["/tf"] for t in m.transforms} == {f"{r}/base_link" for r in robots}
    grids = messages["/scout/team_map"]
    _, grid = grids[-1]
    cells = np.asarray(grid.data)
    assert cells.size == grid.info.width * grid.info.height > 0
    assert (cells == -1).any() and (cells > 50).any() and ((cells >= 0) & (cells < 50)).any()
    found = {m.text.split(" ")[0] for _, array in messages["/scout/markers"] for m in array.markers if m.type == 9}
    assert len(found) >= summary["found"] if isinstance(summary["found"], int) else set(summary["found"]) <= found
    plans = [s.message for _, array in messages["/scout/diagnostics"] for s in array.status]
    assert any(p.startswith("LunarMission") or ":" in p for p in plans)


def test_the_same_seed_records_the_same_bag_and_humble_bags_carry_no_type_hash(tmp_path: Path) -> None:
    # One process per run: OMPL seeds its generator once per process (docs/skills.md), so a second run of a
    # seed in the same process plans other paths.
    argv = [sys.executable, "-m", "alica.app.cli", "demo", "blocksworld", "--robots", "2", "--blocks", "3"]
    argv += ["--seed", "2", "--no-progress", "--json", "--ros2-distro", "humble"]
    runs = []
    for run in ("a", "b"):
        folder = tmp_path / run
        done = subprocess.run([*argv, "--record", str(folder)], capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        runs.append(_read(folder, "humble"))
    first, second = runs
    assert Counter({k: len(v) for k, v in first.items()}) == Counter({k: len(v) for k, v in second.items()})
    assert [s for s, _ in first["/r1/pose"]] == [s for s, _ in second["/r1/pose"]]
    assert [m.pose.position.x for _, m in first["/r1/pose"]] == [m.pose.position.x for _, m in second["/r1/pose"]]
    metadata = (tmp_path / "a" / "metadata.yaml").read_text()
    assert "version: 5" in metadata and "type_description_hash" not in metadata


def test_a_bag_folder_that_is_not_empty_is_refused_before_the_run(tmp_path: Path, capsys: Any) -> None:
    folder = tmp_path / "bag"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    assert main(["demo", "lunar", "--record", str(folder), *SMALL_LUNAR]) == 1
    err = capsys.readouterr().err
    assert "exists and is not empty" in err and (folder / "keep.txt").read_text() == "mine"


@pytest.mark.parametrize("domain", ["-1", "233"])
def test_a_domain_out_of_range_is_a_clear_error(domain: str, tmp_path: Path, capsys: Any) -> None:
    assert main(["demo", "lunar", "--record", str(tmp_path / "b"), "--ros2-domain", domain, *SMALL_LUNAR]) == 1
    assert "--ros2-domain must be a ROS 2 domain id from 0 to 232" in capsys.readouterr().err


def test_alica_run_records_a_team_in_a_world(tmp_path: Path) -> None:
    folder = tmp_path / "run_bag"
    plan = Path(__file__).resolve().parents[2] / "plans" / "examples" / "formation.yaml"
    code = main(
        [
            "run",
            str(plan),
            "--agents",
            "scout:Robot,stummel:Robot",
            "--world",
            "lunar",
            "--ticks",
            "90",
            "--record",
            str(folder),
        ]
    )
    assert code in (0, 1)
    messages = _read(folder, "jazzy")
    assert {"/scout/pose", "/stummel/pose", "/tf", "/scout/diagnostics"} <= set(messages)
    assert len(messages["/scout/pose"]) >= 25  # 3 s at 10 Hz


def test_a_team_of_processes_gives_each_agent_its_own_bag_folder(tmp_path: Path) -> None:
    from argparse import Namespace

    from alica.app.ros2_options import ros2_arguments

    args = Namespace(ros2=True, ros2_router="tcp/127.0.0.1:7447", ros2_domain=3, ros2_distro="humble")
    args.record = str(tmp_path / "bags")
    passed = ros2_arguments(args)
    assert passed is not None
    assert passed.for_agent("scout", 1) == [
        *("--ros2", "--ros2-router", "tcp/127.0.0.1:7447", "--ros2-domain", "3", "--ros2-distro", "humble"),
        *("--record", str(tmp_path / "bags" / "scout")),
    ]
    assert passed.for_agent("scout", 2)[-1] == str(tmp_path / "bags" / "scout.2")  # a restart records anew
    assert ros2_arguments(Namespace(ros2=False, record=None, ros2_domain=0)) is None


def test_alica_run_with_processes_records_one_bag_per_agent(tmp_path: Path) -> None:
    folder = tmp_path / "bags"
    plan = Path(__file__).resolve().parents[2] / "plans" / "examples" / "gate.yaml"
    argv = [sys.executable, "-m", "alica.app.cli", "run", str(plan), "--agents", "scout:Worker,stummel:Worker"]
    argv += ["--processes", "--time-limit", "4", "--record", str(folder), "--ros2-distro", "humble"]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert done.returncode in (0, 1) and "error" not in done.stderr, done.stderr  # 1: the plan is still running
    assert sorted(p.name for p in folder.iterdir()) == ["scout", "stummel"]
    for robot in ("scout", "stummel"):
        messages = _read(folder / robot, "humble")
        statuses = [s for _, array in messages[f"/{robot}/diagnostics"] for s in array.status]
        assert any(s.message == "Top: Work" and s.hardware_id == robot for s in statuses), statuses
