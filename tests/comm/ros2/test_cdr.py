"""The CDR codec: byte for byte what rosbags writes, round trips, checked values, hostile data."""

from __future__ import annotations

import math
import random
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from alica.comm.ros2 import decode, encode, known_types, schema_text
from alica.comm.ros2.bag import BagWriter
from alica.comm.ros2.types import PRIMITIVES, FieldType, lookup
from alica.errors import AlicaError

STORES = {"humble": get_typestore(Stores.ROS2_HUMBLE), "jazzy": get_typestore(Stores.ROS2_JAZZY)}
CASES = [(distro, name) for distro in ("humble", "jazzy") for name in known_types(distro)]
STRINGS = ["", "map", "base_link", "ünïcode ✓", "a longer frame name"]


def _scalar(base: str, rng: random.Random) -> Any:
    if base == "bool":
        return rng.random() < 0.5
    if base.startswith("float"):
        return rng.randint(-4000, 4000) / 8
    if base == "byte":  # rosbags packs byte as a signed char; ROS 2's octet is 0..255
        return rng.randint(0, 127)
    info = np.iinfo(np.dtype(PRIMITIVES[base][0]))
    return rng.choice([int(info.min), int(info.max), rng.randint(int(info.min), int(info.max))])


def _one(ftype: FieldType, distro: str, rng: random.Random) -> Any:
    if ftype.nested:
        return sample(ftype.base, distro, rng)
    if ftype.base == "string":
        return rng.choice(STRINGS)
    return _scalar(ftype.base, rng)


def sample(typename: str, distro: str, rng: random.Random) -> dict[str, Any]:
    """A value of every field of ``typename``, primitive arrays as numpy arrays."""
    value: dict[str, Any] = {}
    for field in lookup(typename, distro).fields:
        ftype = field.type
        if ftype.kind == "single":
            value[field.name] = _one(ftype, distro, rng)
            continue
        count = ftype.size if ftype.kind == "array" else rng.randint(0, 3)
        if ftype.base in PRIMITIVES:
            items = [_scalar(ftype.base, rng) for _ in range(count)]
            value[field.name] = np.array(items, dtype=PRIMITIVES[ftype.base][0])
        else:
            element = FieldType(ftype.base)
            value[field.name] = [_one(element, distro, rng) for _ in range(count)]
    return value


def to_rosbags(typename: str, value: dict[str, Any], distro: str) -> Any:
    """The rosbags message object holding ``value``."""
    store = STORES[distro]
    kwargs: dict[str, Any] = {}
    for field in lookup(typename, distro).fields:
        item = value[field.name]
        if field.type.nested and field.type.kind == "single":
            item = to_rosbags(field.type.base, item, distro)
        elif field.type.nested:
            item = [to_rosbags(field.type.base, x, distro) for x in item]
        kwargs[field.name] = item
    return store.types[typename](**kwargs)


def same(left: Any, right: Any) -> bool:
    """Equal values, NaN equal to NaN; numpy arrays must also share their dtype."""
    if isinstance(left, dict) and isinstance(right, dict):
        return left.keys() == right.keys() and all(same(left[k], right[k]) for k in left)
    if isinstance(left, np.ndarray) or isinstance(right, np.ndarray):
        if not (isinstance(left, np.ndarray) and isinstance(right, np.ndarray)) or left.dtype != right.dtype:
            return False
        return bool(np.array_equal(left, right, equal_nan=left.dtype.kind == "f"))
    if isinstance(left, list) and isinstance(right, list):
        return len(left) == len(right) and all(same(a, b) for a, b in zip(left, right))
    if isinstance(left, float) and isinstance(right, float) and math.isnan(left):
        return math.isnan(right)
    return bool(left == right) and type(left) is type(right)


@pytest.mark.parametrize(("distro", "typename"), CASES)
def test_encoding_matches_rosbags_byte_for_byte_and_decodes_its_bytes(distro: str, typename: str) -> None:
    for seed in range(4):
        value = sample(typename, distro, random.Random(seed))
        reference = STORES[distro].serialize_cdr(to_rosbags(typename, value, distro), typename)
        assert encode(typename, value, distro) == bytes(reference)
        assert same(decode(typename, bytes(reference), distro), value)


def test_defaults_fill_missing_fields() -> None:
    value = decode("geometry_msgs/msg/PoseStamped", encode("geometry_msgs/msg/PoseStamped", {}))
    assert value["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert value["pose"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}  # as in the .msg
    odometry = decode("nav_msgs/msg/Odometry", encode("nav_msgs/msg/Odometry", {}))
    assert odometry["pose"]["covariance"].dtype == np.dtype("<f8") and len(odometry["pose"]["covariance"]) == 36
    marker = decode("visualization_msgs/msg/Marker", encode("visualization_msgs/msg/Marker", {"id": 3}))
    assert (marker["id"], marker["points"], marker["frame_locked"]) == (3, [], False)
    assert marker["texture"]["data"].dtype == np.uint8


def test_primitive_arrays_accept_lists_tuples_arrays_and_bytes() -> None:
    grid = "nav_msgs/msg/OccupancyGrid"
    as_list = encode(grid, {"data": [0, 100, -1, 50]})
    assert encode(grid, {"data": (0, 100, -1, 50)}) == as_list
    assert encode(grid, {"data": np.array([[0, 100], [-1, 50]], dtype=np.int64)}) == as_list
    assert encode(grid, {"data": bytes([0, 100, 255, 50])}) == as_list
    assert decode(grid, as_list)["data"].tolist() == [0, 100, -1, 50]
    image = decode("sensor_msgs/msg/CompressedImage", encode("sensor_msgs/msg/CompressedImage", {"data": b"\xff\xd8"}))
    assert image["data"].dtype == np.uint8 and image["data"].tolist() == [255, 216]
    scan = {"ranges": np.arange(5, dtype=np.float64), "intensities": [1, 2.5]}
    decoded = decode("sensor_msgs/msg/LaserScan", encode("sensor_msgs/msg/LaserScan", scan))
    assert decoded["ranges"].dtype == np.dtype("<f4") and decoded["intensities"].tolist() == [1.0, 2.5]


def test_nan_and_infinity_are_allowed() -> None:
    twist = {"linear": {"x": math.nan, "y": math.inf}, "angular": {"z": -math.inf}}
    value = decode("geometry_msgs/msg/Twist", encode("geometry_msgs/msg/Twist", twist))
    assert math.isnan(value["linear"]["x"]) and value["linear"]["y"] == math.inf
    scan = decode("sensor_msgs/msg/LaserScan", encode("sensor_msgs/msg/LaserScan", {"ranges": [math.inf, math.nan]}))
    assert scan["ranges"][0] == np.inf and np.isnan(scan["ranges"][1])


def test_a_big_occupancy_grid_encodes_fast() -> None:
    data = np.random.default_rng(0).integers(-1, 101, size=400 * 400, dtype=np.int8)
    grid = {"header": {"frame_id": "map"}, "info": {"resolution": 0.05, "width": 400, "height": 400}, "data": data}
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        payload = encode("nav_msgs/msg/OccupancyGrid", grid)
        best = min(best, time.perf_counter() - start)
    assert best < 0.010
    assert np.array_equal(decode("nav_msgs/msg/OccupancyGrid", payload)["data"], data)


@pytest.mark.parametrize(
    ("typename", "value", "message"),
    [
        ("geometry_msgs/msg/Twist", {"linear": {"x": "a"}}, "geometry_msgs/msg/Twist.linear.x: expected a number, got 'a'"),
        ("geometry_msgs/msg/Twist", {"linear": {"w": 1.0}}, "geometry_msgs/msg/Twist.linear.w: geometry_msgs/msg/Vector3 has no field 'w'"),
        ("geometry_msgs/msg/Twist", {"linear": [1.0, 2.0, 3.0]}, "Twist.linear: expected a mapping of geometry_msgs/msg/Vector3 fields"),
        ("geometry_msgs/msg/Twist", {"angular": {"z": True}}, "Twist.angular.z: expected a float64 number, got True"),
        ("std_msgs/msg/String", {"data": 5}, "std_msgs/msg/String.data: expected a str, got 5"),
        ("std_msgs/msg/String", {"data": "a\0b"}, "String.data: a ROS 2 string cannot hold a NUL"),
        ("std_msgs/msg/Header", {"stamp": {"sec": 2**31}}, "Header.stamp.sec: 2147483648 is out of the int32 range"),
        ("std_msgs/msg/Header", {"stamp": {"nanosec": -1}}, "Header.stamp.nanosec: -1 is out of the uint32 range"),
        ("std_msgs/msg/Header", {"stamp": {"sec": 1.5}}, "Header.stamp.sec: expected an integer, got 1.5"),
        ("std_msgs/msg/ColorRGBA", {"r": 1e300}, "ColorRGBA.r: 1e+300 is out of the float32 range"),
        ("geometry_msgs/msg/PoseWithCovariance", {"covariance": [0.0] * 35}, "PoseWithCovariance.covariance: expected exactly 36 elements, got 35"),
        ("nav_msgs/msg/OccupancyGrid", {"data": [0, 128]}, "OccupancyGrid.data: element 128 is out of the int8 range"),
        ("nav_msgs/msg/OccupancyGrid", {"data": [0.5]}, "OccupancyGrid.data: expected integers, got an array of float64"),
        ("nav_msgs/msg/OccupancyGrid", {"data": "abc"}, "OccupancyGrid.data: expected a list or numpy array of int8, got str"),
        ("sensor_msgs/msg/LaserScan", {"ranges": b"\x00\x00"}, "LaserScan.ranges: bytes are accepted only for 1-byte"),
        ("sensor_msgs/msg/LaserScan", {"ranges": ["a"]}, "LaserScan.ranges: expected numbers"),
        ("sensor_msgs/msg/LaserScan", {"ranges": np.array([1e300])}, "LaserScan.ranges: element 1e+300 is out of the float32 range"),
        ("visualization_msgs/msg/Marker", {"frame_locked": 1}, "Marker.frame_locked: expected a bool, got 1"),
        ("visualization_msgs/msg/MarkerArray", {"markers": [{}, {"pose": {"position": {"x": None}}}]}, "visualization_msgs/msg/MarkerArray.markers[1].pose.position.x: expected a number, got None"),
        ("visualization_msgs/msg/MarkerArray", {"markers": {}}, "MarkerArray.markers: expected a list, got dict"),
        ("diagnostic_msgs/msg/DiagnosticStatus", {"level": 256}, "DiagnosticStatus.level: 256 is out of the byte range"),
    ],
)  # fmt: skip
def test_wrong_values_raise_with_the_type_and_field_path(typename: str, value: Any, message: str) -> None:
    with pytest.raises(AlicaError) as caught:
        encode(typename, value)
    assert message in str(caught.value)


def test_byte_fields_take_ints_or_one_byte() -> None:
    status = "diagnostic_msgs/msg/DiagnosticStatus"
    assert decode(status, encode(status, {"level": b"\x02"}))["level"] == 2
    assert decode(status, encode(status, {"level": 3}))["level"] == 3


def test_unknown_types_and_distros_are_refused() -> None:
    with pytest.raises(AlicaError, match="known types are"):
        encode("geometry_msgs/msg/Twists", {})
    with pytest.raises(AlicaError, match="humble, jazzy"):
        decode("geometry_msgs/msg/Twist", b"\x00\x01\x00\x00", "foxy")


@pytest.mark.parametrize(
    ("typename", "data", "message"),
    [
        ("std_msgs/msg/String", b"", "header"),
        ("std_msgs/msg/String", b"\x00\x00\x00\x00\x02\x00\x00\x00a\x00", "header"),  # big endian
        ("std_msgs/msg/String", b"\x00\x01\x00\x00\x05\x00", "needs 4 bytes"),
        ("std_msgs/msg/String", b"\x00\x01\x00\x00\x05\x00\x00\x00ab", "needs 5 bytes"),
        ("std_msgs/msg/String", b"\x00\x01\x00\x00\x02\x00\x00\x00ab", "does not end with NUL"),
        ("std_msgs/msg/String", b"\x00\x01\x00\x00\x02\x00\x00\x00\xff\x00", "not UTF-8"),
        ("geometry_msgs/msg/Twist", b"\x00\x01\x00\x00" + bytes(40), "needs 8 bytes"),
        ("nav_msgs/msg/OccupancyGrid", encode("nav_msgs/msg/OccupancyGrid", {})[:-4] + b"\xff\xff\xff\xff", "needs 4294967295"),
        ("tf2_msgs/msg/TFMessage", b"\x00\x01\x00\x00\xff\xff\xff\x7f", "exceeds the 0 bytes left"),
    ],
)  # fmt: skip
def test_malformed_data_raises_alica_errors(typename: str, data: bytes, message: str) -> None:
    with pytest.raises(AlicaError) as caught:
        decode(typename, data)
    assert message in str(caught.value)


def test_trailing_bytes_are_ignored() -> None:
    payload = encode("std_msgs/msg/String", {"data": "hi"})
    assert decode("std_msgs/msg/String", payload + b"\x00\x00\x00")["data"] == "hi"


def _scalar_strategy(base: str) -> st.SearchStrategy[Any]:
    if base == "bool":
        return st.booleans()
    if base == "float32":
        return st.floats(width=32)
    if base == "float64":
        return st.floats()
    if base == "byte":
        return st.integers(0, 127)
    info = np.iinfo(np.dtype(PRIMITIVES[base][0]))
    return st.integers(int(info.min), int(info.max))


def _text() -> st.SearchStrategy[str]:
    return st.text(st.characters(blacklist_categories=["Cs"], blacklist_characters="\0"), max_size=12)


def _single(ftype: FieldType) -> st.SearchStrategy[Any]:
    if ftype.nested:
        return message_strategy(ftype.base)
    return _text() if ftype.base == "string" else _scalar_strategy(ftype.base)


def message_strategy(typename: str) -> st.SearchStrategy[dict[str, Any]]:
    """Random complete values of ``typename`` (Jazzy), primitive arrays as numpy arrays."""
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for field in lookup(typename).fields:
        ftype = field.type
        if ftype.kind == "single":
            fields[field.name] = _single(ftype)
        elif ftype.base in PRIMITIVES:
            shape = ftype.size if ftype.kind == "array" else st.integers(0, 40)
            dtype = np.dtype(PRIMITIVES[ftype.base][0])
            fields[field.name] = hnp.arrays(dtype, shape, elements=_scalar_strategy(ftype.base))
        else:
            low, high = (ftype.size, ftype.size) if ftype.kind == "array" else (0, 3)
            fields[field.name] = st.lists(_single(FieldType(ftype.base)), min_size=low, max_size=high)
    return st.fixed_dictionaries(fields)


ROUND_TRIP = [
    "geometry_msgs/msg/Twist",
    "geometry_msgs/msg/PoseStamped",
    "sensor_msgs/msg/LaserScan",
    "nav_msgs/msg/OccupancyGrid",
    "std_msgs/msg/String",
    "diagnostic_msgs/msg/DiagnosticArray",
]


@pytest.mark.parametrize("typename", ROUND_TRIP)
def test_random_values_round_trip(typename: str) -> None:
    @settings(max_examples=60)
    @given(message_strategy(typename))
    def check(value: dict[str, Any]) -> None:
        payload = encode(typename, value)
        assert same(decode(typename, payload), value)
        assert STORES["jazzy"].deserialize_cdr(payload, typename) is not None

    check()


@pytest.mark.parametrize("typename", [*ROUND_TRIP, "visualization_msgs/msg/MarkerArray", "tf2_msgs/msg/TFMessage"])
def test_random_bytes_decode_or_raise_alica_errors(typename: str) -> None:
    @settings(max_examples=150)
    @given(st.booleans(), st.binary(max_size=120))
    def check(with_header: bool, body: bytes) -> None:
        data = (b"\x00\x01\x00\x00" if with_header else b"") + body
        try:
            decode(typename, data)
        except AlicaError:
            pass

    check()


def test_a_bag_written_with_the_schemas_reads_back_with_rosbags(tmp_path: Path) -> None:
    for distro in ("humble", "jazzy"):
        rng = random.Random(7)
        messages = [(name, sample(name, distro, rng)) for name in ROUND_TRIP + ["visualization_msgs/msg/MarkerArray"]]
        folder = tmp_path / distro
        with BagWriter(folder, distro=distro) as bag:
            for index, (name, value) in enumerate(messages):
                topic = f"/topic{index}"
                bag.add_topic(topic, name, schema_text(name, distro))
                bag.write(topic, 1_000 + index, encode(name, value, distro))
        with AnyReader([folder], default_typestore=STORES[distro]) as reader:
            read = {conn.topic: reader.deserialize(raw, conn.msgtype) for conn, _, raw in reader.messages()}
        for index, (name, value) in enumerate(messages):
            again = STORES[distro].serialize_cdr(read[f"/topic{index}"], name)
            assert same(decode(name, bytes(again), distro), value), name
