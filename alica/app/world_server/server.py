"""The world server: one pybullet world, its robots served over zenoh to agents in other processes.

One thread (the one that calls :meth:`WorldServer.serve`) owns the world: it
steps it, casts the sensors and serves the calls that touch pybullet, taking
them off a queue that zenoh's callbacks fill. The calls that only set a
command (:data:`FAST_CALLS`: drive, stop, set_estimate, set_bumped) are served
at once on zenoh's thread, under a lock the world's thread holds while it
steps, so a drive command does not wait for a camera picture.

* **Calls.** Each robot has a queryable ``P/world/robot/NAME/call``; the world
  one ``P/world/call`` (see :mod:`alica.app.world_server.wire`). A robot
  answers only its own agent: every robot call names its caller, and a caller
  that is not the robot's agent is refused (``stats.refused``). Each reply to a
  robot call carries the robot's state after the call, so the agent reads its
  own writes (an arm told to follow a path is busy at once).
* **State.** After each step the server publishes the time, every robot's
  pose, estimate, flags and arm, the movable objects' geometry and pose (the
  static ones are in the answer to ``state``), and, free-running, the lidar
  scans agents asked for: once an agent asked for a scan, its robot's lidar is
  cast with those settings at every step. In lock-step a scan is cast only on
  request (the agent's tick waits for it anyway, and skills ask for a scan a
  few times a second at most: casting every robot's at every step cost the
  world server most of its time).
* **Time.** Free-running (the default) steps ``1/frequency`` simulated seconds
  every ``1/(frequency*speed)`` wall seconds. Lock-step steps once every
  connected agent has said it finished its tick (the ``tick`` call, answered
  with the state after the step), so a run with a seed repeats exactly. The
  first step waits for the ``agents`` named at the start.
* **Faults.** An agent whose liveliness token leaves (its process ended or
  was killed) is its robot's crash (:meth:`~alica.worldsim.robots.Robot.crash`):
  the base stops and the gripper opens. When it comes back, the robot recovers.
* **Bad input.** Every frame is checked (:func:`~alica.app.world_server.wire.decode`
  and the checks of each call); a malformed one is counted in
  ``stats.rejected`` by reason and answered with an error, never fatal.
"""

from __future__ import annotations

import contextlib
import logging
import math
import queue
import threading
import time
import zlib
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Self

import numpy as np
import zenoh

from alica.app.world_server import wire
from alica.app.world_server.wire import BadPayload

if TYPE_CHECKING:
    from alica.worldsim.objects import WorldObject
    from alica.worldsim.robots import Robot
    from alica.worldsim.world import World

__all__ = ["ServerStats", "WorldServer"]

logger = logging.getLogger(__name__)

MAX_RAYS = 100_000
MAX_PIXELS = 1280 * 960
MAX_PATH = 100_000
FAST_CALLS = frozenset({"drive", "stop", "set_bumped", "set_estimate"})
"""Robot calls served at once on zenoh's thread (they only set commands, never touch pybullet)."""
SENSOR_CALLS = frozenset({"lidar", "camera", "camera_pose"})
"""Robot calls that only read the world: served without holding the lock, so fast calls do not wait for them."""


@dataclass
class ServerStats:
    """What a server did: steps, calls served, calls refused and frames rejected (by reason)."""

    steps: int = 0
    calls: int = 0
    refused: int = 0
    rejected: Counter[str] = field(default_factory=Counter)
    crashes: int = 0
    recoveries: int = 0


class _Refused(Exception):
    """A well-formed call the server will not serve (someone else's robot, a robot without an arm)."""


class WorldServer:
    """Serves the robots of ``world`` over a zenoh session.

    Args:
        world: the world (the server steps it; the caller closes it).
        listen: zenoh endpoints to listen on (``tcp/127.0.0.1:7447``).
        connect: zenoh endpoints to connect to.
        prefix: the team's key prefix.
        lockstep: step only when every connected agent finished its tick.
        speed: free-running: simulated seconds per wall second (> 0).
        frequency: steps per simulated second (> 0); a step is ``1/frequency`` s.
        agents: the agents expected: in lock-step the first step waits for them all.
        mode: zenoh mode (``peer`` or ``client``).
        lease: zenoh link lease, seconds (how soon a partition shows).
        settings: more zenoh settings (e.g. :meth:`alica.comm.credentials.TeamKeys.zenoh_settings`), applied last.

    Raises:
        ValueError: a bad speed or frequency, or zenoh settings it does not accept.
        WorldError: the zenoh session does not open (the endpoint is taken).
    """

    def __init__(
        self,
        world: World,
        *,
        listen: Sequence[str] = (),
        connect: Sequence[str] = (),
        prefix: str = "alica",
        lockstep: bool = False,
        speed: float = 1.0,
        frequency: float = 30.0,
        agents: Iterable[str] = (),
        mode: str = "peer",
        lease: float = 2.0,
        settings: Mapping[str, object] | None = None,
    ) -> None:
        from alica.comm.zenoh_transport import zenoh_config
        from alica.worldsim.errors import WorldError

        if not (math.isfinite(speed) and speed > 0):
            raise ValueError(f"speed must be > 0 simulated seconds per wall second, got {speed}")
        if not (math.isfinite(frequency) and 0 < frequency <= 1000):
            raise ValueError(f"frequency must be in (0, 1000] Hz, got {frequency}")
        self.world = world
        self.prefix = prefix
        self.lockstep = lockstep
        self.speed = float(speed)
        self.period = 1.0 / float(frequency)
        self.expected = frozenset(agents)
        self.stats = ServerStats()
        self.endpoints = tuple(listen) or tuple(connect)
        self._id = time.time_ns() & (2**62 - 1)
        self._version = 0
        self._inbox: queue.SimpleQueue[tuple[str, Any]] = queue.SimpleQueue()
        self._stop = threading.Event()
        self._alive: set[str] = set()
        self._ever: set[str] = set()
        self._crashed_by_us: set[str] = set()
        self._ticks: dict[str, list[zenoh.Query]] = {}
        self._static: dict[str, dict[str, Any]] = {}
        self._streams: dict[str, tuple[int, float | None]] = {}
        self._draws: dict[str, tuple[int, int]] = {}
        self._static_names: frozenset[str] = frozenset()
        self._epoch = 0
        self._lock = threading.RLock()
        self._closed = False
        try:
            self._session = zenoh.open(zenoh_config(tuple(connect), tuple(listen), mode, lease, settings))
        except zenoh.ZError as exc:
            raise WorldError(f"the world server cannot open its zenoh session on {', '.join(listen)}: {exc}") from None
        s = self._session
        self._handles: list[Any] = [
            s.declare_queryable(wire.call_key(prefix), lambda q: self._inbox.put(("world", q))),
            s.liveliness().declare_subscriber(wire.agent_key(prefix, "*"), self._on_agent, history=True),
        ]
        for robot in world.robots:
            self._handles.append(s.declare_queryable(wire.robot_key(prefix, robot), self._queue_for(robot)))
        self._publisher = s.declare_publisher(
            wire.state_key(prefix), congestion_control=zenoh.CongestionControl.DROP, express=True
        )
        self._token = s.liveliness().declare_token(wire.alive_key(prefix))

    def _queue_for(self, robot: str) -> Callable[[zenoh.Query], None]:
        def put(query: zenoh.Query) -> None:
            self._on_robot_query(robot, query)

        return put

    def _on_robot_query(self, robot: str, query: zenoh.Query) -> None:
        """(zenoh's thread) Serve a fast call at once, under the lock; queue the others for the world's thread."""
        try:
            frame = _decode(query)
        except BadPayload as exc:
            self._malformed(query, exc)
            return
        if frame.header.get("call") in FAST_CALLS:
            with self._lock:
                self._serve(robot, query, frame)
        else:
            self._inbox.put((robot, (query, frame)))

    # -- life ----------------------------------------------------------------------------------------------

    def serve(self, duration: float | None = None, until: Callable[[], bool] | None = None) -> None:
        """Serve until :meth:`stop`, for ``duration`` wall seconds, or until ``until()`` is true.

        ``until`` is asked after each step, and at least every 50 ms.
        """
        end = math.inf if duration is None else time.monotonic() + duration
        next_step = asked = time.monotonic()
        self._publish()
        while not self._stop.is_set() and time.monotonic() < end:
            now = time.monotonic()
            wait = 0.05 if self.lockstep else max(0.0, next_step - now)
            try:
                kind, item = self._inbox.get(timeout=min(wait, 0.05, max(0.0, end - now)))
            except queue.Empty:
                pass
            else:
                self._handle(kind, item)
            stepped = False
            if self.lockstep:
                if self._all_ticked():
                    self._step_lockstep()
                    stepped = True
            elif time.monotonic() >= next_step:
                self._step()
                stepped = True
                next_step += self.period / self.speed
                next_step = max(next_step, time.monotonic() - 2 * self.period / self.speed)  # no catch-up burst
            if until is not None and (stepped or time.monotonic() - asked >= 0.05):
                asked = time.monotonic()
                if until():
                    break

    def stop(self) -> None:
        """Make :meth:`serve` return (from any thread)."""
        self._stop.set()

    def close(self) -> None:
        """Leave: the token goes (clients see the server gone), the session closes. The world stays open."""
        self._stop.set()
        if self._closed:
            return
        self._closed = True
        for queries in self._ticks.values():
            for q in queries:
                q.drop()
        self._ticks.clear()
        try:
            self._token.undeclare()
        finally:
            self._session.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- stepping ------------------------------------------------------------------------------------------

    def _step(self) -> bytes:
        """Step the world, cast the lidar streams, publish; returns the frame published (for lock-step replies)."""
        with self._lock:
            self.world.step(self.period)
            self.stats.steps += 1
            self._version += 1
            state = self._state_json(objects=True)
        return self._publish(state)

    def _all_ticked(self) -> bool:
        waiting = {a for a, qs in self._ticks.items() if qs}
        if not waiting:
            return False
        if self.stats.steps == 0 and not self.expected <= self._ever | waiting:
            return False
        return (self._alive & set(self.world.robots)) <= waiting

    def _step_lockstep(self) -> None:
        reply = self._step()
        for agent in list(self._ticks):
            queries = self._ticks[agent]
            if queries:
                q = queries.pop(0)
                q.reply(q.key_expr, reply)
                q.drop()

    def _publish(self, state: dict[str, Any] | None = None) -> bytes:
        if state is None:
            with self._lock:
                state = self._state_json(objects=True)
        scans: dict[str, np.ndarray] = {}
        for robot, (n, max_range) in sorted(self._streams.items()):
            with self._own_noise(robot):
                scans[f"scan/{robot}"] = np.asarray(self.world.robots[robot].lidar(n, max_range), dtype=np.float64)
        state["scans"] = {robot: [n, max_range] for robot, (n, max_range) in self._streams.items()}
        frame = wire.encode({"ok": True, **state}, scans)
        self._publisher.put(frame)
        return frame

    @contextlib.contextmanager
    def _own_noise(self, robot: str) -> Iterator[None]:
        """In lock-step, a sensor's noise for ``robot`` drawn from a generator of its own for this step and call.

        Agents' sensor calls in one step arrive in any order; drawing each from the world's one
        generator would make the noise depend on that order. Seeded by the world's seed, the step,
        the robot and the call's number in the step, a run repeats whatever the order.
        """
        if not self.lockstep:
            yield
            return
        step = self.stats.steps
        last, count = self._draws.get(robot, (step, 0))
        count = count + 1 if last == step else 1
        self._draws[robot] = (step, count)
        world = self.world
        saved = world.rng
        world.rng = np.random.default_rng([world.seed & 0xFFFFFFFF, step, zlib.crc32(robot.encode()), count])
        try:
            yield
        finally:
            world.rng = saved

    # -- state ---------------------------------------------------------------------------------------------

    def _robot_json(self, robot: Robot) -> dict[str, Any]:
        arm = robot.arm
        held = None if arm is None else arm.held
        return wire.robot_state_json(
            robot.pose,
            robot.estimate,
            robot.crashed,
            robot.bumped,
            None if arm is None else (arm.q(), arm.busy, None if held is None else held.name),
        )

    def _thing_json(self, obj: WorldObject) -> dict[str, Any]:
        cached = self._static.get(obj.name)
        if cached is not None:
            return cached
        position, quat = obj.pose()
        lo, hi = obj.aabb()
        fp = obj.footprint()
        entry = {
            "kind": obj.kind,
            "size": obj.size,
            "radius": obj.radius,
            "half_extents": list(obj.half_extents),
            "pose": [list(position), list(quat)],
            "aabb": [np.clip(lo, -wire.MAX_BOUND, wire.MAX_BOUND).tolist(), np.clip(hi, -1e6, 1e6).tolist()],
            "footprint": None
            if fp is None
            else {
                "kind": fp.kind,
                "x": fp.x,
                "y": fp.y,
                "radius": fp.radius,
                "half_x": fp.half_x,
                "half_y": fp.half_y,
                "yaw": fp.yaw,
            },
        }
        if not obj.movable:
            self._static[obj.name] = entry
        return entry

    def _state_json(self, *, objects: bool, robots: Iterable[str] | None = None, full: bool = False) -> dict[str, Any]:
        """The state now: the ``robots`` (default all); with ``objects`` the movable objects (all with ``full``)."""
        world = self.world
        names = world.robots if robots is None else robots
        out: dict[str, Any] = {
            "server": self._id,
            "version": self._version,
            "step": self.stats.steps,
            "t": world.now(),
            "robots": {n: self._robot_json(world.robots[n]) for n in names},
        }
        if objects:
            statics = frozenset(n for n, o in world.objects.items() if not o.movable)
            if statics != self._static_names:
                self._static_names = statics
                self._epoch += 1
            out["epoch"] = self._epoch
            out["objects"] = {n: self._thing_json(o) for n, o in world.objects.items() if full or o.movable}
            if full:
                out["static_names"] = sorted(statics)
        return out

    # -- agents' liveliness ----------------------------------------------------------------------------------

    def _on_agent(self, sample: zenoh.Sample) -> None:
        agent = str(sample.key_expr).rsplit("/", 1)[-1]
        self._inbox.put(("alive", (agent, sample.kind == zenoh.SampleKind.PUT)))

    def _agent_seen(self, agent: str, alive: bool) -> None:
        try:
            wire.name(agent, "agent name")
        except BadPayload as exc:
            self.stats.rejected[exc.reason] += 1
            return
        with self._lock:
            self._agent_changed(agent, alive)

    def _agent_changed(self, agent: str, alive: bool) -> None:
        robot = self.world.robots.get(agent)
        if alive:
            self._alive.add(agent)
            self._ever.add(agent)
            if robot is not None and agent in self._crashed_by_us:
                self._crashed_by_us.discard(agent)
                robot.recover()
                self.stats.recoveries += 1
                self._version += 1
                logger.info("agent %s is back: its robot recovered", agent)
        else:
            self._alive.discard(agent)
            self._streams.pop(agent, None)
            for q in self._ticks.pop(agent, []):
                q.drop()
            if robot is not None and not robot.crashed:
                robot.crash()
                self._crashed_by_us.add(agent)
                self.stats.crashes += 1
                self._version += 1
                logger.info("agent %s left: its robot crashed", agent)

    # -- calls ---------------------------------------------------------------------------------------------

    def _handle(self, kind: str, item: Any) -> None:
        if kind == "alive":
            self._agent_seen(*item)
            return
        if kind == "world":
            try:
                frame = _decode(item)
            except BadPayload as exc:
                self._malformed(item, exc)
                return
            self._serve(kind, item, frame)
            return
        query, frame = item
        if frame.header.get("call") in SENSOR_CALLS:
            self._serve(kind, query, frame)
        else:
            with self._lock:
                self._serve(kind, query, frame)

    def _malformed(self, query: zenoh.Query, exc: BadPayload) -> None:
        with self._lock:
            self.stats.rejected[exc.reason] += 1
        logger.debug("refused a malformed call: %s", exc)
        try:
            query.reply(query.key_expr, wire.encode({"ok": False, "error": f"malformed call: {exc}"}))
        finally:
            query.drop()

    def _serve(self, kind: str, query: zenoh.Query, frame: wire.Frame) -> None:
        """Serve one decoded call: ``kind`` is ``world`` or the robot whose queryable it came to."""
        held = False
        try:
            caller = wire.name(frame.header.get("caller"), "caller")
            call = wire.name(frame.header.get("call"), "call")
            args = wire.mapping(frame.header.get("args", {}), "args", 16)
            if kind == "world":
                if call == "tick":
                    if not self.lockstep:
                        raise _Refused("the world server runs free (--speed), not in lock-step: there is no tick")
                    self._ticks.setdefault(caller, []).append(query)
                    held = True
                    return
                header, arrays = self._world_call(call, args)
            else:
                if caller != kind:
                    with self._lock:
                        self.stats.refused += 1
                    raise _Refused(f"robot '{kind}' answers only its own agent, not '{caller}'")
                header, arrays = self._robot_call(self.world.robots[kind], call, args, frame.arrays)
                with self._lock:
                    self._version += 1
                    header["state"] = self._state_json(objects=False, robots=(kind,))
            with self._lock:
                self.stats.calls += 1
            query.reply(query.key_expr, wire.encode({"ok": True, **header}, arrays))
        except BadPayload as exc:
            with self._lock:
                self.stats.rejected[exc.reason] += 1
            logger.debug("refused a malformed call: %s", exc)
            query.reply(query.key_expr, wire.encode({"ok": False, "error": f"malformed call: {exc}"}))
        except _Refused as exc:
            query.reply(query.key_expr, wire.encode({"ok": False, "error": str(exc)}))
        except (ValueError, TypeError, RuntimeError) as exc:  # WorldError is a ValueError
            query.reply(query.key_expr, wire.encode({"ok": False, "error": str(exc)[:2000]}))
        except Exception as exc:  # (pybullet's own errors, a bug: answered and logged, never the server's end)
            logger.exception("call %r on %s failed", frame.header.get("call"), kind)
            reason = f"the world server failed to serve the call: {type(exc).__name__}: {exc}"
            query.reply(query.key_expr, wire.encode({"ok": False, "error": reason[:2000]}))
        finally:
            if not held:
                query.drop()

    def _world_call(self, call: str, args: dict[str, Any]) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        world = self.world
        if call == "info":
            return self._info()
        if call == "state":
            with self._lock:
                return self._state_json(objects=True, full=True), {}
        if call == "blocker":
            x = wire.number(args.get("x"), "x")
            y = wire.number(args.get("y"), "y")
            r = wire.number(args.get("radius"), "radius", 0.0, 1000.0)
            return {"result": world.blocker(x, y, r)}, {}
        if call == "obstacles":
            include = wire.flag(args.get("include_samples", False), "include_samples")
            found = world.ground_truth_obstacles(include_samples=include)
            return {
                "result": [
                    {
                        "kind": o.kind,
                        "x": o.x,
                        "y": o.y,
                        "radius": o.radius,
                        "half_x": o.half_x,
                        "half_y": o.half_y,
                        "yaw": o.yaw,
                        "name": o.name,
                    }
                    for o in found
                ]
            }, {}
        if call == "mesh":
            obj = world.objects.get(wire.name(args.get("object"), "object"))
            if obj is None or obj.mesh is None:
                return {"result": None}, {}
            return {"result": obj.name}, {
                "vertices": np.asarray(obj.mesh.vertices, dtype=np.float64),
                "faces": np.asarray(obj.mesh.faces, dtype=np.int32),
            }
        if call == "blocks_facts":
            return {"result": sorted(list(f) for f in world.blocks_facts())}, {}
        raise BadPayload("call", f"there is no world call {call!r}")

    def _info(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        import dataclasses

        world = self.world
        robots: dict[str, Any] = {}
        for n, robot in world.robots.items():
            spec = dataclasses.asdict(robot.spec)
            spec["capabilities"] = sorted(robot.spec.capabilities)
            spec["colour"] = list(robot.spec.colour)
            robots[n] = {
                "spec": spec,
                "lidar_noise": robot.lidar_noise,
                "mount_offset": None if robot.arm is None else list(robot.arm.mount_offset),
            }
        meshes = [n for n, obj in world.objects.items() if obj.mesh is not None]
        header = {
            "server": self._id,
            "seed": world.seed,
            "bounds": list(world.bounds),
            "period": self.period,
            "lockstep": self.lockstep,
            "robots": robots,
            "meshes": meshes,
        }
        return header, {}

    def _robot_call(
        self, robot: Robot, call: str, args: dict[str, Any], arrays: Mapping[str, np.ndarray]
    ) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        if call == "drive":
            robot.drive(wire.number(args.get("v"), "v", -100.0, 100.0), wire.number(args.get("w"), "w", -100.0, 100.0))
            return {}, {}
        if call == "stop":
            robot.stop()
            return {}, {}
        if call == "set_estimate":
            robot.set_estimate(wire.triple(args.get("pose"), "pose"))
            return {}, {}
        if call == "set_bumped":
            robot.bumped = wire.flag(args.get("value"), "value")
            return {}, {}
        if call == "lidar":
            n = wire.integer(args.get("n_rays"), "n_rays", 1, MAX_RAYS)
            max_range = wire.optional_number(args.get("max_range"), "max_range", 0.0, 1e4)
            with self._own_noise(robot.name):
                ranges = np.asarray(robot.lidar(n, max_range), dtype=np.float64)
            if not self.lockstep:  # free-running: from now on cast at every step, for reads without a round trip
                self._streams[robot.name] = (n, max_range)
            return {}, {"ranges": ranges}
        if call == "camera_pose":
            at = args.get("pose")
            position, rotation = robot.camera_pose(
                None if at is None else wire.triple(at, "pose"), wire.number(args.get("pan", 0.0), "pan", -10.0, 10.0)
            )
            return {}, {"position": np.asarray(position, float), "rotation": np.asarray(rotation, float)}
        if call == "camera":
            return self._camera(robot, args)
        if call.startswith("arm_"):
            return self._arm_call(robot, call[4:], args, arrays)
        raise BadPayload("call", f"there is no robot call {call!r}")

    def _camera(self, robot: Robot, args: dict[str, Any]) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        width = wire.integer(args.get("width", 320), "width", 1, 2048)
        height = wire.integer(args.get("height", 240), "height", 1, 2048)
        if width * height > MAX_PIXELS:
            raise BadPayload("range", f"a picture of {width}x{height} is over {MAX_PIXELS} pixels")
        window = args.get("window")
        win = None
        if window is not None:
            if not isinstance(window, list) or len(window) != 4:
                raise BadPayload("type", "window must be [u0, v0, u1, v1]")
            u0, v0, u1, v1 = (wire.integer(v, "window", 0, 4096) for v in window)
            win = (u0, v0, u1, v1)
        with self._own_noise(robot.name):
            image = robot.camera(
                width=width,
                height=height,
                fov=wire.optional_number(args.get("fov"), "fov", 0.0, 4.0),
                far=wire.optional_number(args.get("far"), "far", 0.0, 1e4),
                pan=wire.number(args.get("pan", 0.0), "pan", -10.0, 10.0),
                believed=wire.flag(args.get("believed", False), "believed"),
                window=win,
            )
        header = {
            "intrinsics": list(image.intrinsics),
            "time": image.time,
            "pan": image.pan,
            "offset": list(image.offset),
            "frame": None if image.frame is None else list(image.frame),
        }
        depth = np.asarray(image.depth, dtype=np.float64)
        return header, {
            "rgb": np.asarray(image.rgb, dtype=np.uint8),
            "depth": depth,
            "position": np.asarray(image.position, dtype=np.float64),
            "rotation": np.asarray(image.rotation, dtype=np.float64),
        }

    def _arm_call(
        self, robot: Robot, call: str, args: dict[str, Any], arrays: Mapping[str, np.ndarray]
    ) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        arm = robot.arm
        if arm is None:
            raise _Refused(f"robot '{robot.name}' has no arm")
        if call == "follow":
            path = wire.array(arrays, "path", "arm follow", ndim=2, width=7)
            if len(path) > MAX_PATH:
                raise BadPayload("range", f"a path of more than {MAX_PATH} configurations")
            duration = wire.optional_number(args.get("duration"), "duration", 0.0, 1e6)
            return {"result": arm.follow(np.array(path, dtype=float), duration)}, {}
        if call == "stop":
            arm.stop()
        elif call == "open":
            arm.open()
        elif call == "close":
            arm.close(wire.optional_number(args.get("force"), "force", 0.0, 1e4))
        elif call == "attach":
            return {"result": arm.attach(wire.name(args.get("object"), "object"))}, {}
        elif call == "detach":
            dropped = arm.detach()
            return {"result": None if dropped is None else dropped.name}, {}
        elif call == "grip_force":
            return {"result": float(arm.grip_force())}, {}
        elif call == "base_pose":
            position, quat = arm.base_pose()
            return {"result": [list(position), list(quat)]}, {}
        else:
            raise BadPayload("call", f"there is no arm call {call!r}")
        return {}, {}


def _decode(query: zenoh.Query) -> wire.Frame:
    payload = query.payload
    if payload is not None and len(payload) > wire.MAX_FRAME:
        raise BadPayload("size", f"a frame of {len(payload)} bytes is over the limit of {wire.MAX_FRAME}")
    return wire.decode(b"" if payload is None else payload.to_bytes())
