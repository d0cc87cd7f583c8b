"""The ROS 2 message definitions alica speaks, as ``.msg`` text per distribution.

Each entry maps a full type name (``pkg/msg/Type``) to its ``.msg`` text, as
the ROS 2 packages define it for Humble and Jazzy, without comments. Nested
types may be named without their package when they live in the same package,
as in ROS 2. Humble and Jazzy differ here only in ``visualization_msgs/Marker``,
whose ``ARROW_STRIP`` constant is new in Jazzy (both carry the texture and mesh
fields, added before Humble's release). :mod:`alica.comm.ros2.types` parses them.
"""

from __future__ import annotations

from alica.errors import AlicaError

DISTROS: tuple[str, ...] = ("humble", "jazzy")

_STAMP = "int32 sec\nuint32 nanosec\n"
_XYZ64 = "float64 x\nfloat64 y\nfloat64 z\n"

_COMMON: dict[str, str] = {
    "builtin_interfaces/msg/Time": _STAMP,
    "builtin_interfaces/msg/Duration": _STAMP,
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "std_msgs/msg/String": "string data\n",
    "rosgraph_msgs/msg/Clock": "builtin_interfaces/Time clock\n",
    "std_msgs/msg/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    "geometry_msgs/msg/Point": _XYZ64,
    "geometry_msgs/msg/Point32": "float32 x\nfloat32 y\nfloat32 z\n",
    "geometry_msgs/msg/Vector3": _XYZ64,
    "geometry_msgs/msg/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    "geometry_msgs/msg/Pose": "Point position\nQuaternion orientation\n",
    "geometry_msgs/msg/PoseStamped": "std_msgs/Header header\nPose pose\n",
    "geometry_msgs/msg/Twist": "Vector3 linear\nVector3 angular\n",
    "geometry_msgs/msg/TwistStamped": "std_msgs/Header header\nTwist twist\n",
    "geometry_msgs/msg/Transform": "Vector3 translation\nQuaternion rotation\n",
    "geometry_msgs/msg/TransformStamped": "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
    "geometry_msgs/msg/PoseWithCovariance": "Pose pose\nfloat64[36] covariance\n",
    "geometry_msgs/msg/TwistWithCovariance": "Twist twist\nfloat64[36] covariance\n",
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
    "nav_msgs/msg/Odometry": (
        "std_msgs/Header header\n"
        "string child_frame_id\n"
        "geometry_msgs/PoseWithCovariance pose\n"
        "geometry_msgs/TwistWithCovariance twist\n"
    ),
    "nav_msgs/msg/MapMetaData": (
        "builtin_interfaces/Time map_load_time\n"
        "float32 resolution\n"
        "uint32 width\n"
        "uint32 height\n"
        "geometry_msgs/Pose origin\n"
    ),
    "nav_msgs/msg/OccupancyGrid": "std_msgs/Header header\nMapMetaData info\nint8[] data\n",
    "sensor_msgs/msg/LaserScan": (
        "std_msgs/Header header\n"
        "float32 angle_min\n"
        "float32 angle_max\n"
        "float32 angle_increment\n"
        "float32 time_increment\n"
        "float32 scan_time\n"
        "float32 range_min\n"
        "float32 range_max\n"
        "float32[] ranges\n"
        "float32[] intensities\n"
    ),
    "sensor_msgs/msg/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n",
    "visualization_msgs/msg/MarkerArray": "Marker[] markers\n",
    "visualization_msgs/msg/UVCoordinate": "float32 u\nfloat32 v\n",
    "visualization_msgs/msg/MeshFile": "string filename\nuint8[] data\n",
    "diagnostic_msgs/msg/DiagnosticArray": "std_msgs/Header header\nDiagnosticStatus[] status\n",
    "diagnostic_msgs/msg/DiagnosticStatus": (
        "byte OK=0\n"
        "byte WARN=1\n"
        "byte ERROR=2\n"
        "byte STALE=3\n"
        "byte level\n"
        "string name\n"
        "string message\n"
        "string hardware_id\n"
        "KeyValue[] values\n"
    ),
    "diagnostic_msgs/msg/KeyValue": "string key\nstring value\n",
}

_MARKER_SHAPES = (
    "int32 ARROW=0\n"
    "int32 CUBE=1\n"
    "int32 SPHERE=2\n"
    "int32 CYLINDER=3\n"
    "int32 LINE_STRIP=4\n"
    "int32 LINE_LIST=5\n"
    "int32 CUBE_LIST=6\n"
    "int32 SPHERE_LIST=7\n"
    "int32 POINTS=8\n"
    "int32 TEXT_VIEW_FACING=9\n"
    "int32 MESH_RESOURCE=10\n"
    "int32 TRIANGLE_LIST=11\n"
)

_MARKER_BODY = (
    "int32 ADD=0\n"
    "int32 MODIFY=0\n"
    "int32 DELETE=2\n"
    "int32 DELETEALL=3\n"
    "std_msgs/Header header\n"
    "string ns\n"
    "int32 id\n"
    "int32 type\n"
    "int32 action\n"
    "geometry_msgs/Pose pose\n"
    "geometry_msgs/Vector3 scale\n"
    "std_msgs/ColorRGBA color\n"
    "builtin_interfaces/Duration lifetime\n"
    "bool frame_locked\n"
    "geometry_msgs/Point[] points\n"
    "std_msgs/ColorRGBA[] colors\n"
    "string texture_resource\n"
    "sensor_msgs/CompressedImage texture\n"
    "UVCoordinate[] uv_coordinates\n"
    "string text\n"
    "string mesh_resource\n"
    "MeshFile mesh_file\n"
    "bool mesh_use_embedded_materials\n"
)

_BY_DISTRO: dict[str, dict[str, str]] = {
    "humble": {"visualization_msgs/msg/Marker": _MARKER_SHAPES + _MARKER_BODY},
    "jazzy": {"visualization_msgs/msg/Marker": _MARKER_SHAPES + "int32 ARROW_STRIP=12\n" + _MARKER_BODY},
}


def check_distro(distro: str) -> None:
    """Check that ``distro`` is one this module defines messages for.

    Raises:
        AlicaError: the distro is unknown; the message names the known ones.
    """
    if distro not in _BY_DISTRO:
        raise AlicaError(f"unknown ROS 2 distro {distro!r}: choose one of {', '.join(DISTROS)}")


def definitions(distro: str) -> dict[str, str]:
    """The ``.msg`` text of every defined type of ``distro``, keyed by full type name.

    Raises:
        AlicaError: the distro is unknown.
    """
    check_distro(distro)
    return {**_COMMON, **_BY_DISTRO[distro]}
