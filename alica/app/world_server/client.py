"""The remote robot: a world served by a world server, seen from one agent's process.

:class:`RemoteWorld` satisfies the robot interface
(:class:`~alica.worldsim.interface.RobotWorld`, its robots
:class:`~alica.worldsim.interface.MobileRobot`, their arms
:class:`~alica.worldsim.arm_interface.RobotArm`, its objects
:class:`~alica.worldsim.interface.WorldThing`): skills cannot tell it from a
local :class:`~alica.worldsim.world.World`.

* **Reads** (poses, estimates, flags, the arm's joints, objects, time) come
  from the state the server publishes after each step, and from the state each
  reply carries (so a robot reads its own writes). States are ordered by the
  server's version; an older one that arrives late is ignored.
* **Calls** (drive, sensors, the arm) are zenoh queries, answered within
  ``timeout`` seconds or :class:`~alica.worldsim.errors.WorldError` says the
  server does not answer. When the server's liveliness token is gone every call
  and read raises at once; when it comes back, the client goes on.
* **The arm's planning scene** is built here, a kinematic model of the arm
  (:class:`~alica.worldsim.arm_scene.ArmScene`) placed at the arm's base, as a
  real robot plans with its own model.

The robots, arms and objects are in :mod:`alica.app.world_server.remote`.
"""

from __future__ import annotations

import threading
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Self

import numpy as np
import zenoh

from alica.app.world_server import wire
from alica.app.world_server.remote import RemoteArm, RemoteRobot, RemoteThing
from alica.app.world_server.wire import BadPayload, RobotState, ThingState, WorldState
from alica.worldsim.errors import WorldError
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.robot_specs import RobotSpec

if TYPE_CHECKING:
    from alica.worldsim.arm_interface import ArmPlanningScene, RobotArm
    from alica.worldsim.arm_scene import ArmScene
    from alica.worldsim.interface import MobileRobot, RobotWorld, WorldThing

__all__ = ["RemoteArm", "RemoteClock", "RemoteRobot", "RemoteThing", "RemoteWorld"]


class RemoteClock:
    """The world server's simulated time, as this client last heard it (an :class:`alica.clock.Clock`)."""

    __slots__ = ("_world",)

    def __init__(self, world: RemoteWorld) -> None:
        self._world = world

    def now(self) -> float:
        """The server's simulated time, seconds."""
        return self._world.now()


class RemoteWorld:
    """A world served by ``alica world serve``, for the agent ``name``.

    Args:
        connect: zenoh endpoints of the server (``tcp/127.0.0.1:7447``).
        name: the agent's name (its robot's name; only that robot takes its commands).
        prefix: the team's key prefix.
        listen: zenoh endpoints this session listens on (usually none).
        mode: zenoh mode (``peer`` or ``client``).
        settings: more zenoh settings (the team's credentials), applied last.
        timeout: seconds a call waits for its answer.
        step_timeout: seconds :meth:`tick_done` waits for the lock-step server to step.
        wait: seconds to wait for the server when opening.
        lease: zenoh link lease, seconds.

    Raises:
        WorldError: no server answered within ``wait`` seconds, or the session does not open.
    """

    def __init__(
        self,
        connect: Sequence[str],
        name: str,
        *,
        prefix: str = "alica",
        listen: Sequence[str] = (),
        mode: str = "peer",
        settings: Mapping[str, object] | None = None,
        timeout: float = 2.0,
        step_timeout: float = 10.0,
        wait: float = 5.0,
        lease: float = 2.0,
    ) -> None:
        from alica.comm.zenoh_transport import zenoh_config

        self.name = wire.name(name, "the agent's name")
        self.prefix = prefix
        self.timeout = float(timeout)
        self.step_timeout = float(step_timeout)
        self.endpoints = tuple(connect) or tuple(listen)
        self.rejected: Counter[str] = Counter()
        self.clock = RemoteClock(self)
        self._lock = threading.Lock()
        self._alive = threading.Event()
        self._gone = False
        self._closed = False
        self._server = -1
        self._info: dict[str, Any] = {}
        self._time = 0.0
        self._robot_states: dict[str, tuple[int, RobotState]] = {}
        self._things: dict[str, ThingState] = {}
        self._things_version = -1
        self._statics: dict[str, ThingState] = {}
        self._epoch = -1
        self._statics_stale = False
        self._time_version = -1
        self._step = -1
        self._scans: dict[str, tuple[int, int, float | None, np.ndarray]] = {}
        self._robots: dict[str, RemoteRobot] = {}
        self._thing_views: dict[str, RemoteThing] = {}
        self._meshes: dict[str, tuple[np.ndarray, np.ndarray] | None] = {}
        try:
            self._session = zenoh.open(zenoh_config(tuple(connect), tuple(listen), mode, lease, settings))
        except zenoh.ZError as exc:
            raise WorldError(f"cannot open a zenoh session to the world server at {self._where()}: {exc}") from None
        s = self._session
        self._handles: list[Any] = [
            s.liveliness().declare_subscriber(wire.alive_key(prefix), self._on_server, history=True),
            s.declare_subscriber(wire.state_key(prefix), self._on_state),
        ]
        self._token = s.liveliness().declare_token(wire.agent_key(prefix, self.name))
        try:
            self._connect(wait)
        except BaseException:
            self.close()
            raise

    # -- opening, closing ------------------------------------------------------------------------------------

    def _where(self) -> str:
        return f"{', '.join(self.endpoints) or 'the default endpoints'} (key prefix '{self.prefix}')"

    def _connect(self, wait: float) -> None:
        end = time.monotonic() + wait
        while True:
            self._alive.wait(max(0.0, min(0.1, end - time.monotonic())))
            if self._alive.is_set():
                try:
                    self._refresh()
                    return
                except WorldError:
                    if time.monotonic() >= end:
                        raise
                    time.sleep(0.05)  # (its token came before its queryables)
            if time.monotonic() >= end:
                raise WorldError(
                    f"no world server at {self._where()} answered within {wait:g} s: start one with "
                    "'alica world serve --world lunar|blocks --listen ENDPOINT'"
                )

    def _refresh(self) -> None:
        """Fetch the server's description and its state now (after opening, or when a new server answers)."""
        info = self._call(wire.call_key(self.prefix), "info", {}, what="the world's description").header
        try:
            self._describe(info)
        except BadPayload as exc:
            self.rejected[exc.reason] += 1
            raise WorldError(f"the world server at {self._where()} describes its world wrongly: {exc}") from None
        frame = self._call(wire.call_key(self.prefix), "state", {}, what="the world's state")
        try:
            self._take(wire.parse_state(frame.header))
        except BadPayload as exc:
            self.rejected[exc.reason] += 1
            raise WorldError(f"the world server at {self._where()} sent a malformed state: {exc}") from None

    def _describe(self, info: Mapping[str, Any]) -> None:
        robots = wire.mapping(info.get("robots"), "robots", 1000)
        meshes = info.get("meshes", [])
        if not isinstance(meshes, list) or len(meshes) > 100_000:
            raise BadPayload("type", "meshes must be a list of object names")
        with self._lock:
            self._info = {
                "server": wire.integer(info.get("server"), "server", 0, 2**63),
                "seed": wire.integer(info.get("seed"), "seed", -(2**63), 2**63),
                "bounds": wire.numbers(info.get("bounds"), "bounds", 4),
                "period": wire.number(info.get("period"), "period", 0.0, 10.0),
                "lockstep": wire.flag(info.get("lockstep"), "lockstep"),
                "meshes": {wire.name(m, "mesh") for m in meshes},
            }
            for robot, entry in robots.items():
                wire.name(robot, "robot name")
                if robot not in self._robots:
                    self._robots[robot] = RemoteRobot(self, robot, _spec(entry), wire.mapping(entry, "robot"))

    def close(self) -> None:
        """Leave: the agent's token goes (its robot crashes in the world), the session closes, arm scenes close."""
        if self._closed:
            return
        self._closed = True
        for robot in self._robots.values():
            if robot.arm is not None:
                robot.arm.close_scene()
        try:
            self._token.undeclare()
        finally:
            self._session.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the server's messages ----------------------------------------------------------------------------------

    def _on_server(self, sample: zenoh.Sample) -> None:
        if sample.kind == zenoh.SampleKind.PUT:
            self._gone = False
            self._alive.set()
        else:
            self._gone = True
            self._alive.clear()

    def _on_state(self, sample: zenoh.Sample) -> None:
        try:
            frame = wire.decode(sample.payload.to_bytes())
            state = wire.parse_state(frame.header)
            scans = _scans(frame)
        except BadPayload as exc:
            self.rejected[exc.reason] += 1
            return
        self._take(state, scans)

    def _take(self, state: WorldState, scans: Mapping[str, tuple[int, float | None, np.ndarray]] | None = None) -> None:
        """Keep what is newer in ``state`` (and its lidar scans) than what this client has."""
        with self._lock:
            if state.server != self._server:
                if self._server != -1 and self._info.get("server") != state.server:
                    self._info["stale"] = True
                self._server = state.server
                self._robot_states.clear()
                self._things_version = -1
                self._time_version = -1
                self._step = -1
                self._scans.clear()
                self._statics, self._epoch = {}, -1
            if scans is not None and state.step >= self._step:  # (a full state: its scans are of its step)
                for n, (rays, max_range, ranges) in scans.items():
                    self._scans[n] = (state.step, rays, max_range, ranges)
                self._step = state.step
            for n, r in state.robots.items():
                held = self._robot_states.get(n)
                if held is None or held[0] <= state.version:
                    self._robot_states[n] = (state.version, r)
            if state.objects is not None and state.version >= self._things_version:
                if state.static_names is not None:  # a full state
                    self._statics = {n: s for n, s in state.objects.items() if n in state.static_names}
                    self._epoch = state.epoch
                    self._statics_stale = False
                    self._things = dict(state.objects)
                else:
                    self._statics_stale = state.epoch != self._epoch
                    self._things = {**self._statics, **state.objects}
                self._things_version = state.version
            if state.version >= self._time_version:
                self._time = state.time
                self._time_version = state.version

    # -- calls ---------------------------------------------------------------------------------------------------

    def _call(
        self,
        key: str,
        call: str,
        args: Mapping[str, Any],
        arrays: Mapping[str, np.ndarray] | None = None,
        *,
        what: str,
        timeout: float | None = None,
    ) -> wire.Frame:
        """Ask the server; the reply's frame (its robot state taken).

        Raises:
            WorldError: the server is gone or does not answer in time, refuses the call, or answers garbage.
        """
        if self._closed:
            raise WorldError(f"{what}: the connection of agent '{self.name}' to the world server is closed")
        if self._gone:
            raise WorldError(
                f"the world server at {self._where()} does not answer: it has gone (its liveliness token left); "
                f"{what} was not sent. The agent goes on when a server comes back."
            )
        wait = self.timeout if timeout is None else timeout
        payload = wire.encode({"caller": self.name, "call": call, "args": dict(args)}, arrays)
        start = time.monotonic()
        try:
            replies = self._session.get(key, payload=payload, timeout=wait)
            reply = next(iter(replies), None)
        except zenoh.ZError as exc:
            raise WorldError(f"the world server at {self._where()} cannot be asked for {what}: {exc}") from None
        if reply is None or reply.ok is None:
            if time.monotonic() - start < 0.5 * wait:
                raise WorldError(
                    f"the world server at {self._where()} does not answer: nobody took {what} (the server is not "
                    "reachable, or, with team credentials, the robot is not this agent's)"
                )
            raise WorldError(
                f"the world server at {self._where()} does not answer: {what} got no reply within {wait:g} s"
            )
        try:
            frame = wire.decode(reply.ok.payload.to_bytes())
        except BadPayload as exc:
            self.rejected[exc.reason] += 1
            raise WorldError(
                f"the world server at {self._where()} answered {what} with a malformed frame: {exc}"
            ) from None
        header = frame.header
        if header.get("ok") is not True:
            error = header.get("error")
            raise WorldError(f"{what}: {error if isinstance(error, str) else 'refused by the world server'}"[:2000])
        state = header.get("state")
        if state is not None:
            try:
                self._take(wire.parse_state(wire.mapping(state, "state")))
            except BadPayload as exc:
                self.rejected[exc.reason] += 1
        if self._info.get("stale"):
            self._info["stale"] = False
            self._refresh()
        return frame

    def _robot_state(self, robot: str) -> RobotState:
        if self._gone:
            raise WorldError(
                f"the world server at {self._where()} does not answer: it has gone; robot '{robot}''s state is unknown"
            )
        with self._lock:
            held = self._robot_states.get(robot)
        if held is None:
            raise WorldError(f"the world server at {self._where()} has not told the state of robot '{robot}'")
        return held[1]

    def _scan(self, robot: str, n_rays: int, max_range: float | None) -> np.ndarray | None:
        """The streamed scan of ``robot`` of the last step heard, if it was cast with these settings."""
        with self._lock:
            held = self._scans.get(robot)
            if held is None or held[0] != self._step or held[1] != n_rays or held[2] != max_range:
                return None
            return held[3].copy()

    def _fresh_statics(self) -> None:
        """Fetch a full state when the server's static objects changed (a rock added, a table removed)."""
        if self._statics_stale:
            frame = self._call(wire.call_key(self.prefix), "state", {}, what="the world's state")
            try:
                self._take(wire.parse_state(frame.header))
            except BadPayload as exc:
                self.rejected[exc.reason] += 1
                raise WorldError(f"the world server at {self._where()} sent a malformed state: {exc}") from None

    def _thing_state(self, obj: str) -> ThingState:
        self._fresh_statics()
        with self._lock:
            state = self._things.get(obj)
        if state is None:
            raise WorldError(f"the world server at {self._where()} has no object '{obj}' (any more)")
        return state

    def _mesh(self, obj: str) -> tuple[np.ndarray, np.ndarray] | None:
        if obj not in self._meshes:
            frame = self._call(wire.call_key(self.prefix), "mesh", {"object": obj}, what=f"the mesh of '{obj}'")
            if frame.header.get("result") is None:
                self._meshes[obj] = None
            else:
                try:
                    vertices = wire.array(frame.arrays, "vertices", "mesh", ndim=2, width=3)
                    faces = wire.array(frame.arrays, "faces", "mesh", ndim=2, width=3)
                    if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
                        raise BadPayload("range", "mesh faces name vertices that are not there")
                except BadPayload as exc:
                    raise WorldError(f"the mesh of '{obj}' from the world server is malformed: {exc}") from None
                self._meshes[obj] = (vertices.copy(), faces.astype(np.int64))
        return self._meshes[obj]

    # -- the robot interface --------------------------------------------------------------------------------------

    @property
    def robots(self) -> Mapping[str, RemoteRobot]:
        """The robots by name (only :attr:`name`'s takes commands from this agent)."""
        return dict(self._robots)

    @property
    def objects(self) -> Mapping[str, RemoteThing]:
        """The objects by name, as the last state told them."""
        self._fresh_statics()
        with self._lock:
            names = list(self._things)
        views = self._thing_views
        for n in names:
            if n not in views:
                views[n] = RemoteThing(self, n)
        return {n: views[n] for n in names}

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the field."""
        x0, y0, x1, y1 = self._info["bounds"]
        return (x0, y0, x1, y1)

    @property
    def seed(self) -> int:
        """The seed of the served world."""
        return int(self._info["seed"])

    @property
    def lockstep(self) -> bool:
        """Whether the server steps in lock-step with its agents (then call :meth:`tick_done` after each tick)."""
        return bool(self._info["lockstep"])

    @property
    def period(self) -> float:
        """Simulated seconds of one world step."""
        return float(self._info["period"])

    def now(self) -> float:
        """The server's simulated time as last heard."""
        if self._gone:
            raise WorldError(f"the world server at {self._where()} does not answer: it has gone; its time is unknown")
        with self._lock:
            return self._time

    def tick_done(self, timeout: float | None = None) -> float:
        """Tell the lock-step server this agent finished its tick; return once it stepped, with the new time.

        Raises:
            WorldError: the server is not in lock-step, is gone, or did not step within ``timeout``
                (default :attr:`step_timeout`) seconds (another agent may hang).
        """
        wait = self.step_timeout if timeout is None else timeout
        frame = self._call(wire.call_key(self.prefix), "tick", {}, what="the lock-step tick", timeout=wait)
        try:
            self._take(wire.parse_state(frame.header), _scans(frame))
        except BadPayload as exc:
            self.rejected[exc.reason] += 1
            raise WorldError(f"the world server answered the tick with a malformed state: {exc}") from None
        return self.now()

    def ground_truth_obstacles(self, *, include_samples: bool = False) -> list[Obstacle2D]:
        """Footprints of the obstacles lying in the world (the server's)."""
        frame = self._call(
            wire.call_key(self.prefix), "obstacles", {"include_samples": include_samples}, what="the obstacles"
        )
        found = frame.header.get("result")
        if not isinstance(found, list):
            raise WorldError("the world server answered the obstacles with something that is not a list")
        try:
            return [_obstacle(wire.mapping(o, "obstacle", 10), name=True) for o in found]
        except (BadPayload, ValueError) as exc:
            raise WorldError(f"the world server answered the obstacles with a malformed one: {exc}") from None

    def blocker(self, x: float, y: float, radius: float) -> str | None:
        """What a circle at ``(x, y)`` would overlap, or ``None`` (asked of the server)."""
        frame = self._call(
            wire.call_key(self.prefix), "blocker", {"x": x, "y": y, "radius": radius}, what="what blocks a place"
        )
        result = frame.header.get("result")
        return None if result is None else wire.text(result, "blocker", 200)

    def blocks_facts(self) -> set[tuple[str, ...]]:
        """The blocks-world facts the server's perception gives now."""
        frame = self._call(wire.call_key(self.prefix), "blocks_facts", {}, what="the blocks facts")
        facts = frame.header.get("result")
        if not isinstance(facts, list):
            raise WorldError("the world server answered the blocks facts with something that is not a list")
        out: set[tuple[str, ...]] = set()
        for f in facts:
            if not (isinstance(f, list) and 1 <= len(f) <= 4 and all(isinstance(a, str) for a in f)):
                raise WorldError("the world server answered a blocks fact that is not a list of names")
            out.add(tuple(f))
        return out

    def __repr__(self) -> str:
        return f"RemoteWorld({self.name!r} at {self._where()})"


def _scans(frame: wire.Frame) -> dict[str, tuple[int, float | None, np.ndarray]]:
    """The lidar scans a state frame carries: robot -> ``(rays, max_range, ranges)``.

    Raises:
        BadPayload: a scan that does not match its settings.
    """
    out: dict[str, tuple[int, float | None, np.ndarray]] = {}
    for robot, settings in wire.mapping(frame.header.get("scans", {}), "scans", 1000).items():
        wire.name(robot, "scan robot")
        if not isinstance(settings, list) or len(settings) != 2:
            raise BadPayload("type", "a scan's settings are [rays, max_range]")
        rays = wire.integer(settings[0], "rays", 1, 100_000)
        max_range = wire.optional_number(settings[1], "max_range", 0.0, 1e4)
        ranges = wire.array(frame.arrays, f"scan/{robot}", "scan", ndim=1)
        if len(ranges) != rays:
            raise BadPayload("array", f"the scan of {robot!r} has {len(ranges)} rays, not {rays}")
        out[robot] = (rays, max_range, ranges)
    return out


def _spec(entry: Any) -> RobotSpec:
    from alica.worldsim.robot_specs import ROBOT_KINDS

    d = wire.mapping(wire.mapping(entry, "robot").get("spec"), "spec", 32)
    kind = wire.name(d.get("kind"), "spec kind")
    known = ROBOT_KINDS.get(kind)
    try:
        spec = RobotSpec(
            kind=kind,
            capabilities=frozenset(wire.name(c, "capability") for c in d.get("capabilities", [])),
            radius=wire.number(d.get("radius"), "radius", 0.0, 100.0),
            max_speed=wire.number(d.get("max_speed"), "max_speed", 0.0, 100.0),
            max_yaw_rate=wire.number(d.get("max_yaw_rate"), "max_yaw_rate", 0.0, 100.0),
            has_arm=wire.flag(d.get("has_arm"), "has_arm"),
            lidar_range=wire.number(d.get("lidar_range"), "lidar_range", 0.0, 1e4),
            perception=wire.name(d.get("perception"), "perception"),
            height=wire.number(d.get("height"), "height", 0.0, 100.0),
            lidar_height=wire.number(d.get("lidar_height"), "lidar_height", 0.0, 100.0),
            camera_fov=wire.number(d.get("camera_fov"), "camera_fov", 0.0, 10.0),
            camera_pan_limit=wire.number(d.get("camera_pan_limit"), "camera_pan_limit", 0.0, 10.0),
            perception_range=wire.number(d.get("perception_range"), "perception_range", 0.0, 1e4),
            mass=wire.number(d.get("mass"), "mass", 0.0, 1e6),
            colour=wire.quaternion(d.get("colour"), "colour"),
        )
    except (TypeError, ValueError) as exc:
        raise BadPayload("type", f"a robot spec that does not hold: {exc}") from None
    return known if known == spec else spec


def _obstacle(d: Mapping[str, Any], *, name: bool = False) -> Obstacle2D:
    kind = d.get("kind")
    if kind not in ("circle", "box"):
        raise BadPayload("type", "an obstacle is a circle or a box")
    return Obstacle2D(
        str(kind),
        wire.number(d.get("x"), "x"),
        wire.number(d.get("y"), "y"),
        radius=wire.number(d.get("radius", 0.0), "radius", 0.0),
        half_x=wire.number(d.get("half_x", 0.0), "half_x", 0.0),
        half_y=wire.number(d.get("half_y", 0.0), "half_y", 0.0),
        yaw=wire.number(d.get("yaw", 0.0), "yaw"),
        name=wire.text(d.get("name", ""), "name", wire.MAX_NAME) if name else "",
    )


if TYPE_CHECKING:  # mypy checks that the remote world satisfies the robot interface

    def _is_a_robot_world(world: RemoteWorld) -> RobotWorld:
        return world

    def _is_a_mobile_robot(robot: RemoteRobot) -> MobileRobot:
        return robot

    def _is_a_robot_arm(arm: RemoteArm) -> RobotArm:
        return arm

    def _is_a_world_thing(thing: RemoteThing) -> WorldThing:
        return thing

    def _is_a_planning_scene(scene: ArmScene) -> ArmPlanningScene:
        return scene
