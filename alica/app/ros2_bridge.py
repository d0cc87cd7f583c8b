"""What a team shows the ROS 2 world: each agent's pose, the team map, samples and goals, and its plans.

Every agent publishes under its robot's namespace (``/scout/...``), in the
message types ROS 2 tools read (:data:`TOPICS`):

* ``/tf`` (``tf2_msgs/msg/TFMessage``): ``map`` -> ``<robot>/base_link``, and
  ``<robot>/pose`` (``geometry_msgs/msg/PoseStamped``, frame ``map``): where
  the robot believes it is, at most :data:`POSE_HZ` times a second;
* ``<robot>/team_map`` (``nav_msgs/msg/OccupancyGrid``, latched): the team's
  map as the agent's world model holds it, when it changed, at most every
  :data:`MAP_EVERY_S` seconds (0 to 100 per cell, -1 unknown);
* ``<robot>/markers`` (``visualization_msgs/msg/MarkerArray``): the samples the
  team found (a cylinder and the sample's kind) and the places the team's
  planning goals name (``at(s, g)``: a marker at ``g``), when they changed;
* ``<robot>/diagnostics`` (``diagnostic_msgs/msg/DiagnosticArray``): one status
  per running plan, root first (plan, task, state, the behaviours and their
  feedback), once a second and when the agent's plans changed.

The same messages go to any number of sinks: a live ROS 2 node (rmw_zenoh's
wire format, :mod:`alica.comm.ros2.rmw`) and a rosbag2 recording
(:mod:`alica.comm.ros2.bag`). Times are the run's clock: simulated seconds in a
simulated run (a recording of one seed is the same every time), wall seconds
for ``alica agent``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from alica.comm.ros2 import encode

#: Poses and transforms at most this often per (simulated) second.
POSE_HZ = 10.0
#: The team map at most this often, in seconds, when it changed.
MAP_EVERY_S = 5.0
#: Diagnostics at least this often, in seconds (and when the agent's plans changed).
DIAGNOSTICS_EVERY_S = 1.0
#: Slack on the rates: ticks of 1/30 s land on 0.1 s slots up to rounding.
_EPS = 1e-6


@dataclass(frozen=True, slots=True)
class Topic:
    """One topic every agent publishes: its name under the robot's namespace, its type and its QoS."""

    name: str
    typename: str
    latched: bool = False
    reliable: bool = True
    depth: int = 10
    global_name: bool = False
    """A name outside the robot's namespace (``/tf``)."""

    def path(self, robot: str) -> str:
        """The topic's full name for ``robot``."""
        return f"/{self.name}" if self.global_name else f"/{ros_name(robot)}/{self.name}"


def ros_name(name: str) -> str:
    """``name`` as a ROS 2 name token: letters, digits and ``_``, not starting with a digit (``r-2`` -> ``r_2``)."""
    token = re.sub(r"[^A-Za-z0-9_]", "_", name) or "_"
    return f"_{token}" if token[0].isdigit() else token


TF = Topic("tf", "tf2_msgs/msg/TFMessage", global_name=True, depth=100)
POSE = Topic("pose", "geometry_msgs/msg/PoseStamped", reliable=False, depth=5)
MAP = Topic("team_map", "nav_msgs/msg/OccupancyGrid", latched=True, depth=1)
MARKERS = Topic("markers", "visualization_msgs/msg/MarkerArray")
DIAGNOSTICS = Topic("diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
#: Every topic an agent publishes.
TOPICS: tuple[Topic, ...] = (TF, POSE, MAP, MARKERS, DIAGNOSTICS)


class Sink(Protocol):
    """Where an agent's messages go: a live ROS 2 node, a rosbag2 recording."""

    def declare(self, path: str, topic: Topic) -> None:
        """Make topic ``path`` known (again: harmless; every agent declares ``/tf``)."""
        ...

    def put(self, path: str, stamp_ns: int, data: bytes) -> None:
        """One serialized message on ``path`` at ``stamp_ns``."""
        ...


# -- messages as plain data (alica.comm.ros2.encode serializes them) ---------------------------------


def stamp(t: float) -> dict[str, int]:
    """A ``builtin_interfaces/msg/Time`` of ``t`` seconds (never negative)."""
    ns = max(0, round(t * 1e9))
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _header(t: float, frame: str) -> dict[str, Any]:
    return {"stamp": stamp(t), "frame_id": frame}


def _yaw_quaternion(yaw: float) -> dict[str, float]:
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2.0), "w": math.cos(yaw / 2.0)}


def pose_stamped(t: float, x: float, y: float, yaw: float) -> dict[str, Any]:
    """``geometry_msgs/msg/PoseStamped`` of a robot on the ground, in frame ``map``."""
    return {
        "header": _header(t, "map"),
        "pose": {"position": {"x": x, "y": y, "z": 0.0}, "orientation": _yaw_quaternion(yaw)},
    }


def tf_message(t: float, robot: str, x: float, y: float, yaw: float) -> dict[str, Any]:
    """``tf2_msgs/msg/TFMessage``: ``map`` -> ``<robot>/base_link``."""
    transform = {
        "header": _header(t, "map"),
        "child_frame_id": f"{ros_name(robot)}/base_link",
        "transform": {"translation": {"x": x, "y": y, "z": 0.0}, "rotation": _yaw_quaternion(yaw)},
    }
    return {"transforms": [transform]}


def occupancy_grid(t: float, origin: tuple[float, float], resolution: float, logodds: np.ndarray) -> dict[str, Any]:
    """``nav_msgs/msg/OccupancyGrid`` of a log-odds grid: 0 to 100 per cell by probability, -1 never observed."""
    ny, nx = logodds.shape
    probability = np.rint(100.0 / (1.0 + np.exp(-logodds.astype(np.float64)))).astype(np.int8)
    cells = np.where(logodds == 0.0, np.int8(-1), probability).astype(np.int8)
    return {
        "header": _header(t, "map"),
        "info": {
            "map_load_time": stamp(t),
            "resolution": float(resolution),
            "width": int(nx),
            "height": int(ny),
            "origin": {"position": {"x": origin[0], "y": origin[1], "z": 0.0}, "orientation": _yaw_quaternion(0.0)},
        },
        "data": cells.reshape(-1),  # row-major from the lower-left cell, as ROS reads it
    }


@dataclass(frozen=True, slots=True)
class Place:
    """Something to mark on the map: a found sample (``kind`` its sample kind) or a goal's place."""

    name: str
    x: float
    y: float
    kind: str = ""
    goal: bool = False


#: Marker colours (r, g, b): samples, goals.
_SAMPLE = (0.2, 0.8, 0.2)
_GOAL = (0.9, 0.6, 0.1)
_ADD, _DELETEALL, _CYLINDER, _TEXT = 0, 3, 3, 9


def marker_array(t: float, robot: str, places: Iterable[Place]) -> dict[str, Any]:
    """``visualization_msgs/msg/MarkerArray``: a DELETEALL, then a cylinder and a label per place."""
    markers: list[dict[str, Any]] = [{"header": _header(t, "map"), "ns": robot, "id": 0, "action": _DELETEALL}]
    for index, place in enumerate(places):
        r, g, b = _GOAL if place.goal else _SAMPLE
        size = 0.6 if place.goal else 0.25
        pose = {"position": {"x": place.x, "y": place.y, "z": 0.15}, "orientation": _yaw_quaternion(0.0)}
        label = f"goal {place.name}" if place.goal else f"{place.name} ({place.kind or '?'})"
        common = {"header": _header(t, "map"), "ns": f"{robot}/{'goals' if place.goal else 'samples'}"}
        markers.append(
            {
                **common,
                "id": 2 * index + 1,
                "type": _CYLINDER,
                "action": _ADD,
                "pose": pose,
                "scale": {"x": size, "y": size, "z": 0.3},
                "color": {"r": r, "g": g, "b": b, "a": 0.8},
            }
        )
        text_pose = {**pose, "position": {"x": place.x, "y": place.y, "z": 0.6}}
        markers.append(
            {
                **common,
                "id": 2 * index + 2,
                "type": _TEXT,
                "action": _ADD,
                "pose": text_pose,
                "scale": {"x": 0.0, "y": 0.0, "z": 0.25},
                "color": {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0},
                "text": label,
            }
        )
    return {"markers": markers}


_OK, _WARN, _ERROR = 0, 1, 2


def diagnostic_array(t: float, robot: str, plans: Iterable[Mapping[str, str]]) -> dict[str, Any]:
    """``diagnostic_msgs/msg/DiagnosticArray``: a status per running plan (``plans``: key, plan, task, state, ...)."""
    status = []
    for plan in plans:
        level = _ERROR if plan.get("status") == "failure" else _OK
        values = [{"key": key, "value": str(value)} for key, value in plan.items()]
        status.append(
            {
                "level": level,
                "name": f"alica/{robot}/{plan.get('key', '')}",
                "message": f"{plan.get('plan', '')}: {plan.get('state') or 'idle'}",
                "hardware_id": robot,
                "values": values,
            }
        )
    if not status:  # no plan runs (e.g. waiting for team mates): say so rather than publish an empty array
        idle = {
            "level": _OK,
            "name": f"alica/{robot}",
            "message": "no plan running",
            "hardware_id": robot,
            "values": [],
        }
        status.append(idle)
    return {"header": _header(t, ""), "status": status}


# -- what an agent publishes, and when ------------------------------------------------------------------


class AgentView(Protocol):
    """What the bridge reads of one agent (``alica.app.ros2_views`` builds it from an engine and a robot)."""

    def pose(self) -> tuple[float, float, float] | None:
        """Where the robot believes it is ``(x, y, yaw)``, or ``None`` (no robot)."""
        ...

    def team_map(self) -> tuple[int, tuple[float, float], float, np.ndarray] | None:
        """``(version, origin, resolution, logodds)`` of the team map in the agent's world model, or ``None``."""
        ...

    def places(self) -> tuple[Place, ...]:
        """The found samples and the goals' places in the agent's world model, sorted."""
        ...

    def plans(self) -> tuple[Mapping[str, str], ...]:
        """The running plans, root first: key, plan, task, state, behaviours, status."""
        ...


class AgentTopics:
    """Publishes one agent's topics to the sinks, at their rates (see the module docstring).

    Args:
        robot: the robot's (and agent's) name: the namespace of its topics.
        view: what the agent knows (:class:`AgentView`).
        sinks: where the messages go.
        distro: ``humble`` or ``jazzy`` (the messages' definitions differ).
        epoch: seconds added to the run's time for the messages' stamps (0 in simulated time; the wall
            time at the clock's zero for an agent on the wall clock).
    """

    def __init__(
        self, robot: str, view: AgentView, sinks: Iterable[Sink], distro: str = "jazzy", epoch: float = 0.0
    ) -> None:
        self.robot = robot
        self.view = view
        self.sinks = list(sinks)
        self.distro = distro
        self.epoch = epoch
        self.sent: dict[str, int] = {topic.name: 0 for topic in TOPICS}
        """Messages sent, per topic."""
        for topic in TOPICS:
            for sink in self.sinks:
                sink.declare(topic.path(robot), topic)
        self._next_pose = -math.inf
        self._next_map = -math.inf
        self._map_version: int | None = None
        self._places: tuple[Place, ...] | None = None
        self._plans: tuple[Mapping[str, str], ...] | None = None
        self._next_diagnostics = -math.inf

    def publish(self, now: float) -> None:
        """After a tick at time ``now`` (the run's clock): whatever is due."""
        t = now + self.epoch
        if now >= self._next_pose - _EPS:
            pose = self.view.pose()
            if pose is not None:
                self._next_pose = now + 1.0 / POSE_HZ
                x, y, yaw = pose
                self._send(TF, t, tf_message(t, self.robot, x, y, yaw))
                self._send(POSE, t, pose_stamped(t, x, y, yaw))
        if now >= self._next_map - _EPS:
            grid = self.view.team_map()
            if grid is not None and grid[0] != self._map_version:
                self._next_map = now + MAP_EVERY_S
                self._map_version = grid[0]
                self._send(MAP, t, occupancy_grid(t, grid[1], grid[2], grid[3]))
            else:
                self._next_map = now + 1.0  # look again in a second
        places = self.view.places()
        if places != self._places:
            self._places = places
            self._send(MARKERS, t, marker_array(t, self.robot, places))
        plans = self.view.plans()
        if plans != self._plans or now >= self._next_diagnostics - _EPS:
            self._plans = plans
            self._next_diagnostics = now + DIAGNOSTICS_EVERY_S
            self._send(DIAGNOSTICS, t, diagnostic_array(t, self.robot, plans))

    def _send(self, topic: Topic, t: float, message: Mapping[str, Any]) -> None:
        data = encode(topic.typename, message, self.distro)
        stamp_ns = max(0, round(t * 1e9))
        path = topic.path(self.robot)
        for sink in self.sinks:
            sink.put(path, stamp_ns, data)
        self.sent[topic.name] += 1


def publishers(
    robots: Mapping[str, AgentView],
    sinks: Callable[[str], Iterable[Sink]],
    distro: str,
    alive: Callable[[str], bool] = lambda _name: True,
    epoch: float = 0.0,
) -> Callable[[float], None]:
    """A hook for after each tick that publishes the topics of every agent ``alive`` says runs.

    Args:
        robots: agent (and robot) name -> what it knows.
        sinks: where an agent's messages go, by its name.
        distro: ``humble`` or ``jazzy``.
        alive: whether an agent runs now (a crashed robot's computer is off: it says nothing).
        epoch: seconds added to the run's time for the stamps (see :class:`AgentTopics`).
    """
    agents = [AgentTopics(name, view, sinks(name), distro, epoch) for name, view in sorted(robots.items())]

    def publish(now: float) -> None:
        for agent in agents:
            if alive(agent.robot):
                agent.publish(now)

    return publish
