"""The messages an agent shows ROS 2 (poses, /tf, the team map, markers, diagnostics): they decode with rosbags, at their rates."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from alica.app.ros2_bridge import (
    DIAGNOSTICS,
    MAP,
    MARKERS,
    POSE,
    TF,
    TOPICS,
    AgentTopics,
    Place,
    Topic,
    diagnostic_array,
    marker_array,
    occupancy_grid,
    pose_stamped,
    publishers,
    tf_message,
)
from alica.comm.ros2 import encode

STORES = {"humble": get_typestore(Stores.ROS2_HUMBLE), "jazzy": get_typestore(Stores.ROS2_JAZZY)}


def _decoded(typename: str, message: Mapping[str, Any], distro: str = "jazzy") -> Any:
    return STORES[distro].deserialize_cdr(encode(typename, message, distro), typename)


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_a_pose_and_its_transform_decode_with_the_robot_frame(distro: str) -> None:
    pose = _decoded(POSE.typename, pose_stamped(12.5, 3.0, -4.0, math.pi / 2), distro)
    assert (pose.header.stamp.sec, pose.header.stamp.nanosec, pose.header.frame_id) == (12, 500_000_000, "map")
    assert (pose.pose.position.x, pose.pose.position.y) == (3.0, -4.0)
    assert pose.pose.orientation.z == pytest.approx(math.sin(math.pi / 4))
    tf = _decoded(TF.typename, tf_message(12.5, "scout", 3.0, -4.0, 0.0), distro)
    (transform,) = tf.transforms
    assert (transform.header.frame_id, transform.child_frame_id) == ("map", "scout/base_link")
    assert (transform.transform.translation.x, transform.transform.rotation.w) == (3.0, 1.0)


def test_the_team_map_is_0_to_100_by_probability_and_minus_1_where_unknown() -> None:
    logodds = np.zeros((3, 4), dtype=np.float32)
    logodds[0, 0] = 5.0  # surely occupied
    logodds[1, 2] = -5.0  # surely free
    logodds[2, 3] = 0.01  # seen, undecided
    grid = _decoded(MAP.typename, occupancy_grid(2.0, (-1.0, 2.0), 0.25, logodds))
    assert (grid.info.width, grid.info.height, grid.info.resolution) == (4, 3, 0.25)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == (-1.0, 2.0)
    cells = np.asarray(grid.data).reshape(3, 4)
    assert cells[0, 0] == 99 and cells[1, 2] == 1 and cells[2, 3] == 50
    assert (cells == -1).sum() == 9


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_markers_clear_then_mark_each_sample_and_goal_with_a_label(distro: str) -> None:
    places = (Place("s1", 1.0, 2.0, "red-black-red"), Place("g", 0.0, 0.0, goal=True))
    markers = _decoded(MARKERS.typename, marker_array(3.0, "scout", places), distro).markers
    assert markers[0].action == 3  # DELETEALL: a sample no longer known goes
    assert [m.type for m in markers[1:]] == [3, 9, 3, 9]  # cylinder, text per place
    assert markers[2].text == "s1 (red-black-red)" and markers[4].text == "goal g"
    assert (markers[1].pose.position.x, markers[1].pose.position.y) == (1.0, 2.0)
    assert len({(m.ns, m.id) for m in markers}) == len(markers)


def test_diagnostics_say_each_plan_its_task_and_state() -> None:
    plans = [
        {"key": "root", "plan": "Mission", "task": "Explore", "state": "Exploring", "status": "running"},
        {"key": "root/1", "plan": "Fetch", "task": "", "state": "", "status": "failure"},
    ]
    array = _decoded(DIAGNOSTICS.typename, diagnostic_array(4.0, "scout", plans))
    first, second = array.status
    assert (first.level, first.name, first.message, first.hardware_id) == (
        0,
        "alica/scout/root",
        "Mission: Exploring",
        "scout",
    )
    assert {kv.key: kv.value for kv in first.values}["task"] == "Explore"
    assert (second.level, second.message) == (2, "Fetch: idle")
    (idle,) = _decoded(DIAGNOSTICS.typename, diagnostic_array(4.0, "scout", [])).status
    assert (idle.level, idle.name, idle.message) == (0, "alica/scout", "no plan running")


class _View:
    def __init__(self) -> None:
        self.xy = (0.0, 0.0, 0.0)
        self.grid: tuple[int, tuple[float, float], float, np.ndarray] | None = None
        self.found: tuple[Place, ...] = ()
        self.running: tuple[Mapping[str, str], ...] = ({"key": "root", "plan": "P", "state": "A"},)

    def pose(self) -> tuple[float, float, float] | None:
        return self.xy

    def team_map(self) -> tuple[int, tuple[float, float], float, np.ndarray] | None:
        return self.grid

    def places(self) -> tuple[Place, ...]:
        return self.found

    def plans(self) -> tuple[Mapping[str, str], ...]:
        return self.running


class _Sink:
    def __init__(self) -> None:
        self.declared: dict[str, Topic] = {}
        self.messages: list[tuple[str, int, bytes]] = []

    def declare(self, path: str, topic: Topic) -> None:
        self.declared[path] = topic

    def put(self, path: str, stamp_ns: int, data: bytes) -> None:
        self.messages.append((path, stamp_ns, data))

    def count(self, path: str) -> int:
        return sum(1 for p, _, _ in self.messages if p == path)


def test_an_agent_publishes_poses_at_10_hz_the_map_when_it_changed_and_markers_when_they_changed() -> None:
    view, sink = _View(), _Sink()
    agent = AgentTopics("scout", view, [sink])
    assert set(sink.declared) == {"/tf", "/scout/pose", "/scout/team_map", "/scout/markers", "/scout/diagnostics"}
    assert sink.declared["/scout/team_map"].latched
    for tick in range(300):  # 10 s at 30 Hz
        now = tick / 30.0
        view.xy = (now, 0.0, 0.0)
        if tick == 60:
            view.grid = (1, (0.0, 0.0), 0.5, np.zeros((2, 2), dtype=np.float32))
        if tick == 200:
            view.grid = (2, (0.0, 0.0), 0.5, np.ones((2, 2), dtype=np.float32))
        if tick == 90:
            view.found = (Place("s1", 1.0, 1.0, "k"),)
        agent.publish(now)
    assert 98 <= sink.count("/scout/pose") <= 101 and sink.count("/tf") == sink.count("/scout/pose")
    assert sink.count("/scout/team_map") == 2  # two versions, 5 s or more apart
    assert sink.count("/scout/markers") == 2  # the empty set at the start, then s1
    assert 10 <= sink.count("/scout/diagnostics") <= 11  # once a second, the plans unchanged
    stamps = [s for p, s, _ in sink.messages if p == "/scout/pose"]
    assert stamps == sorted(stamps) and stamps[1] - stamps[0] == pytest.approx(1e8, abs=4e7)


def test_a_crashed_agent_says_nothing_and_an_epoch_moves_the_stamps() -> None:
    sink, views = _Sink(), {"a": _View(), "b": _View()}
    publish = publishers(views, lambda _name: [sink], "jazzy", alive=lambda name: name != "b", epoch=100.0)
    publish(1.0)
    assert {p for p, _, _ in sink.messages} == {"/tf", "/a/pose", "/a/markers", "/a/diagnostics"}
    assert all(stamp == 101_000_000_000 for _, stamp, _ in sink.messages)
    assert {topic.name for topic in TOPICS} == {"tf", "pose", "team_map", "markers", "diagnostics"}
