"""A robot driver for ROS 2 mobile bases: ``cmd_vel``, ``odom`` and ``scan`` over rmw_zenoh, without a ROS installation.

:func:`make_robot` is the robot factory of ``--robot ros2`` (the entry point of the
group ``alica.robots``). It joins the ROS 2 graph as the rmw_zenoh node
``alica_<name>`` (:mod:`alica.comm.ros2.rmw`, messages in CDR by
:mod:`alica.comm.ros2`) and offers the robot interface
(:mod:`alica.worldsim.interface`) on what it hears:

* **Drive.** ``drive(v, w)`` publishes one ``geometry_msgs/msg/Twist`` on
  ``cmd_vel`` (``linear.x = v``, ``angular.z = w``, clamped to the kind's speeds),
  ``stop()`` a zero twist. There is no timer: a command is sent when a skill gives
  one, and stopping a base that hears nothing is its own watchdog's business.
* **Pose.** ``nav_msgs/msg/Odometry`` on ``odom``: ``pose`` is the odometry's
  ``(x, y, yaw)`` in the odometry frame; ``estimate`` is that pose through a
  map-from-odometry correction which :meth:`Ros2BaseRobot.set_estimate` sets (a
  localiser's result), so that later odometry moves the estimate on from there.
* **Lidar.** ``sensor_msgs/msg/LaserScan`` on ``scan``: :meth:`Ros2BaseRobot.lidar`
  resamples the latest scan to the rays of :meth:`Ros2BaseRobot.lidar_angles`
  (the unicycle's convention: ``n`` rays counter-clockwise over the full circle
  from the heading on). Each ray takes the nearest beam within one beam
  spacing and the shortest beam inside its own angular cell; a NaN, an infinity,
  a range outside ``[range_min, range_max]`` or an angle the scanner does not
  cover reads ``max_range``. The laser is taken to sit at the base's centre,
  aligned with it.
* **Health.** ``crashed`` is true while no odometry has arrived for ``timeout``
  seconds (the base, or the link to it, is down). A payload that does not decode,
  or holds non-finite numbers or absurd sizes, is counted in ``dropped`` and
  ignored.
* **Time.** :meth:`Ros2BaseWorld.now` is the wall time in seconds since the
  driver started (monotonic), not the odometry's stamp: a base that stops
  publishing must not stop the executive's clock. The world has no ``step``: it is
  hardware, and the run goes on the wall clock.
* **No camera, no arm**: the spec's capabilities are only ``base`` and
  ``lidar2d``; ``objects`` is empty and ``blocks_facts()`` too, ``blocker()``
  ``None``. ``bounds`` and ``ground_truth_obstacles()`` come from the ``map``
  option (the unicycle's text format) when given, else the ``bounds`` option and
  no obstacles.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.comm.ros2 import dds_name, decode, encode, type_hash
from alica.comm.ros2.rmw import DEFAULT, ROUTER, SENSOR, Ros2Node, fully_qualified, open_session
from alica.errors import AlicaError
from alica.worldsim.camera_image import CameraImage
from alica.worldsim.errors import WorldError
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing
from alica.worldsim.robot_specs import ROBOT_KINDS, RobotSpec
from alica.worldsim.unicycle import OccupancyMap, option_numbers

if TYPE_CHECKING:
    import zenoh

__all__ = ["MAX_BEAMS", "OPTIONS", "Ros2BaseRobot", "Ros2BaseWorld", "Topics", "make_robot"]

log = logging.getLogger(__name__)

TWIST = "geometry_msgs/msg/Twist"
ODOMETRY = "nav_msgs/msg/Odometry"
LASER_SCAN = "sensor_msgs/msg/LaserScan"
MAX_BEAMS = 100_000
"""The most beams a scan may have; a larger scan is refused (counted in ``dropped``)."""
DEFAULT_BOUNDS = (-20.0, -20.0, 20.0, 20.0)
"""The field without a ``map`` or ``bounds`` option: 40 m x 40 m around the odometry's origin."""

#: The options of :func:`make_robot`.
OPTIONS = frozenset(
    {
        "router",
        "domain",
        "distro",
        "namespace",
        "cmd_vel",
        "odom",
        "scan",
        "kind",
        "lidar_range",
        "map",
        "resolution",
        "origin",
        "bounds",
        "timeout",
        "lidar_noise",
        "wait",
    }
)


@dataclasses.dataclass(frozen=True, slots=True)
class Topics:
    """The topic names the driver uses, relative to the node's namespace unless they start with ``/``."""

    cmd_vel: str = "cmd_vel"
    odom: str = "odom"
    scan: str = "scan"


def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """The yaw (rotation about ``z``) of a quaternion ``(x, y, z, w)``."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


class _Scan:
    """One accepted LaserScan: the beams' angles in the laser frame and their ranges (``inf`` for no return)."""

    __slots__ = ("angles", "increment", "ranges")

    def __init__(self, angles: np.ndarray, ranges: np.ndarray, increment: float) -> None:
        self.angles = angles
        self.ranges = ranges
        self.increment = increment


class Ros2BaseRobot:
    """The robot of a :class:`Ros2BaseWorld` (see the module docstring); made by the world.

    ``bumped`` stays false: a base's bumper is not read.
    """

    def __init__(self, world: Ros2BaseWorld, name: str, spec: RobotSpec, lidar_noise: float) -> None:
        self._world = world
        self._name = name
        self._spec = spec
        self._lidar_noise = float(lidar_noise)
        self._correction = (0.0, 0.0, 0.0)
        self.bumped = False

    @property
    def name(self) -> str:
        return self._name

    @property
    def spec(self) -> RobotSpec:
        return self._spec

    @property
    def arm(self) -> None:
        return None

    @property
    def pose(self) -> tuple[float, float, float]:
        """The latest odometry ``(x, y, yaw)`` in the odometry frame (zeros before the first)."""
        return self._world.odometry_pose()

    @property
    def estimate(self) -> tuple[float, float, float]:
        """The odometry through the map-from-odometry correction that :meth:`set_estimate` keeps."""
        return _compose(self._correction, self.pose)

    def set_estimate(self, pose: tuple[float, float, float]) -> None:
        """Make the estimate ``pose`` now; later odometry moves it on relative to that."""
        target = (float(pose[0]), float(pose[1]), float(pose[2]))
        self._correction = _compose(target, _inverse(self.pose))

    @property
    def lidar_noise(self) -> float:
        return self._lidar_noise

    def lidar_angles(self, n_rays: int) -> np.ndarray:
        return np.linspace(0.0, 2 * math.pi, int(n_rays), endpoint=False)

    def lidar(self, n_rays: int, max_range: float | None = None) -> np.ndarray:
        """The latest scan resampled to ``n_rays`` rays (see the module docstring); all ``max_range`` before the first."""
        reach = self._spec.lidar_range if max_range is None else float(max_range)
        scan = self._world.latest_scan()
        targets = self.lidar_angles(n_rays)
        if scan is None or len(targets) == 0:
            return np.full(len(targets), reach)
        step = 2 * math.pi / len(targets)
        relative = np.mod(scan.angles, 2 * math.pi)  # each beam's angle counter-clockwise from the heading
        out = np.full(len(targets), np.inf)
        # nearest beam within one beam spacing of each ray (rays finer than the beams)
        order = np.argsort(relative)
        sorted_angles = relative[order]
        spot = np.searchsorted(sorted_angles, targets) % len(sorted_angles)
        before = (spot - 1) % len(sorted_angles)
        gaps = [np.abs(np.mod(targets - sorted_angles[c] + math.pi, 2 * math.pi) - math.pi) for c in (spot, before)]
        nearest = np.where(gaps[0] <= gaps[1], order[spot], order[before])
        near = np.minimum(gaps[0], gaps[1]) <= scan.increment * 1.0001
        out = np.where(near, scan.ranges[nearest], out)
        # the shortest beam inside each ray's cell (beams finer than the rays)
        cell = np.round(relative / step).astype(int) % len(targets)
        np.minimum.at(out, cell, scan.ranges)
        return np.where(np.isfinite(out), np.clip(out, 0.0, reach), reach)

    def camera_pose(
        self, pose: tuple[float, float, float] | None = None, pan: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray]:
        raise WorldError(f"robot '{self._name}' is a ROS 2 base driven without a camera")

    def camera(
        self,
        *,
        width: int = 320,
        height: int = 240,
        fov: float | None = None,
        far: float | None = None,
        pan: float = 0.0,
        believed: bool = False,
        window: tuple[int, int, int, int] | None = None,
    ) -> CameraImage:
        raise WorldError(f"robot '{self._name}' is a ROS 2 base driven without a camera")

    @property
    def crashed(self) -> bool:
        """Whether no odometry has arrived for the world's ``timeout`` seconds."""
        return self._world.odometry_age() > self._world.timeout

    def drive(self, v: float, w: float) -> None:
        """Publish one Twist of ``v`` m/s and ``w`` rad/s, clamped to the kind's speeds."""
        spec = self._spec
        self._world.send_twist(
            max(-spec.max_speed, min(spec.max_speed, float(v))),
            max(-spec.max_yaw_rate, min(spec.max_yaw_rate, float(w))),
        )

    def stop(self) -> None:
        """Publish a zero Twist."""
        self._world.send_twist(0.0, 0.0)


class Ros2BaseWorld:
    """One ROS 2 mobile base as a :class:`~alica.worldsim.interface.RobotWorld` (hardware: no ``step``).

    Args:
        session: the zenoh session (from :func:`~alica.comm.ros2.rmw.open_session`).
        name: the robot's name; the node is ``alica_<name>``.
        spec: the robot's kind (its speeds clamp the commands, its lidar range is a ray's reach).
        namespace: the node's namespace (``/<name>`` in :func:`make_robot`).
        domain: the ROS domain id.
        distro: ``jazzy`` or ``humble`` (the type-hash form and the message definitions).
        topics: the topic names.
        occupancy: the known map, or ``None`` (then ``bounds`` and no obstacles).
        bounds: the field without a map.
        timeout: seconds without odometry after which the robot counts as crashed.
        lidar_noise: the range noise the skills assume of the scanner (m).
        clock: the clock of :meth:`now` and of the odometry's age (monotonic wall time when omitted).
        owns_session: whether :meth:`close` closes the session too.

    Raises:
        ValueError: a bad node name, namespace, topic or domain.
        AlicaError: an unknown distro.
    """

    def __init__(
        self,
        session: zenoh.Session,
        name: str,
        spec: RobotSpec,
        *,
        namespace: str = "",
        domain: int = 0,
        distro: str = "jazzy",
        topics: Topics | None = None,
        occupancy: OccupancyMap | None = None,
        bounds: tuple[float, float, float, float] = DEFAULT_BOUNDS,
        timeout: float = 1.0,
        lidar_noise: float = 0.02,
        clock: Callable[[], float] | None = None,
        owns_session: bool = False,
    ) -> None:
        self.topics = topics or Topics()
        self.distro = distro
        self.timeout = float(timeout)
        self.map = occupancy
        self._bounds = occupancy.bounds if occupancy is not None else bounds
        self._clock = clock or time.monotonic
        self._start = self._clock()
        self._session = session
        self._owns_session = owns_session
        self._lock = threading.RLock()
        self._arrived = threading.Condition(self._lock)
        self._odometry: tuple[float, float, float] | None = None
        self._odometry_time = -math.inf
        self._scan: _Scan | None = None
        self._rejected = 0
        self.odometry_count = 0
        """Odometry messages accepted so far."""
        self.scan_count = 0
        """Scans accepted so far."""
        self.sent = 0
        """Twists published so far."""
        self.odometry_stamp = -math.inf
        """The header stamp (s) of the latest accepted odometry."""
        self.scan_stamp = -math.inf
        """The header stamp (s) of the latest accepted scan."""
        hashes = {t: type_hash(t, distro) for t in (TWIST, ODOMETRY, LASER_SCAN)}
        self.node = Ros2Node(session, f"alica_{name}", namespace, domain=domain)
        try:
            self.cmd_vel_topic = fully_qualified(self.node.namespace, self.topics.cmd_vel)
            self.odom_topic = fully_qualified(self.node.namespace, self.topics.odom)
            self.scan_topic = fully_qualified(self.node.namespace, self.topics.scan)
            self._twist = self.node.publisher(self.topics.cmd_vel, dds_name(TWIST), hashes[TWIST], DEFAULT)
            self.node.subscribe(self.topics.odom, dds_name(ODOMETRY), hashes[ODOMETRY], self._on_odometry, DEFAULT)
            self.node.subscribe(self.topics.scan, dds_name(LASER_SCAN), hashes[LASER_SCAN], self._on_scan, SENSOR)
        except BaseException:
            self.node.close()
            raise
        self._robot = Ros2BaseRobot(self, name, spec, lidar_noise)
        self._closed = False

    # --- the robot interface -------------------------------------------------------------------

    @property
    def robots(self) -> Mapping[str, Ros2BaseRobot]:
        return {self._robot.name: self._robot}

    @property
    def objects(self) -> Mapping[str, WorldThing]:
        return {}

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        return self._bounds

    @property
    def seed(self) -> int:
        return 0

    def now(self) -> float:
        """Wall seconds since the driver started."""
        return self._clock() - self._start

    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        """The ``map`` option's occupied cells as boxes; none without a map."""
        return self.map.boxes() if self.map is not None else []

    def blocker(self, x: float, y: float, radius: float, ignore: str | None = None) -> str | None:
        """Always ``None``: the driver knows of no other robot or object."""
        return None

    def blocks_facts(self) -> set[tuple[str, ...]]:
        return set()

    # --- what the node hears and says ----------------------------------------------------------

    @property
    def dropped(self) -> int:
        """Samples ignored: malformed attachments (the node's count) and payloads that failed the checks."""
        with self._lock:
            return self._rejected + self.node.dropped

    def odometry_pose(self) -> tuple[float, float, float]:
        """The latest odometry ``(x, y, yaw)``, zeros before the first."""
        with self._lock:
            return self._odometry or (0.0, 0.0, 0.0)

    def odometry_age(self) -> float:
        """Seconds since the latest odometry arrived (``inf`` before the first)."""
        with self._lock:
            return self._clock() - self._odometry_time

    def latest_scan(self) -> _Scan | None:
        with self._lock:
            return self._scan

    def wait(self, condition: Callable[[], bool], timeout: float) -> bool:
        """Whether ``condition`` holds within ``timeout`` wall seconds, looked at again as each message arrives."""
        deadline = time.monotonic() + timeout
        with self._arrived:
            while not condition():
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._arrived.wait(remaining)
        return True

    def send_twist(self, v: float, w: float) -> None:
        """Publish a Twist of ``linear.x = v`` and ``angular.z = w`` on ``cmd_vel``."""
        if self._closed:
            return
        payload = encode(TWIST, {"linear": {"x": v}, "angular": {"z": w}}, self.distro)
        self._twist.put(payload)
        with self._lock:
            self.sent += 1

    def _reject(self, topic: str, why: str) -> None:
        with self._arrived:
            self._rejected += 1
            self._arrived.notify_all()
        log.debug("driver %s ignored a message on %s: %s", self.node.name, topic, why)

    def _on_odometry(self, payload: bytes, meta: tuple[int, int, bytes] | None) -> None:
        try:
            message = decode(ODOMETRY, payload, self.distro)
            pose = message["pose"]["pose"]
            position, orientation = pose["position"], pose["orientation"]
            x, y = float(position["x"]), float(position["y"])
            q = [float(orientation[k]) for k in ("x", "y", "z", "w")]
            stamp = _stamp(message)
        except (AlicaError, KeyError, TypeError, ValueError) as exc:
            self._reject(self.odom_topic, str(exc))
            return
        norm = math.sqrt(sum(v * v for v in q))
        if not all(math.isfinite(v) for v in (x, y, *q)) or not 0.5 < norm < 1.5:
            self._reject(self.odom_topic, f"a pose that is not finite or a quaternion of norm {norm:g}")
            return
        yaw = yaw_of(*(v / norm for v in q))
        with self._arrived:
            self._odometry = (x, y, yaw)
            self._odometry_time = self._clock()
            self.odometry_count += 1
            self.odometry_stamp = stamp
            self._arrived.notify_all()

    def _on_scan(self, payload: bytes, meta: tuple[int, int, bytes] | None) -> None:
        try:
            message = decode(LASER_SCAN, payload, self.distro)
            scan = _checked_scan(message)
            stamp = _stamp(message)
        except (AlicaError, KeyError, TypeError, ValueError) as exc:
            self._reject(self.scan_topic, str(exc))
            return
        with self._arrived:
            self._scan = scan
            self.scan_count += 1
            self.scan_stamp = stamp
            self._arrived.notify_all()

    def close(self) -> None:
        """Stop the base (one zero Twist), close the node and, if it owns it, the session."""
        if self._closed:
            return
        try:
            self.send_twist(0.0, 0.0)
        except Exception:  # closing must not fail on a broken link
            log.debug("driver %s could not send the last stop", self.node.name, exc_info=True)
        self._closed = True
        self.node.close()
        if self._owns_session:
            _close_session(self._session)


def _stamp(message: Mapping[str, Any]) -> float:
    """The header stamp of a decoded message in seconds."""
    stamp = message["header"]["stamp"]
    return float(stamp["sec"]) + float(stamp["nanosec"]) * 1e-9


def _checked_scan(message: Mapping[str, Any]) -> _Scan:
    """The beams of a decoded LaserScan.

    Raises:
        ValueError: absurd sizes or angles (more than :data:`MAX_BEAMS` beams, none, a zero or non-finite
            increment, beams spanning more than a full turn).
    """
    ranges = np.asarray(message["ranges"], dtype=np.float64).reshape(-1)
    count = len(ranges)
    if not 1 <= count <= MAX_BEAMS:
        raise ValueError(f"a scan of {count} beams (1..{MAX_BEAMS} accepted)")
    angle_min, increment = float(message["angle_min"]), float(message["angle_increment"])
    low, high = float(message["range_min"]), float(message["range_max"])
    if not all(math.isfinite(v) for v in (angle_min, increment, low, high)):
        raise ValueError("a scan's angles or range limits are not finite")
    if (increment == 0.0 and count > 1) or abs(increment) * (count - 1) > 2 * math.pi + 1e-3:
        raise ValueError(f"{count} beams of {increment:g} rad do not fit in one turn")
    if not 0.0 <= low <= high:
        raise ValueError(f"range limits [{low:g}, {high:g}]")
    angles = angle_min + increment * np.arange(count)
    valid = np.isfinite(ranges) & (ranges >= low) & (ranges <= high)
    spacing = abs(increment) if increment != 0.0 else 2 * math.pi
    return _Scan(angles, np.where(valid, ranges, np.inf), spacing)


def _compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """The pose ``b`` given in frame ``a``, in ``a``'s parent frame."""
    ax, ay, ayaw = a
    bx, by, byaw = b
    c, s = math.cos(ayaw), math.sin(ayaw)
    return (ax + c * bx - s * by, ay + s * bx + c * by, _wrap(ayaw + byaw))


def _inverse(a: tuple[float, float, float]) -> tuple[float, float, float]:
    x, y, yaw = a
    c, s = math.cos(yaw), math.sin(yaw)
    return (-(c * x + s * y), s * x - c * y, _wrap(-yaw))


def make_robot(name: str, role: str, options: Mapping[str, str]) -> Ros2BaseWorld:
    """The robot factory of the plug-in ``ros2``: the ROS 2 mobile base named ``name``, reached over rmw_zenoh.

    Options (all strings, as ``--robot-option KEY=VALUE`` gives them):

    * ``router``: the zenoh endpoint of ``rmw_zenohd`` (default ``tcp/127.0.0.1:7447``);
    * ``domain``: the ROS domain id, 0..232 (default 0); ``distro``: ``jazzy`` (default) or ``humble``;
    * ``namespace``: the node's namespace (default ``/<name>``); ``cmd_vel``, ``odom``, ``scan``: the topics
      (defaults ``cmd_vel``, ``odom``, ``scan``, under the namespace unless they start with ``/``);
    * ``kind``: the robot kind whose size and speeds it takes (default: the role's, lower-cased, when it
      is a kind; else ``scout``); ``lidar_range``: a ray's reach in metres (default: the kind's);
    * ``map``, ``resolution`` (default 0.25), ``origin`` (default ``0,0``): the known map in the unicycle's
      text format, for ``bounds`` and ``ground_truth_obstacles()``; without it ``bounds``
      ``xmin,ymin,xmax,ymax`` (default ``-20,-20,20,20``) and no obstacles;
    * ``timeout``: seconds without odometry after which the robot is ``crashed`` (default 1.0);
    * ``lidar_noise``: the scanner's range noise in metres the skills assume (default 0.02);
    * ``wait``: seconds to wait for the first odometry (default 5; 0 does not wait).

    Raises:
        ValueError: an unknown option, a value that is not what the option takes, or no odometry within
            ``wait`` seconds (the message says which topic was silent and what to check).
    """
    unknown = sorted(set(options) - OPTIONS)
    if unknown:
        raise ValueError(f"the ros2 base has no option {', '.join(unknown)}; its options: {', '.join(sorted(OPTIONS))}")

    def number(key: str, default: float, low: float = -math.inf) -> float:
        text = options.get(key)
        try:
            value = default if text is None else float(text)
        except ValueError:
            raise ValueError(f"option {key}: '{text}' is not a number") from None
        if not math.isfinite(value):
            raise ValueError(f"option {key}: '{text}' is not a finite number")
        if value < low:
            raise ValueError(f"option {key}: must be >= {low:g}, got {value:g}")
        return value

    router = options.get("router", ROUTER)
    domain = number("domain", 0, 0)
    if domain != int(domain) or domain > 232:
        raise ValueError(f"option domain: a ROS domain id is a whole number within 0..232, got '{options['domain']}'")
    distro = options.get("distro", "jazzy")
    if distro not in ("jazzy", "humble"):
        raise ValueError(f"option distro: 'jazzy' or 'humble', got '{distro}'")
    namespace = options.get("namespace", f"/{name}")
    topics = Topics(options.get("cmd_vel", "cmd_vel"), options.get("odom", "odom"), options.get("scan", "scan"))
    for key, topic in (("namespace", "x"), ("cmd_vel", topics.cmd_vel), ("odom", topics.odom), ("scan", topics.scan)):
        try:
            fully_qualified(namespace, topic)
        except ValueError as exc:
            raise ValueError(f"option {key}: {exc}") from None
    kind = options.get("kind") or (role.lower() if role.lower() in ROBOT_KINDS else "scout")
    if kind not in ROBOT_KINDS:
        raise ValueError(f"option kind: no robot kind '{kind}'; kinds: {', '.join(sorted(ROBOT_KINDS))}")
    spec = ROBOT_KINDS[kind]
    spec = dataclasses.replace(
        spec,
        capabilities=spec.capabilities & {"base", "lidar2d"},
        lidar_range=number("lidar_range", spec.lidar_range, 0.0),
    )
    if not spec.lidar_range > 0:
        raise ValueError("option lidar_range: must be > 0 metres")
    occupancy = None
    origin = option_numbers(options, "origin", "0,0", "x,y")
    if "map" in options:
        try:
            lines = Path(options["map"]).read_text(encoding="utf-8").splitlines()
        except (OSError, UnicodeDecodeError) as exc:
            raise ValueError(f"option map: cannot read '{options['map']}': {exc}") from None
        rows = [row for row in (line.strip() for line in lines) if row]
        try:
            occupancy = OccupancyMap.from_rows(rows, number("resolution", 0.25), (origin[0], origin[1]))
        except ValueError as exc:
            raise ValueError(f"option map: {exc}") from None
    box = option_numbers(options, "bounds", ",".join(f"{v:g}" for v in DEFAULT_BOUNDS), "xmin,ymin,xmax,ymax")
    if not (box[0] < box[2] and box[1] < box[3]):
        raise ValueError(f"option bounds: xmin < xmax and ymin < ymax, got '{options['bounds']}'")
    timeout = number("timeout", 1.0, 0.0)
    noise = number("lidar_noise", 0.02, 0.0)
    wait = number("wait", 5.0, 0.0)
    session = open_session(router)
    try:
        world = Ros2BaseWorld(
            session,
            name,
            spec,
            namespace=namespace,
            domain=int(domain),
            distro=distro,
            topics=topics,
            occupancy=occupancy,
            bounds=(box[0], box[1], box[2], box[3]),
            timeout=timeout,
            lidar_noise=noise,
            owns_session=True,
        )
    except BaseException:
        _close_session(session)
        raise
    if wait > 0 and not world.wait(lambda: world.odometry_count > 0, wait):
        world.close()
        raise ValueError(
            f"no odometry on {world.odom_topic} (nav_msgs/msg/Odometry, domain {int(domain)}, {distro}) within "
            f"{wait:g} s: check that the base runs with RMW_IMPLEMENTATION=rmw_zenoh_cpp, that rmw_zenohd listens "
            f"on {router}, and the options namespace, odom and domain (or set wait=0)"
        )
    return world


def _close_session(session: zenoh.Session) -> None:
    close: Callable[[], object] = session.close  # zenoh's stubs leave close() untyped
    close()


if TYPE_CHECKING:  # mypy checks that the driver satisfies the robot interface

    def _is_a_robot_world(world: Ros2BaseWorld) -> RobotWorld:
        return world

    def _is_a_mobile_robot(robot: Ros2BaseRobot) -> MobileRobot:
        return robot
