"""ROS 2 without a ROS installation: message definitions, the CDR codec and type identity.

The package re-exports the codec (:mod:`alica.comm.ros2.cdr`) and the type
functions (:mod:`alica.comm.ros2.types`). The zenoh transport
(:mod:`alica.comm.ros2.rmw`) and the rosbag2 writer (:mod:`alica.comm.ros2.bag`)
are imported from their modules, since they need zenoh and mcap.
"""

from __future__ import annotations

from alica.comm.ros2.cdr import decode, encode
from alica.comm.ros2.types import dds_name, known_types, schema_text, type_hash

__all__ = ["dds_name", "decode", "encode", "known_types", "schema_text", "type_hash"]
