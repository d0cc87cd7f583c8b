"""BagWriter: a rosbag2 folder that an independent reader (rosbags) opens."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from alica.comm.ros2.bag import BagWriter
from alica.errors import AlicaError

TS = get_typestore(Stores.ROS2_HUMBLE)
POSE = "geometry_msgs/msg/PoseStamped"
GRID = "nav_msgs/msg/OccupancyGrid"
MARKERS = "visualization_msgs/msg/MarkerArray"
TF = "tf2_msgs/msg/TFMessage"


def _header(t: int, frame: str) -> Any:
    stamp = TS.types["builtin_interfaces/msg/Time"](sec=t // 10**9, nanosec=t % 10**9)
    return TS.types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def _pose(t: int, x: float) -> Any:
    types = TS.types
    pose = types["geometry_msgs/msg/Pose"](
        position=types["geometry_msgs/msg/Point"](x=x, y=2.0, z=0.0),
        orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
    )
    return types[POSE](header=_header(t, "map"), pose=pose)


def _grid(t: int) -> Any:
    import numpy as np

    types = TS.types
    info = types["nav_msgs/msg/MapMetaData"](
        map_load_time=_header(t, "").stamp,
        resolution=0.5,
        width=2,
        height=2,
        origin=_pose(t, 0.0).pose,
    )
    return types[GRID](header=_header(t, "map"), info=info, data=np.array([0, 100, -1, 0], dtype=np.int8))


def _markers(t: int) -> Any:
    return TS.types[MARKERS](markers=[])


def _tf(t: int) -> Any:
    types = TS.types
    tr = types["geometry_msgs/msg/Transform"](
        translation=types["geometry_msgs/msg/Vector3"](x=1.0, y=0.0, z=0.0),
        rotation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
    )
    stamped = types["geometry_msgs/msg/TransformStamped"](
        header=_header(t, "map"), child_frame_id="scout", transform=tr
    )
    return types[TF](transforms=[stamped])


def _write(folder: Path, distro: str) -> dict[str, list[tuple[int, bytes]]]:
    """Write a bag and return, per topic, the (timestamp, payload) written."""
    plan: list[tuple[str, str, Any, int]] = [
        ("/map", GRID, _grid, 1_000),
        ("/scout/pose", POSE, lambda t: _pose(t, t / 1e9), 2_000),
        ("/scout/pose", POSE, lambda t: _pose(t, t / 1e9), 1_500),  # out of order
        ("/markers", MARKERS, _markers, 3_000),
        ("/tf", TF, _tf, 2_500),
        ("/scout/pose", POSE, lambda t: _pose(t, t / 1e9), 4_000),
    ]
    written: dict[str, list[tuple[int, bytes]]] = {}
    with BagWriter(folder, distro=distro) as bag:
        for name, typename in (("/map", GRID), ("/scout/pose", POSE), ("/markers", MARKERS), ("/tf", TF)):
            schema, _ = TS.generate_msgdef(typename, ros_version=2)
            bag.add_topic(name, typename, schema, latched=name == "/map")
        for name, typename, build, t in plan:
            data = bytes(TS.serialize_cdr(build(t), typename))
            bag.write(name, t, data)
            written.setdefault(name, []).append((t, data))
    return written


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_bag_reads_back_in_rosbags(tmp_path: Path, distro: str) -> None:
    folder = tmp_path / "nested" / "run"
    written = _write(folder, distro)
    with Reader(folder) as reader:
        assert reader.message_count == 6
        assert reader.start_time == 1_000
        assert reader.duration == 4_000 - 1_000 + 1
        by_topic = {c.topic: c for c in reader.connections}
        assert {t: c.msgtype for t, c in by_topic.items()} == {
            "/map": GRID,
            "/scout/pose": POSE,
            "/markers": MARKERS,
            "/tf": TF,
        }
        assert {t: c.msgcount for t, c in by_topic.items()} == {
            "/map": 1,
            "/scout/pose": 3,
            "/markers": 1,
            "/tf": 1,
        }
        map_qos = by_topic["/map"].ext.offered_qos_profiles  # type: ignore[union-attr]
        pose_qos = by_topic["/scout/pose"].ext.offered_qos_profiles  # type: ignore[union-attr]
        assert map_qos[0].durability == QosDurability.TRANSIENT_LOCAL
        assert pose_qos[0].durability == QosDurability.VOLATILE
        read: dict[str, list[tuple[int, bytes]]] = {}
        for conn, t, raw in reader.messages():
            read.setdefault(conn.topic, []).append((t, bytes(raw)))
    assert {k: sorted(v) for k, v in read.items()} == {k: sorted(v) for k, v in written.items()}


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_messages_deserialize_with_anyreader(tmp_path: Path, distro: str) -> None:
    _write(tmp_path / "bag", distro)
    with AnyReader([tmp_path / "bag"], default_typestore=TS) as reader:
        poses: list[Any] = [
            reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages() if c.topic == "/scout/pose"
        ]
        grids: list[Any] = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages() if c.topic == "/map"]
    assert sorted(p.pose.position.x for p in poses) == [1.5e-6, 2e-6, 4e-6]
    assert list(grids[0].data) == [0, 100, -1, 0]
    assert grids[0].info.width == 2


def test_mcap_has_ros2_profile_and_encodings(tmp_path: Path) -> None:
    _write(tmp_path / "bag", "jazzy")
    (mcap_file,) = (tmp_path / "bag").glob("*.mcap")
    with mcap_file.open("rb") as stream:
        reader = make_reader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
    assert header.profile == "ros2"
    assert summary is not None
    assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    assert all("offered_qos_profiles" in c.metadata for c in summary.channels.values())


def test_metadata_versions(tmp_path: Path) -> None:
    import yaml

    _write(tmp_path / "h", "humble")
    _write(tmp_path / "j", "jazzy")
    humble = yaml.safe_load((tmp_path / "h" / "metadata.yaml").read_text())
    jazzy = yaml.safe_load((tmp_path / "j" / "metadata.yaml").read_text())
    assert humble["rosbag2_bagfile_information"]["version"] == 5
    assert "ros_distro" not in humble["rosbag2_bagfile_information"]
    assert jazzy["rosbag2_bagfile_information"]["version"] == 8
    assert jazzy["rosbag2_bagfile_information"]["ros_distro"] == "jazzy"


def test_non_empty_folder_is_refused(tmp_path: Path) -> None:
    (tmp_path / "old.txt").write_text("x")
    with pytest.raises(AlicaError, match=r"exists and is not empty"):
        BagWriter(tmp_path)


def test_unknown_topic_and_write_after_close(tmp_path: Path) -> None:
    bag = BagWriter(tmp_path / "bag")
    with pytest.raises(AlicaError, match=r"'/nope' is not in bag"):
        bag.write("/nope", 1, b"")
    bag.close()
    bag.close()
    with pytest.raises(AlicaError, match=r"is closed"):
        bag.write("/nope", 1, b"")
