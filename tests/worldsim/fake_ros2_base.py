"""A fake ROS 2 mobile base for the driver's tests: an rmw_zenoh node that obeys ``cmd_vel`` and publishes ``odom`` and ``scan``.

The base is a kinematic unicycle on a small known map (:class:`~alica.worldsim.unicycle.UnicycleWorld`
without lidar noise). It is stepped by the test, in simulated time: :meth:`FakeBase.step` drives the
last ``cmd_vel`` (the base stops when none came for :data:`WATCHDOG` seconds of its time) and
:meth:`FakeBase.publish` sends one Odometry and one LaserScan, stamped with that time. The scan
follows a real scanner's convention, not the driver's: 360 beams from ``-pi`` counter-clockwise,
``range_max`` 6 m, no return as ``inf``. :meth:`FakeBase.heartbeat` publishes on its own thread
until stopped, for the driver's start, which waits for the first odometry.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import zenoh

from alica.comm.ros2 import dds_name, decode, encode, type_hash
from alica.comm.ros2.rmw import DEFAULT, Ros2Node, open_session
from alica.worldsim.unicycle import OccupancyMap, UnicycleWorld

TWIST = "geometry_msgs/msg/Twist"
ODOMETRY = "nav_msgs/msg/Odometry"
LASER_SCAN = "sensor_msgs/msg/LaserScan"
WATCHDOG = 0.5
"""Seconds of the base's time after which it stops without a new ``cmd_vel``."""
BEAMS = 360
RANGE_MAX = 6.0

#: 6 m x 5 m of 0.25 m cells, walled, a block in the middle: the map of the fake base and of the driver.
ROOM = (
    ["#" * 24]
    + ["#" + "." * 22 + "#"] * 7
    + ["#" + "." * 9 + "#" * 4 + "." * 9 + "#"] * 4
    + ["#" + "." * 22 + "#"] * 7
    + ["#" * 24]
)


class FakeBase:
    """A fake ROS 2 base: a zenoh peer listening on ``endpoint`` (where the driver's ``router`` points).

    Args:
        endpoint: the loopback endpoint to listen on.
        namespace: the base's namespace (the driver's default is ``/<name>``).
        pose: where the base starts on :data:`ROOM`.
        distro: the type-hash form.
    """

    def __init__(
        self,
        endpoint: str,
        namespace: str = "/r1",
        pose: tuple[float, float, float] = (1.0, 1.0, 0.0),
        *,
        distro: str = "jazzy",
        domain: int = 0,
    ) -> None:
        self.endpoint = endpoint
        self.session: zenoh.Session = open_session(None, listen=[endpoint])
        self.distro = distro
        self.node = Ros2Node(self.session, "fake_base", namespace, domain=domain)
        self.world = UnicycleWorld(OccupancyMap.from_rows(ROOM, 0.25), lidar_noise=0.0)
        self.robot = self.world.add_robot("scout", "base", pose)
        self.time = 0.0
        self.twists: list[tuple[float, float]] = []
        self.last_sequence = 0
        """The attachment's sequence number of the latest Twist (the driver's count of Twists sent)."""
        self.command = (0.0, 0.0)
        self._seen = 0
        self._lock = threading.Lock()
        self.published = 0
        self._last_command = -math.inf
        self._changed = threading.Condition()
        self._hashes = {t: type_hash(t, distro) for t in (TWIST, ODOMETRY, LASER_SCAN)}
        self.odom = self.node.publisher("odom", dds_name(ODOMETRY), self._hashes[ODOMETRY], DEFAULT)
        self.scan = self.node.publisher("scan", dds_name(LASER_SCAN), self._hashes[LASER_SCAN], DEFAULT)
        self.node.subscribe("cmd_vel", dds_name(TWIST), self._hashes[TWIST], self._on_twist, DEFAULT)

    def _on_twist(self, payload: bytes, meta: Any) -> None:
        message = decode(TWIST, payload, self.distro)
        with self._changed:
            self.twists.append((float(message["linear"]["x"]), float(message["angular"]["z"])))
            if meta is not None:
                self.last_sequence = max(self.last_sequence, meta[0])
            self._changed.notify_all()

    def wait(self, condition: Callable[[], bool], timeout: float = 5.0) -> bool:
        """Whether ``condition`` holds within ``timeout`` wall seconds, looked at again on each Twist."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while not condition():
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._changed.wait(remaining)
        return True

    def step(self, seconds: float) -> None:
        """Drive the last Twist for ``seconds`` of the base's time (stopped after :data:`WATCHDOG` without one)."""
        with self._changed:
            count = len(self.twists)
            command = self.twists[-1] if self.twists else (0.0, 0.0)
        if count != self._seen:
            self._seen = count
            self._last_command = self.time
        if self.time - self._last_command > WATCHDOG:
            command = (0.0, 0.0)
        self.command = command
        self.robot.drive(*command)
        self.world.step(seconds)
        self.time += seconds

    def odometry(self) -> dict[str, Any]:
        """The Odometry message of the base now."""
        x, y, yaw = self.robot.pose
        v, w = self.command
        sec = int(self.time)
        return {
            "header": {"stamp": {"sec": sec, "nanosec": int((self.time - sec) * 1e9)}, "frame_id": "odom"},
            "child_frame_id": "base_link",
            "pose": {
                "pose": {
                    "position": {"x": x, "y": y, "z": 0.0},
                    "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)},
                }
            },
            "twist": {"twist": {"linear": {"x": v}, "angular": {"z": w}}},
        }

    def laser_scan(self) -> dict[str, Any]:
        """The LaserScan of the base now: :data:`BEAMS` beams from ``-pi``, ``inf`` where nothing is in range."""
        ranges = self.robot.lidar(BEAMS, RANGE_MAX + 1.0)  # beam j at j degrees from the heading
        ranges = np.roll(ranges, -BEAMS // 2)  # beam i at -180 + i degrees
        ranges = np.where(ranges > RANGE_MAX, np.inf, ranges).astype(np.float32)
        sec = int(self.time)
        return {
            "header": {"stamp": {"sec": sec, "nanosec": int((self.time - sec) * 1e9)}, "frame_id": "base_link"},
            "angle_min": -math.pi,
            "angle_max": math.pi - 2 * math.pi / BEAMS,
            "angle_increment": 2 * math.pi / BEAMS,
            "range_min": 0.05,
            "range_max": RANGE_MAX,
            "ranges": ranges,
        }

    def publish(self) -> int:
        """Send one Odometry and one LaserScan; returns how many of each were sent so far."""
        with self._lock:
            self.odom.put(encode(ODOMETRY, self.odometry(), self.distro))
            self.scan.put(encode(LASER_SCAN, self.laser_scan(), self.distro))
            self.published += 1
            return self.published

    def put_raw(self, topic: str, payload: bytes) -> None:
        """Send ``payload`` as it is on ``odom`` or ``scan`` (for malformed messages)."""
        (self.odom if topic == "odom" else self.scan).put(payload)

    @contextmanager
    def heartbeat(self, period: float = 0.02) -> Iterator[None]:
        """Publish every ``period`` wall seconds on a thread of its own while the block runs."""
        done = threading.Event()

        def beat() -> None:
            while not done.is_set():
                self.publish()
                done.wait(period)

        thread = threading.Thread(target=beat, name="fake-base-heartbeat", daemon=True)
        thread.start()
        try:
            yield
        finally:
            done.set()
            thread.join(5.0)

    def close(self) -> None:
        self.node.close()
        close: Callable[[], object] = self.session.close  # zenoh's stubs leave close() untyped
        close()
