"""The rmw_zenoh wire format: keys, tokens, attachments and QoS strings, and a node seen by a fake ROS 2 node."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest
from rosbags.typesys import Stores, get_typestore

from alica.comm.ros2.rmw import (
    DEFAULT,
    LATCHED,
    SENSOR,
    Qos,
    Ros2Node,
    attachment,
    endpoint_token,
    fully_qualified,
    mangle,
    node_token,
    open_session,
    parse_attachment,
    topic_key,
)
from alica.comm.zenoh_transport import free_endpoints
from tests.comm.ros2.fake_ros2 import Endpoint, FakeRos2, fake_attachment

POSE = "geometry_msgs::msg::dds_::PoseStamped_"
HASH = "RIHS01_" + "ab" * 32
GID = bytes(range(16))


# --- pure forms, against the design document's examples -----------------------------------------


def test_data_key_is_the_documented_one() -> None:
    assert (
        topic_key(0, "/robot1/cmd_vel", "geometry_msgs::msg::dds_::Twist_", HASH)
        == "0/robot1/cmd_vel/geometry_msgs::msg::dds_::Twist_/" + HASH
    )
    assert topic_key(7, "/chatter", "std_msgs::msg::dds_::String_", "TypeHashNotSupported") == (
        "7/chatter/std_msgs::msg::dds_::String_/TypeHashNotSupported"
    )


def test_names_are_mangled_and_qualified() -> None:
    assert mangle("/robot1/pose") == "%robot1%pose"
    assert mangle("") == "%"
    assert fully_qualified("/robot1", "pose") == "/robot1/pose"
    assert fully_qualified("", "pose") == "/pose"
    assert fully_qualified("/robot1", "/map") == "/map"
    with pytest.raises(ValueError, match="topic"):
        fully_qualified("", "bad topic")


def test_qos_compact_forms() -> None:
    assert DEFAULT.text() == "::,10:,:,:,,"  # the design's example: reliable, volatile, keep last 10
    assert LATCHED.text() == ":1:,1:,:,:,,"
    assert SENSOR.text() == "2::,5:,:,:,,"
    with pytest.raises(ValueError, match="depth"):
        Qos(depth=0)


def test_attachment_is_33_bytes_and_round_trips() -> None:
    data = attachment(1, 1_700_000_000_123_456_789, GID)
    assert len(data) == 33
    assert data[:8] == (1).to_bytes(8, "little") and data[16] == 16 and data[17:] == GID
    assert data == fake_attachment(1, 1_700_000_000_123_456_789, GID)
    assert parse_attachment(data) == (1, 1_700_000_000_123_456_789, GID)


@pytest.mark.parametrize("bad", [b"", b"\x00" * 32, b"\x00" * 34, fake_attachment(1, 2, GID)[:16] + b"\x08" + GID])
def test_a_malformed_attachment_is_refused(bad: bytes) -> None:
    with pytest.raises(ValueError, match="attachment"):
        parse_attachment(bad)


def test_tokens_are_the_documented_ones() -> None:
    assert node_token(0, "aac3178e146ba6f1fc6e6a4085e77f21", 0, "", "talker") == (
        "@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/talker"
    )
    assert endpoint_token(
        0, "aac3178e146ba6f1fc6e6a4085e77f21", 0, 10, "MP", "", "talker", "/chatter",
        "std_msgs::msg::dds_::String_", "TypeHashNotSupported", DEFAULT,
    ) == (
        "@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MP/%/%/talker/%chatter/"
        "std_msgs::msg::dds_::String_/TypeHashNotSupported/::,10:,:,:,,"
    )  # fmt: skip
    assert endpoint_token(2, "z", 1, 3, "MS", "/robot1", "alica", "/robot1/map", "T", HASH, LATCHED, "/sec") == (
        f"@ros2_lv/2/z/1/3/MS/%sec/%robot1/alica/%robot1%map/T/{HASH}/:1:,1:,:,:,,"
    )
    with pytest.raises(ValueError, match="MP"):
        endpoint_token(0, "z", 1, 2, "XX", "", "n", "/t", "T", HASH, DEFAULT)


def test_open_session_checks_the_endpoint() -> None:
    for bad in ("127.0.0.1:7447", "tcp/127.0.0.1", "tcp/127.0.0.1:99999", "tcp/a b:1"):
        with pytest.raises(ValueError, match="tcp/127.0.0.1:7447"):
            open_session(bad)
    with pytest.raises(ValueError, match="endpoint"):
        open_session(None, listen=["nope"])


# --- a node on loopback, seen by the fake ROS 2 node ----------------------------------------------


@pytest.fixture
def net() -> Iterator[tuple[Ros2Node, FakeRos2]]:
    endpoint = free_endpoints(1)[0]
    session = open_session(None, listen=[endpoint])
    node = Ros2Node(session, "alica", "/robot1")
    fake = FakeRos2(endpoint)
    try:
        yield node, fake
    finally:
        node.close()
        fake.close()
        session.close()


def pose_payload(x: float) -> tuple[bytes, str]:
    store = get_typestore(Stores.ROS2_JAZZY)
    pose = store.types["geometry_msgs/msg/PoseStamped"]
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    point = store.types["geometry_msgs/msg/Point"]
    quat = store.types["geometry_msgs/msg/Quaternion"]
    msg = pose(
        header(stamp(1, 2), "map"),
        store.types["geometry_msgs/msg/Pose"](point(x, 2.0, 0.0), quat(0.0, 0.0, 0.0, 1.0)),
    )
    return bytes(store.serialize_cdr(msg, "geometry_msgs/msg/PoseStamped")), store.hash_rihs01(
        "geometry_msgs/msg/PoseStamped"
    )


def test_a_published_pose_reaches_the_fake_node_with_key_attachment_and_payload(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, fake = net
    payload, type_hash = pose_payload(1.5)
    fake.subscribe(f"0/robot1/pose/{POSE}/*")
    publisher = node.publisher("pose", POSE, type_hash)
    assert fake.wait(lambda: any(e.kind == "MP" for e in fake.endpoints()))
    deadline = time.monotonic() + 5
    while not fake.received and time.monotonic() < deadline:  # the subscription may take a moment to match
        publisher.put(payload, timestamp_ns=1000)
        fake.wait(lambda: bool(fake.received), 0.05)
    first = len(fake.received)
    assert first >= 1
    publisher.put(payload, timestamp_ns=2000)
    assert fake.wait(lambda: len(fake.received) == first + 1)
    got = fake.received
    assert got[0].key == f"0/robot1/pose/{POSE}/{type_hash}" and type_hash.startswith("RIHS01_")
    assert [r.sequence for r in got] == list(range(got[0].sequence, got[0].sequence + len(got)))
    assert got[-1].timestamp_ns == 2000 and got[0].timestamp_ns == 1000
    assert {r.gid for r in got} == {publisher.gid} and len(publisher.gid) == 16
    assert got[-1].payload == payload
    store = get_typestore(Stores.ROS2_JAZZY)
    decoded = store.deserialize_cdr(got[-1].payload, "geometry_msgs/msg/PoseStamped")
    assert decoded.pose.position.x == 1.5  # type: ignore[attr-defined]


def test_the_sequence_starts_at_one(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, fake = net
    publisher = node.publisher("s", POSE, HASH, Qos(transient_local=True, depth=5))  # the history holds both
    assert publisher.put(b"\x00\x01\x00\x00a") == 1
    assert publisher.put(b"\x00\x01\x00\x00b") == 2
    fake.subscribe(f"0/robot1/s/{POSE}/*", history=True)
    assert fake.wait(lambda: {r.sequence for r in fake.received} == {1, 2})
    assert {(r.sequence, r.payload) for r in fake.received} == {(1, b"\x00\x01\x00\x00a"), (2, b"\x00\x01\x00\x00b")}


def test_the_graph_shows_the_node_and_its_endpoints_with_their_qos(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, fake = net
    node.publisher("pose", POSE, HASH)
    node.publisher("/map", "nav_msgs::msg::dds_::OccupancyGrid_", HASH, LATCHED)
    node.subscribe("goal", "std_msgs::msg::dds_::String_", HASH, lambda payload, meta: None, SENSOR)
    expected = [
        Endpoint("MP", "/robot1", "alica", "/robot1/pose", POSE, HASH, "::,10:,:,:,,"),
        Endpoint("MP", "/robot1", "alica", "/map", "nav_msgs::msg::dds_::OccupancyGrid_", HASH, ":1:,1:,:,:,,"),
        Endpoint("MS", "/robot1", "alica", "/robot1/goal", "std_msgs::msg::dds_::String_", HASH, "2::,5:,:,:,,"),
    ]
    assert fake.wait(lambda: sorted(fake.endpoints(), key=repr) == sorted(expected, key=repr))
    assert fake.nodes() == {("", "/robot1", "alica")}
    node.close()
    assert fake.wait(lambda: fake.tokens() == [])


def test_a_latched_message_reaches_a_late_subscriber(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, fake = net
    publisher = node.publisher("/map", "nav_msgs::msg::dds_::OccupancyGrid_", HASH, LATCHED)
    publisher.put(b"\x00\x01\x00\x00old", timestamp_ns=1)
    publisher.put(b"\x00\x01\x00\x00map", timestamp_ns=2)
    fake.subscribe("0/map/nav_msgs::msg::dds_::OccupancyGrid_/*", history=True)
    assert fake.wait(lambda: len(fake.received) >= 1)
    assert [(r.payload, r.sequence) for r in fake.received] == [(b"\x00\x01\x00\x00map", 2)]  # depth 1


def test_a_subscriber_receives_and_drops_malformed_attachments(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, fake = net
    got: list[tuple[bytes, tuple[int, int, bytes] | None]] = []
    arrived = threading.Event()

    def take(payload: bytes, meta: tuple[int, int, bytes] | None) -> None:
        got.append((payload, meta))
        arrived.set()

    node.subscribe("goal", "std_msgs::msg::dds_::String_", "TypeHashNotSupported", take)
    assert fake.wait(lambda: any(e.type_hash == "TypeHashNotSupported" for e in fake.endpoints()))
    key = "0/robot1/goal/std_msgs::msg::dds_::String_/TypeHashNotSupported"
    deadline = time.monotonic() + 5
    sequence = 0
    while not got and time.monotonic() < deadline:
        sequence += 1
        fake.put(key, b"\x00\x01\x00\x00goal", fake_attachment(sequence, 42, GID))
        arrived.wait(0.05)  # wakes as soon as it arrives
    assert got and got[0] == (b"\x00\x01\x00\x00goal", (sequence, 42, GID))
    count = len(got)
    fake.put(key, b"bad", b"\x01\x02\x03")
    fake.put(key, b"bad", fake_attachment(1, 2, GID)[:16] + b"\x07" + GID)
    fake.put(key, b"\x00\x01\x00\x00last", None)
    assert fake.wait(lambda: len(got) == count + 1 and node.dropped == 2)
    assert got[-1] == (b"\x00\x01\x00\x00last", None)


def test_a_closed_node_refuses_new_endpoints(net: tuple[Ros2Node, FakeRos2]) -> None:
    node, _ = net
    node.close()
    with pytest.raises(RuntimeError, match="closed"):
        node.publisher("pose", POSE, HASH)
