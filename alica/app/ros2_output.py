"""``--ros2`` and ``--record DIR``: where a run's ROS 2 messages go, a live ROS 2 graph and a rosbag2 folder.

:class:`BagSink` writes them into a rosbag2 folder (:class:`alica.comm.ros2.bag.BagWriter`);
:class:`LiveSink` publishes them as an rmw_zenoh node does (:class:`alica.comm.ros2.rmw.Ros2Node`),
one node ``alica_<robot>`` per agent in the robot's namespace. :class:`Ros2Output` opens both
from the command line's options and attaches them to a simulated team (:meth:`Ros2Output.attach_team`)
or to one agent process (:meth:`Ros2Output.attach_agent`); the topics are
:mod:`alica.app.ros2_bridge`'s, and a live run also takes goals from ``/alica/goal``
(:mod:`alica.app.ros2_goal`).

A simulated run stamps its messages with simulated time (seconds from 0: the same seed
gives the same recording) and, live, publishes it on ``/clock`` so that ROS 2 tools
run with ``use_sim_time``; an agent on the wall clock stamps with the wall time.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.app.ros2_bridge import POSE_HZ, Sink, Topic, pose_stamped, publishers, ros_name
from alica.app.ros2_views import EngineView
from alica.comm.ros2 import dds_name, encode, schema_text, type_hash
from alica.comm.ros2.bag import BagWriter
from alica.comm.ros2.rmw import Qos, Ros2Node, Ros2Publisher, open_session
from alica.errors import AlicaError

if TYPE_CHECKING:
    import zenoh

    from alica.app.ros2_goal import GoalTopic
    from alica.engine import AgentEngine, SimulatedTeam
    from alica.model import PlanLibrary

#: The run's time, for ROS 2 tools with ``use_sim_time`` (a live simulated run, a world server).
CLOCK = Topic("clock", "rosgraph_msgs/msg/Clock", reliable=False, depth=1, global_name=True)
#: A world server's true pose of each robot (``geometry_msgs/msg/PoseStamped``, frame ``map``).
GROUND_TRUTH = Topic("ground_truth", "geometry_msgs/msg/PoseStamped", reliable=False, depth=5)


class BagSink:
    """Messages into a rosbag2 folder (one topic per path, declared once)."""

    def __init__(self, writer: BagWriter, distro: str) -> None:
        self.writer = writer
        self.distro = distro
        self._declared: set[str] = set()

    def declare(self, path: str, topic: Topic) -> None:
        """Add ``path`` to the bag (again: nothing)."""
        if path in self._declared:
            return
        self._declared.add(path)
        self.writer.add_topic(
            path,
            topic.typename,
            schema_text(topic.typename, self.distro),
            latched=topic.latched,
            reliable=topic.reliable,
            depth=topic.depth,
        )

    def put(self, path: str, stamp_ns: int, data: bytes) -> None:
        """One message into the bag."""
        self.writer.write(path, stamp_ns, data)


class LiveSink:
    """Messages to a ROS 2 graph through one rmw_zenoh node (a publisher per path)."""

    def __init__(self, node: Ros2Node, distro: str) -> None:
        self.node = node
        self.distro = distro
        self._publishers: dict[str, Ros2Publisher] = {}

    def declare(self, path: str, topic: Topic) -> None:
        """A publisher for ``path`` with the topic's QoS (again: nothing)."""
        if path in self._publishers:
            return
        qos = Qos(reliable=topic.reliable, transient_local=topic.latched, depth=topic.depth)
        self._publishers[path] = self.node.publisher(
            path, dds_name(topic.typename), type_hash(topic.typename, self.distro), qos
        )

    def put(self, path: str, stamp_ns: int, data: bytes) -> None:
        """Publish one message; the attachment's source time is the wall clock's, as rmw_zenoh's (the stamps are in the message)."""
        self._publishers[path].put(data, time.time_ns())


class Ros2Output:
    """The ROS 2 side of one process: a recording, a live graph, or both; :meth:`close` it at the end.

    Args:
        record: the rosbag2 folder to write (``None``: no recording).
        live: join the ROS 2 graph through ``router``.
        router: the zenoh router (``rmw_zenohd``) to join as a client; ``None``: a peer on its own
            (tests give ``listen`` then).
        domain: the ROS 2 domain id.
        distro: ``humble`` or ``jazzy``.
        listen: zenoh endpoints to listen on (tests).
        goals: take the operator's goal from ``/alica/goal`` (live only).

    Raises:
        AlicaError: the bag folder exists and is not empty, or the distro is unknown.
    """

    def __init__(
        self,
        *,
        record: str | Path | None = None,
        live: bool = False,
        router: str | None = None,
        domain: int = 0,
        distro: str = "jazzy",
        listen: list[str] | None = None,
        goals: bool = True,
    ) -> None:
        self.distro = distro
        self.domain = domain
        self.goals = goals
        self.writer = BagWriter(record, distro=distro) if record is not None else None
        self._bag = BagSink(self.writer, distro) if self.writer is not None else None
        self.session: zenoh.Session | None = None
        if live:
            try:
                self.session = open_session(router, listen=listen)
            except ValueError as exc:
                if self.writer is not None:
                    self.writer.close()
                raise AlicaError(
                    f"--ros2: {exc}; is the ROS 2 router running there (ros2 run rmw_zenoh_cpp rmw_zenohd)? "
                    "Give its endpoint with --ros2-router"
                ) from None
        self.nodes: dict[str, Ros2Node] = {}
        self._live: dict[str, LiveSink] = {}
        self.goal: GoalTopic | None = None
        self._clock: Ros2Publisher | None = None
        self._closed = False

    @classmethod
    def from_args(cls, args: argparse.Namespace, *, live: bool = True) -> Ros2Output | None:
        """The output the options ``--ros2`` and ``--record`` ask for, or ``None`` when neither is given."""
        record = getattr(args, "record", None)
        wanted = live and bool(getattr(args, "ros2", False))
        if record is None and not wanted:
            return None
        return cls(
            record=record,
            live=wanted,
            router=getattr(args, "ros2_router", None),
            domain=getattr(args, "ros2_domain", 0),
            distro=getattr(args, "ros2_distro", "jazzy"),
        )

    def node(self, name: str, namespace: str = "") -> Ros2Node:
        """The live node ``name`` (made on first use)."""
        if self.session is None:
            raise RuntimeError("not a live ROS 2 output")
        if name not in self.nodes:
            self.nodes[name] = Ros2Node(self.session, name, namespace=namespace, domain=self.domain)
        return self.nodes[name]

    def sinks(self, robot: str) -> list[Sink]:
        """Where ``robot``'s messages go: the bag, and its own live node ``alica_<robot>`` in ``/<robot>``."""
        out: list[Sink] = [self._bag] if self._bag is not None else []
        if self.session is not None:
            if robot not in self._live:
                name = ros_name(robot)
                self._live[robot] = LiveSink(self.node(f"alica_{name}", f"/{name}"), self.distro)
            out.append(self._live[robot])
        return out

    def attach_team(self, team: SimulatedTeam, library: PlanLibrary, *, hook: bool = True) -> Callable[[float], None]:
        """Publish every running agent's topics after each tick of ``team``, in simulated time; live, take goals.

        Args:
            team: the simulated team.
            library: its plans (the planning problems a goal from ``/alica/goal`` may name).
            hook: register with ``team.after_tick``; else call the returned function after every tick
                (a demo that runs its own loop).

        Returns:
            What to call after each tick with the time.
        """
        world_of = team.agent_worlds.get
        views = {
            name: EngineView(_engine_of(team, name), _robot_of(world_of(name, team.world), name))
            for name in team.engines
        }
        publish = publishers(views, self.sinks, self.distro, alive=lambda name: name not in team.crashed)
        if self.session is not None and self.goals:
            self.listen_for_goals(library, team.set_goal)
        goal = self.goal

        def after_tick(now: float) -> None:
            if goal is not None:
                goal.poll(now)
            publish(now)
            self.publish_clock(now)

        after_tick(team.now())
        if hook:
            team.after_tick(after_tick)
        return after_tick

    def attach_agent(
        self, engine: AgentEngine, robot: Any | None, library: PlanLibrary, *, epoch: float = 0.0
    ) -> Callable[[float], None]:
        """A hook for after each tick of one agent process: its topics (stamped ``epoch + now``) and, live, goals."""
        view = EngineView(engine, robot)
        publish = publishers({engine.name: view}, self.sinks, self.distro, epoch=epoch)

        def set_goal(problem: str, goal: str) -> None:
            engine.set_problem(problem, goal=goal)
            engine.emit("operator", what="goal", problem=problem, goal=goal, applied=True, via="ros2")

        if self.session is not None and self.goals:
            self.listen_for_goals(library, set_goal)
        goal = self.goal

        def after_tick(now: float) -> None:
            if goal is not None:
                goal.poll(now)
            publish(now)

        return after_tick

    def attach_world(self, world: Any) -> Callable[[], bool]:
        """For a world server: ``/clock`` and each robot's true pose (``/<robot>/ground_truth``), node ``alica_world``.

        Returns:
            What to call after each step of the world (it returns ``False``: serving goes on), e.g. as
            :meth:`alica.app.world_server.WorldServer.serve`'s ``until``.
        """
        sinks: list[Sink] = []
        if self.session is not None:
            sinks.append(LiveSink(self.node("alica_world"), self.distro))
        if self._bag is not None:
            sinks.append(self._bag)
        for name in sorted(world.robots):
            for sink in sinks:
                sink.declare(GROUND_TRUTH.path(name), GROUND_TRUTH)
        last = [-math.inf, -math.inf]  # the last step seen, the last pose sent

        def after_step() -> bool:
            now = float(world.now())
            if now == last[0]:
                return False
            last[0] = now
            self.publish_clock(now)
            if now - last[1] >= 1.0 / POSE_HZ:
                last[1] = now
                stamp_ns = max(0, round(now * 1e9))
                for name, robot in sorted(world.robots.items()):
                    x, y, yaw = (float(v) for v in robot.pose)
                    data = encode(GROUND_TRUTH.typename, pose_stamped(now, x, y, yaw), self.distro)
                    for sink in sinks:
                        sink.put(GROUND_TRUTH.path(name), stamp_ns, data)
            return False

        return after_step

    def listen_for_goals(self, library: PlanLibrary, apply: Callable[[str, str], None]) -> None:
        """Subscribe ``/alica/goal`` with node ``alica_operator`` (the plans' planning problems, ``apply`` sets one)."""
        from alica.app.center.operator import problems
        from alica.app.ros2_goal import GoalTopic

        self.goal = GoalTopic(self.node("alica_operator"), problems(library), apply, self.distro)

    def publish_clock(self, now: float) -> None:
        """``/clock`` (``rosgraph_msgs/msg/Clock``): the simulated time, for ROS 2 tools with ``use_sim_time``."""
        if self.session is None:
            return
        if self._clock is None:
            qos = Qos(reliable=CLOCK.reliable, transient_local=False, depth=CLOCK.depth)
            self._clock = self.node("alica_clock").publisher(
                "/clock", dds_name(CLOCK.typename), type_hash(CLOCK.typename, self.distro), qos
            )
        ns = max(0, round(now * 1e9))
        data = encode(
            CLOCK.typename, {"clock": {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}}, self.distro
        )
        self._clock.put(data, time.time_ns())

    def close(self) -> None:
        """Finish the recording (``metadata.yaml``) and leave the graph; a second call does nothing."""
        if self._closed:
            return
        self._closed = True
        if self.writer is not None:
            self.writer.close()
        for node in self.nodes.values():
            node.close()
        if self.session is not None:
            self.session.close()


def _engine_of(team: SimulatedTeam, name: str) -> Callable[[], AgentEngine]:
    return lambda: team.engines[name]  # a restarted agent gets a new engine


def _robot_of(world: Any, name: str) -> Any | None:
    robots: Mapping[str, Any] = getattr(world, "robots", None) or {}
    return robots.get(name)


__all__ = ["BagSink", "LiveSink", "Ros2Output"]
