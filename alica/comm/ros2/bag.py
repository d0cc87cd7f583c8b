"""A rosbag2 folder writer: ``metadata.yaml`` plus one MCAP file.

The MCAP is written as rosbag2's MCAP storage plugin writes it (profile
``ros2``, schema encoding ``ros2msg``, message encoding ``cdr``, channel
metadata ``offered_qos_profiles``), so ``ros2 bag play``, Foxglove and rviz2
open it. Payloads arrive already serialized as CDR; this module does not
encode messages. Timestamps need not be ordered, as in rosbag2: the start time
is the smallest and the duration spans to the largest.
"""

from __future__ import annotations

from pathlib import Path
from types import TracebackType
from typing import IO, Self

import yaml
from mcap.writer import Writer

from alica.errors import AlicaError

_VERSIONS: dict[str, int] = {"humble": 5, "jazzy": 8}
_INFINITE = {"sec": 9223372036, "nsec": 854775807}


def _qos_yaml(*, latched: bool, reliable: bool, depth: int) -> str:
    """The offered QoS profile list as the YAML string rosbag2 stores."""
    profile = {
        "history": 1,  # keep last
        "depth": depth,
        "reliability": 1 if reliable else 2,
        "durability": 1 if latched else 2,  # transient local / volatile
        "deadline": dict(_INFINITE),
        "lifespan": dict(_INFINITE),
        "liveliness": 1,  # automatic
        "liveliness_lease_duration": dict(_INFINITE),
        "avoid_ros_namespace_conventions": False,
    }
    return yaml.safe_dump([profile], sort_keys=False).strip()


def check_bag_folder(folder: Path) -> None:
    """Refuse a bag folder that exists and is not empty (a recording never mixes with other files).

    Raises:
        AlicaError: it exists and is not an empty folder.
    """
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise AlicaError(f"bag folder {folder} exists and is not empty: choose a new folder or remove this one")


class BagWriter:
    """Write one rosbag2 folder; use as a context manager.

    Args:
        folder: the bag folder; it must be missing or empty.
        distro: ``humble`` (metadata version 5) or ``jazzy`` (version 8).
        compression: only ``None`` is supported.

    Raises:
        AlicaError: the folder exists and is not empty, or the distro is unknown.
    """

    def __init__(self, folder: str | Path, *, distro: str = "jazzy", compression: None = None) -> None:
        self.folder = Path(folder)
        if distro not in _VERSIONS:
            raise AlicaError(f"unknown ROS 2 distro {distro!r}: choose one of {sorted(_VERSIONS)}")
        check_bag_folder(self.folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.distro = distro
        self._name = f"{self.folder.name}_0.mcap"
        self._file: IO[bytes] | None = (self.folder / self._name).open("wb")
        self._writer = Writer(self._file)
        self._writer.start(profile="ros2", library="alica")
        self._topics: dict[str, tuple[int, str, str]] = {}
        self._counts: dict[str, int] = {}
        self._first: int | None = None
        self._last: int | None = None
        self._closed = False

    def add_topic(
        self,
        name: str,
        typename: str,
        schema: str,
        *,
        latched: bool = False,
        reliable: bool = True,
        depth: int = 10,
    ) -> None:
        """Register a topic with its ROS 2 type, ``ros2msg`` schema and QoS.

        Raises:
            AlicaError: the bag is closed or the topic is already registered.
        """
        self._check_open()
        if name in self._topics:
            raise AlicaError(f"topic {name!r} is already in bag {self.folder}")
        qos = _qos_yaml(latched=latched, reliable=reliable, depth=depth)
        schema_id = self._writer.register_schema(name=typename, encoding="ros2msg", data=schema.encode())
        metadata = {"offered_qos_profiles": qos}
        if self.distro != "humble":
            metadata["topic_type_hash"] = ""
        channel = self._writer.register_channel(
            topic=name, message_encoding="cdr", schema_id=schema_id, metadata=metadata
        )
        self._topics[name] = (channel, typename, qos)
        self._counts[name] = 0

    def write(self, topic: str, timestamp_ns: int, data: bytes) -> None:
        """Append one CDR message received at ``timestamp_ns``.

        Raises:
            AlicaError: the bag is closed or the topic was never added.
        """
        self._check_open()
        if topic not in self._topics:
            raise AlicaError(f"topic {topic!r} is not in bag {self.folder}: call add_topic first")
        channel = self._topics[topic][0]
        self._writer.add_message(
            channel_id=channel,
            log_time=timestamp_ns,
            publish_time=timestamp_ns,
            data=data,
            sequence=self._counts[topic],
        )
        self._counts[topic] += 1
        self._first = timestamp_ns if self._first is None else min(self._first, timestamp_ns)
        self._last = timestamp_ns if self._last is None else max(self._last, timestamp_ns)

    def close(self) -> None:
        """Finish the MCAP and write ``metadata.yaml``; a second call does nothing."""
        if self._closed:
            return
        self._closed = True
        self._writer.finish()
        if self._file is not None:
            self._file.close()
            self._file = None
        (self.folder / "metadata.yaml").write_text(yaml.safe_dump(self._metadata(), sort_keys=False))

    def _metadata(self) -> dict[str, object]:
        start = self._first or 0
        duration = (self._last or 0) - start
        total = sum(self._counts.values())
        topics = []
        for name, (_, typename, qos) in self._topics.items():
            meta: dict[str, object] = {
                "name": name,
                "type": typename,
                "serialization_format": "cdr",
                "offered_qos_profiles": qos,
            }
            if self.distro != "humble":
                meta["type_description_hash"] = ""
            topics.append({"topic_metadata": meta, "message_count": self._counts[name]})
        info: dict[str, object] = {
            "version": _VERSIONS[self.distro],
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": total,
            "topics_with_message_count": topics,
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self._name],
            "files": [
                {
                    "path": self._name,
                    "starting_time": {"nanoseconds_since_epoch": start},
                    "duration": {"nanoseconds": duration},
                    "message_count": total,
                }
            ],
        }
        if self.distro != "humble":
            info["custom_data"] = None
            info["ros_distro"] = self.distro
        return {"rosbag2_bagfile_information": info}

    def _check_open(self) -> None:
        if self._closed:
            raise AlicaError(f"bag {self.folder} is closed: open a new BagWriter")

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
