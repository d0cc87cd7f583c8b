"""``--ros2``: the team in a ROS 2 graph as a fake ROS 2 node (written from rmw_zenoh's design) sees it.

The fake node listens where ``rmw_zenohd`` would, and the run joins it as a client, as it joins the
router on a ROS 2 host. No ROS 2 installation was available to these tests.
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from rosbags.typesys import Stores, get_typestore

from alica.app.cli import main
from alica.comm.zenoh_transport import free_endpoints
from tests.comm.ros2.fake_ros2 import FakeRos2, fake_attachment

TS = get_typestore(Stores.ROS2_JAZZY)
STRING = "std_msgs/msg/String"
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def ros() -> Iterator[tuple[FakeRos2, str]]:
    (endpoint,) = free_endpoints(1)
    fake = FakeRos2(None, listen=endpoint)
    yield fake, endpoint
    fake.close()


def _string(text: str) -> bytes:
    return bytes(TS.serialize_cdr(TS.types[STRING](data=text), STRING))


def test_the_lunar_demo_is_in_the_graph_and_takes_a_goal_from_a_topic(ros: tuple[FakeRos2, str], capsys: Any) -> None:
    fake, endpoint = ros
    for key in ("0/scout/pose/*/*", "0/tf/*/*", "0/clock/*/*", "0/alica/goal_result/*/*", "0/amparo/team_map/*/*"):
        fake.subscribe(key)
    argv = ["demo", "lunar", "--seed", "1", "--size", "16", "--rocks", "6", "--samples", "2", "--time-limit", "30"]
    codes: list[int] = []
    run = threading.Thread(
        target=lambda: codes.append(main([*argv, "--ros2", "--ros2-router", endpoint, "--no-progress", "--json"])),
        daemon=True,
    )
    run.start()
    try:
        assert fake.wait(lambda: any(e.topic == "/alica/goal" and e.kind == "MS" for e in fake.endpoints()), 60)
        nodes = {(namespace, name) for _, namespace, name in fake.nodes()}
        assert {("/scout", "alica_scout"), ("/stummel", "alica_stummel"), ("/amparo", "alica_amparo")} <= nodes
        pose = next(e for e in fake.endpoints() if e.topic == "/scout/pose")
        assert (pose.kind, pose.type_name) == ("MP", "geometry_msgs::msg::dds_::PoseStamped_")
        assert pose.type_hash.startswith("RIHS01_")
        goal_key = next(e for e in fake.endpoints() if e.topic == "/alica/goal")
        key = f"0/alica/goal/{goal_key.type_name}/{goal_key.type_hash}"
        fake.put(key, _string("GetObjects=fly(scout)"), fake_attachment(0, 0, bytes(16)))
        fake.put(key, _string("GetObjects=at(nothing_here, g)"), fake_attachment(1, 0, bytes(16)))

        def answers() -> list[str]:
            return [TS.deserialize_cdr(r.payload, STRING).data for r in fake.received if "/goal_result/" in r.key]

        assert fake.wait(lambda: len(answers()) == 2, 60)
        refused, applied = answers()
        assert refused.startswith("refused: GetObjects: column 1: 'fly' is no predicate")
        assert applied == "applied: GetObjects=at(nothing_here, g)"
    finally:
        run.join(300)
    assert not run.is_alive() and codes
    poses = [r for r in fake.received if r.key.startswith("0/scout/pose/")]
    assert len(poses) >= 20
    decoded = TS.deserialize_cdr(poses[-1].payload, "geometry_msgs/msg/PoseStamped")
    assert decoded.header.frame_id == "map" and poses[-1].timestamp_ns > 0
    assert [p.sequence for p in poses] == sorted(p.sequence for p in poses)
    clock = [TS.deserialize_cdr(r.payload, "rosgraph_msgs/msg/Clock") for r in fake.received if "/clock/" in r.key]
    assert clock and clock[-1].clock.sec >= 20
    capsys.readouterr()


def test_an_agent_process_shows_its_plans_in_the_graph(ros: tuple[FakeRos2, str], tmp_path: Path) -> None:
    fake, endpoint = ros
    fake.subscribe("0/scout/diagnostics/*/*")
    (listen,) = free_endpoints(1)
    plan = ROOT / "plans" / "examples" / "gate.yaml"
    argv = [sys.executable, "-m", "alica.app.cli", "agent", str(plan), "--name", "scout", "--agents", "scout:Worker"]
    argv += ["--listen", listen, "--stand-ins", "--time-limit", "4", "--json"]
    argv += ["--ros2", "--ros2-router", endpoint, "--ros2-distro", "humble", "--record", str(tmp_path / "bag")]
    agent = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert fake.wait(lambda: ("", "/scout", "alica_scout") in fake.nodes(), 60)
        assert fake.wait(lambda: len(fake.received) >= 2, 30)
    finally:
        out, err = agent.communicate(timeout=60)
    assert agent.returncode in (0, 1), err
    assert json.loads(out.splitlines()[-1])["name"] == "scout"
    humble = get_typestore(Stores.ROS2_HUMBLE)
    arrays = [humble.deserialize_cdr(r.payload, "diagnostic_msgs/msg/DiagnosticArray") for r in fake.received]
    status = arrays[-1].status
    assert status[0].message.startswith("Top: ")
    assert status[0].name == "alica/scout/" + status[0].name.split("/", 2)[2] and status[0].hardware_id == "scout"
    assert fake.received[0].key.endswith("/TypeHashNotSupported")
    assert fake.received[0].timestamp_ns > 1.7e18  # the wall clock's epoch nanoseconds
    assert (tmp_path / "bag" / "metadata.yaml").is_file()


def test_a_world_server_publishes_the_clock_and_true_poses(ros: tuple[FakeRos2, str]) -> None:
    fake, endpoint = ros
    fake.subscribe("0/clock/*/*")
    fake.subscribe("0/scout/ground_truth/*/*")
    (listen,) = free_endpoints(1)
    argv = [sys.executable, "-m", "alica.app.cli", "world", "serve", "--world", "lunar", "--agents", "scout"]
    argv += ["--listen", listen, "--duration", "4", "--size", "16", "--ros2", "--ros2-router", endpoint]
    server = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert fake.wait(lambda: ("", "", "alica_world") in fake.nodes(), 60)  # the root namespace is written "%"
        assert fake.wait(lambda: {r.key.split("/")[1] for r in fake.received} == {"clock", "scout"}, 30)
    finally:
        _out, err = server.communicate(timeout=60)
    assert server.returncode == 0, err
    truth = next(r for r in fake.received if "/ground_truth/" in r.key)
    assert TS.deserialize_cdr(truth.payload, "geometry_msgs/msg/PoseStamped").header.frame_id == "map"
