"""ROS 2 message definitions, type hashes and schemas, checked against rosbags and published hashes."""

from __future__ import annotations

from typing import Any

import pytest
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from alica.comm.ros2 import dds_name, known_types, schema_text, type_hash
from alica.comm.ros2.types import FieldType, lookup, parse_msg
from alica.errors import AlicaError

STORES = {"humble": get_typestore(Stores.ROS2_HUMBLE), "jazzy": get_typestore(Stores.ROS2_JAZZY)}
CASES = [(distro, name) for distro in ("humble", "jazzy") for name in known_types(distro)]
EXPECTED = {
    "builtin_interfaces/msg/Duration",
    "builtin_interfaces/msg/Time",
    "diagnostic_msgs/msg/DiagnosticArray",
    "diagnostic_msgs/msg/DiagnosticStatus",
    "diagnostic_msgs/msg/KeyValue",
    "geometry_msgs/msg/Point",
    "geometry_msgs/msg/Point32",
    "geometry_msgs/msg/Pose",
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovariance",
    "geometry_msgs/msg/Quaternion",
    "geometry_msgs/msg/Transform",
    "geometry_msgs/msg/TransformStamped",
    "geometry_msgs/msg/Twist",
    "geometry_msgs/msg/TwistStamped",
    "geometry_msgs/msg/TwistWithCovariance",
    "geometry_msgs/msg/Vector3",
    "nav_msgs/msg/MapMetaData",
    "nav_msgs/msg/OccupancyGrid",
    "nav_msgs/msg/Odometry",
    "sensor_msgs/msg/CompressedImage",
    "sensor_msgs/msg/LaserScan",
    "std_msgs/msg/ColorRGBA",
    "std_msgs/msg/Header",
    "std_msgs/msg/String",
    "rosgraph_msgs/msg/Clock",
    "tf2_msgs/msg/TFMessage",
    "visualization_msgs/msg/Marker",
    "visualization_msgs/msg/MarkerArray",
    "visualization_msgs/msg/MeshFile",
    "visualization_msgs/msg/UVCoordinate",
}
# Jazzy hashes as published by copper-project/copper-rs (components/payloads/cu_ros2_payloads/all_rihs.md),
# generated there by a ROS 2 installation, independently of rosbags.
PUBLISHED = {
    "builtin_interfaces/msg/Time": "b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "diagnostic_msgs/msg/DiagnosticArray": "5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e",
    "geometry_msgs/msg/PoseStamped": "10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
    "geometry_msgs/msg/PoseWithCovariance": "9a7c0fd234b7f45c6098745ecccd773ca1085670e64107135397aee31c02e1bb",
    "geometry_msgs/msg/Twist": "9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    "nav_msgs/msg/OccupancyGrid": "8d348150c12913a31ee0ec170fbf25089e4745d17035792a1ba94d6f0bc0cfc7",
    "nav_msgs/msg/Odometry": "3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
    "visualization_msgs/msg/Marker": "45b13ccf791f225962bf74e746f9644518855d783a6f42ba0cc14fde2b4f3ce0",
    "visualization_msgs/msg/MarkerArray": "86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
    "visualization_msgs/msg/UVCoordinate": "f27f7ed21fe360c6066944f856b801a0c0d1e94e815b6886444b42d90b196a26",
}


def _rosbags_fielddef(ftype: FieldType) -> Any:
    """Our field type in rosbags' field-definition form."""
    element: Any = (Nodetype.NAME, ftype.base) if ftype.nested else (Nodetype.BASE, (ftype.base, ftype.string_bound))
    if ftype.kind == "single":
        return element
    if ftype.kind == "array":
        return (Nodetype.ARRAY, (element, ftype.size))
    return (Nodetype.SEQUENCE, (element, ftype.size if ftype.kind == "bounded" else 0))


def _ours(typename: str, distro: str) -> tuple[list[Any], list[Any]]:
    msg = lookup(typename, distro)
    constants = [(c.name, c.base, c.value) for c in msg.constants]
    fields = [(f.name, _rosbags_fielddef(f.type)) for f in msg.fields]
    return constants, fields


def test_the_known_types_are_the_expected_ones_in_both_distros() -> None:
    for distro in ("humble", "jazzy"):
        names = known_types(distro)
        assert names == tuple(sorted(EXPECTED))
        assert set(names) <= set(STORES[distro].fielddefs)


@pytest.mark.parametrize(("distro", "typename"), CASES)
def test_fields_and_constants_match_rosbags(distro: str, typename: str) -> None:
    constants, fields = STORES[distro].fielddefs[typename]
    assert _ours(typename, distro) == ([tuple(c) for c in constants], [tuple(f) for f in fields])


def test_marker_differs_between_humble_and_jazzy_by_arrow_strip() -> None:
    humble = {c.name for c in lookup("visualization_msgs/msg/Marker", "humble").constants}
    jazzy = {c.name for c in lookup("visualization_msgs/msg/Marker", "jazzy").constants}
    assert jazzy - humble == {"ARROW_STRIP"}
    assert lookup("visualization_msgs/msg/Marker", "humble").fields == lookup("visualization_msgs/msg/Marker").fields


@pytest.mark.parametrize("typename", known_types("jazzy"))
def test_jazzy_type_hashes_match_rosbags(typename: str) -> None:
    assert type_hash(typename, "jazzy") == STORES["jazzy"].hash_rihs01(typename)


def test_jazzy_type_hashes_match_published_ones() -> None:
    assert type_hash("std_msgs/msg/String") == "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    for typename, digest in PUBLISHED.items():
        assert type_hash(typename, "jazzy") == f"RIHS01_{digest}", typename


@pytest.mark.parametrize("typename", known_types("humble"))
def test_humble_has_no_type_hashes(typename: str) -> None:
    assert type_hash(typename, "humble") == "TypeHashNotSupported"


def test_dds_names() -> None:
    assert dds_name("geometry_msgs/msg/Twist") == "geometry_msgs::msg::dds_::Twist_"
    assert dds_name("tf2_msgs/msg/TFMessage") == "tf2_msgs::msg::dds_::TFMessage_"
    with pytest.raises(AlicaError, match="pkg/msg/Type"):
        dds_name("Twist")


@pytest.mark.parametrize(("distro", "typename"), CASES)
def test_schema_text_parses_back_with_rosbags(distro: str, typename: str) -> None:
    text = schema_text(typename, distro)
    assert text.startswith(lookup(typename, distro).text)
    parsed = get_types_from_msg(text, typename)
    assert typename in parsed
    for name, definition in parsed.items():
        constants, fields = STORES[distro].fielddefs[name]
        assert [tuple(c) for c in definition[0]] == [tuple(c) for c in constants], name
        assert [tuple(f) for f in definition[1]] == [tuple(f) for f in fields], name


def test_schema_text_lists_every_nested_type_once_depth_first() -> None:
    text = schema_text("nav_msgs/msg/Odometry")
    sections = [line[5:] for line in text.splitlines() if line.startswith("MSG: ")]
    assert sections == [
        "std_msgs/Header",
        "builtin_interfaces/Time",
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion",
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist",
        "geometry_msgs/Vector3",
    ]
    assert ("=" * 80 + "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\n") in text
    assert schema_text("std_msgs/msg/String") == "string data\n"


def test_the_parser_reads_bounds_arrays_constants_defaults_and_comments() -> None:
    text = (
        "# a comment line\n"
        "uint8 ADD=0  # trailing comment\n"
        'string NAME="a # b"\n'
        "float32 SCALE=0.5\n"
        "string<=10 short\n"
        "int32[4] fixed\n"
        "float64[<=3] bounded\n"
        "string<=5[<=2] names\n"
        "Point[] points\n"
        "geometry_msgs/Vector3 v\n"
        "bool flag true\n"
        "int16 level -3  # default\n"
    )
    msg = parse_msg("test_msgs/msg/Thing", text)
    assert [(c.name, c.base, c.value) for c in msg.constants] == [
        ("ADD", "uint8", 0),
        ("NAME", "string", "a # b"),
        ("SCALE", "float32", 0.5),
    ]
    fields = {f.name: f for f in msg.fields}
    assert fields["short"].type == FieldType("string", "single", 0, 10)
    assert fields["fixed"].type == FieldType("int32", "array", 4)
    assert fields["bounded"].type == FieldType("float64", "bounded", 3)
    assert fields["names"].type == FieldType("string", "bounded", 2, 5)
    assert fields["points"].type == FieldType("test_msgs/msg/Point", "sequence")
    assert fields["v"].type == FieldType("geometry_msgs/msg/Vector3")
    assert (fields["flag"].default, fields["level"].default) == (True, -3)
    assert lookup("geometry_msgs/msg/Quaternion").fields[3].default == 1.0
    # rosbags reads the same definition the same way
    reference = get_types_from_msg(text.replace('string NAME="a # b"\n', ""), "test_msgs/msg/Thing")
    ours = [(f.name, _rosbags_fielddef(f.type)) for f in msg.fields]
    assert ours == [tuple(f) for f in reference["test_msgs/msg/Thing"][1]]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("float64", "expected 'type name'"),
        ("float64[0] x", "size > 0"),
        ("int32<=3 x", "only strings"),
        ("int32 X=abc", "not a int32"),
        ("float64 1x", "not a field name"),
        ("int32[x] y", "cannot read the type"),
    ],
)
def test_the_parser_rejects_bad_lines(text: str, match: str) -> None:
    with pytest.raises(AlicaError, match=match):
        parse_msg("test_msgs/msg/Bad", text)


def test_unknown_types_and_distros_name_the_known_ones() -> None:
    with pytest.raises(AlicaError, match="known types are .*geometry_msgs/msg/Twist"):
        type_hash("geometry_msgs/msg/Twits")
    with pytest.raises(AlicaError, match="humble, jazzy"):
        schema_text("geometry_msgs/msg/Twist", "iron")
    with pytest.raises(AlicaError, match="humble, jazzy"):
        known_types("rolling")
