"""The ROS 2 base driver (``--robot ros2``, :mod:`alica.worldsim.ros2_base`) against a fake ROS 2 base on loopback.

The fake base (:mod:`tests.worldsim.fake_ros2_base`) is an rmw_zenoh node that obeys
``cmd_vel`` and publishes ``odom`` and ``scan``. The tests step it and the driver in
lock-step, in simulated time: each step waits (on events, bounded) until the driver's
Twists reached the base and the base's Odometry and LaserScan reached the driver.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from alica.app.cli import main
from alica.app.robot_plugin import RobotPlugin, close_world, load_factory
from alica.clock import ManualClock
from alica.comm.ros2 import encode
from alica.comm.ros2.rmw import open_session
from alica.comm.zenoh_transport import free_endpoints
from alica.skills.testing import run_skill
from alica.worldsim.interface import MobileRobot, RobotWorld
from alica.worldsim.robot_specs import ROBOT_KINDS
from alica.worldsim.ros2_base import Ros2BaseWorld, make_robot
from tests.worldsim.fake_ros2_base import BEAMS, LASER_SCAN, ODOMETRY, RANGE_MAX, ROOM, FakeBase

WAIT = 5.0
"""Wall seconds any one message may take on loopback before a test fails."""


@pytest.fixture
def base() -> Iterator[FakeBase]:
    fake = FakeBase(free_endpoints(1)[0])
    try:
        yield fake
    finally:
        fake.close()


@pytest.fixture
def room(tmp_path: Path) -> Path:
    path = tmp_path / "room.txt"
    path.write_text("\n".join(ROOM) + "\n", encoding="utf-8")
    return path


def connect(fake: FakeBase, **options: str) -> Ros2BaseWorld:
    """The driver of ``r1`` on the fake base: started while the base beats, then the ``cmd_vel`` link made."""
    with fake.heartbeat():
        world = make_robot("r1", "Scout", {"router": fake.endpoint, **options})
    robot = world.robots["r1"]
    linked = False
    for _ in range(100):  # a Twist sent before the base's subscription is known is lost: send until one arrives
        robot.stop()
        if fake.wait(lambda: fake.last_sequence > 0, 0.05):
            linked = True
            break
    assert linked, "the fake base never heard cmd_vel"
    return world


def exchange(world: Ros2BaseWorld, fake: FakeBase, seconds: float) -> None:
    """One lock-step: the driver's Twists reach the base, the base moves ``seconds``, its messages reach the driver."""
    assert fake.wait(lambda: fake.last_sequence >= world.sent, WAIT), "a Twist did not reach the base"
    fake.step(seconds)
    fake.publish()
    stamp = fake.time - 1e-6
    assert world.wait(lambda: world.odometry_stamp >= stamp and world.scan_stamp >= stamp, WAIT), "no odom/scan"


class LockStep:
    """The driver's world for :func:`run_skill`: its ``step`` moves the fake base and waits for the messages."""

    def __init__(self, world: Ros2BaseWorld, fake: FakeBase) -> None:
        self.world = world
        self.fake = fake
        self.clock = ManualClock()
        self.path: list[tuple[float, float, float]] = []
        """The base's true pose after each step."""

    def __getattr__(self, name: str) -> Any:
        return getattr(self.world, name)

    @property
    def robots(self) -> Mapping[str, MobileRobot]:
        return self.world.robots

    def now(self) -> float:
        return self.clock.now()

    def step(self, seconds: float) -> None:
        exchange(self.world, self.fake, seconds)
        self.path.append(self.fake.robot.pose)
        self.clock.advance(seconds)


def test_odometry_and_scans_reach_the_driver() -> None:
    base = FakeBase(free_endpoints(1)[0], pose=(1.5, 1.25, 0.7))
    world = connect(base)
    try:
        assert isinstance(world, RobotWorld) and not hasattr(world, "step")  # hardware: the wall clock
        robot = world.robots["r1"]
        exchange(world, base, 0.1)
        assert robot.pose == pytest.approx((1.5, 1.25, 0.7)) and robot.estimate == pytest.approx(robot.pose)
        assert not robot.crashed and world.odometry_count >= 1 and world.scan_count >= 1
        truth = base.robot.lidar(BEAMS, RANGE_MAX + 1.0)  # the driver's convention: from the heading on
        expected = np.where(truth > RANGE_MAX, 6.0, truth)
        assert robot.lidar(BEAMS, 6.0) == pytest.approx(expected, abs=1e-5)
        reach = robot.spec.lidar_range
        assert robot.lidar(BEAMS) == pytest.approx(np.where(truth > RANGE_MAX, reach, truth), abs=1e-5)
        coarse = robot.lidar(90, 6.0)  # a ray: the shortest beam of its 4-degree cell
        for ray in range(90):
            cell = [expected[(4 * ray + k) % BEAMS] for k in (-2, -1, 0, 1, 2)]
            assert min(cell) - 1e-5 <= coarse[ray] <= expected[4 * ray] + 1e-5
        fine = robot.lidar(720, 6.0)  # finer rays than beams: the nearest beam
        assert fine[::2] == pytest.approx(expected, abs=1e-5)
        assert robot.spec.capabilities == {"base", "lidar2d"} and robot.arm is None
        assert world.objects == {} and world.blocks_facts() == set() and world.blocker(1, 1, 0.2) is None
    finally:
        world.close()
        base.close()


def test_drive_and_stop_reach_the_base_clamped(base: FakeBase) -> None:
    world = connect(base)
    try:
        robot = world.robots["r1"]
        spec = ROBOT_KINDS["scout"]
        robot.drive(5.0, -0.3)
        assert base.wait(lambda: base.last_sequence >= world.sent, WAIT)
        assert base.twists[-1] == pytest.approx((spec.max_speed, -0.3))
        robot.drive(0.2, 9.0)
        robot.stop()
        assert base.wait(lambda: base.last_sequence >= world.sent, WAIT)
        assert base.twists[-2:] == [pytest.approx((0.2, spec.max_yaw_rate)), (0.0, 0.0)]
    finally:
        world.close()
    assert base.wait(lambda: base.last_sequence >= world.sent, WAIT) and base.twists[-1] == (0.0, 0.0)  # close stops


def test_the_base_moves_and_set_estimate_keeps_a_map_from_odometry_correction(base: FakeBase) -> None:
    world = connect(base)
    try:
        robot = world.robots["r1"]
        exchange(world, base, 0.1)
        assert robot.estimate == pytest.approx((1.0, 1.0, 0.0))
        robot.set_estimate((10.0, 5.0, math.pi / 2))  # a localiser's result: odometry (1, 1, 0) is really there
        assert robot.estimate == pytest.approx((10.0, 5.0, math.pi / 2))
        for _ in range(20):  # 2 s at 0.5 m/s: 1 m ahead in the odometry frame
            robot.drive(0.5, 0.0)
            exchange(world, base, 0.1)
        assert robot.pose == pytest.approx((2.0, 1.0, 0.0), abs=1e-6)
        assert robot.estimate == pytest.approx((10.0, 6.0, math.pi / 2), abs=1e-6)  # 1 m ahead in the map
        for _ in range(10):  # the base's watchdog stops it without cmd_vel
            exchange(world, base, 0.1)
        assert robot.pose[0] == pytest.approx(2.0 + 0.5 * 0.5, abs=0.06)
    finally:
        world.close()


def test_malformed_payloads_are_counted_and_ignored(base: FakeBase) -> None:
    world = connect(base)
    try:
        exchange(world, base, 0.1)
        good = base.odometry()
        nan = dict(good, pose={"pose": {"position": {"x": math.nan}, "orientation": {"w": 1.0}}})
        flat = dict(good, pose={"pose": {"orientation": {"w": 0.0}}})  # a quaternion of norm 0
        scan = base.laser_scan()
        bad = [
            ("odom", b"garbage"),
            ("odom", b"\x00\x01\x00\x00\x01"),
            ("odom", encode(ODOMETRY, nan)),
            ("odom", encode(ODOMETRY, flat)),
            ("scan", encode(ODOMETRY, good)[:40]),
            ("scan", encode(LASER_SCAN, dict(scan, ranges=np.ones(200_000, np.float32)))),
            ("scan", encode(LASER_SCAN, dict(scan, ranges=np.ones(0, np.float32)))),
            ("scan", encode(LASER_SCAN, dict(scan, angle_increment=0.0))),
            ("scan", encode(LASER_SCAN, dict(scan, angle_increment=0.1))),  # 360 beams of 0.1 rad: 6 turns
            ("scan", encode(LASER_SCAN, dict(scan, angle_min=math.inf))),
            ("scan", encode(LASER_SCAN, dict(scan, range_min=5.0, range_max=1.0))),
        ]
        pose, scans = world.robots["r1"].pose, world.scan_count
        for topic, payload in bad:
            base.put_raw(topic, payload)
        assert world.wait(lambda: world.dropped == len(bad), WAIT), world.dropped
        assert world.robots["r1"].pose == pose and world.scan_count == scans
        exchange(world, base, 0.1)  # still listening
        assert world.dropped == len(bad)
    finally:
        world.close()


def test_crashed_while_no_odometry_arrives(base: FakeBase) -> None:
    clock = ManualClock(100.0)
    session = open_session(base.endpoint)
    world = Ros2BaseWorld(session, "r1", ROBOT_KINDS["scout"], namespace="/r1", clock=clock.now, timeout=1.0)
    try:
        robot = world.robots["r1"]
        assert robot.crashed and world.now() == 0.0  # nothing heard yet
        with base.heartbeat():
            assert world.wait(lambda: world.odometry_count > 0, WAIT)
        assert not robot.crashed
        clock.advance(0.9)
        assert not robot.crashed and world.now() == pytest.approx(0.9)
        clock.advance(0.2)
        assert robot.crashed  # 1.1 s without odometry
    finally:
        world.close()
        close: Callable[[], object] = session.close  # zenoh's stubs leave close() untyped
        close()


def test_the_topics_follow_the_namespace_and_the_options(tmp_path: Path) -> None:
    fake = FakeBase(free_endpoints(1)[0], namespace="/base7", domain=3, distro="humble")
    try:
        with fake.heartbeat():
            world = make_robot(
                "r1",
                "",
                {"router": fake.endpoint, "namespace": "/base7", "domain": "3", "distro": "humble", "odom": "odom"},
            )
        try:
            assert world.node.name == "alica_r1" and world.odom_topic == "/base7/odom"
            assert world.cmd_vel_topic == "/base7/cmd_vel" and world.scan_topic == "/base7/scan"
            assert world.bounds == (-20.0, -20.0, 20.0, 20.0) and world.ground_truth_obstacles() == []
        finally:
            world.close()
    finally:
        fake.close()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"speed": "3"}, "the ros2 base has no option speed"),
        ({"router": "localhost"}, "tcp/127.0.0.1:7447"),
        ({"domain": "233"}, "option domain"),
        ({"domain": "1.5"}, "option domain"),
        ({"distro": "iron"}, "option distro"),
        ({"namespace": "bad name"}, "option namespace"),
        ({"cmd_vel": "cmd vel"}, "option cmd_vel"),
        ({"kind": "tank"}, "no robot kind 'tank'"),
        ({"timeout": "soon"}, "option timeout: 'soon' is not a number"),
        ({"lidar_noise": "-1"}, "option lidar_noise: must be >= 0"),
        ({"lidar_range": "0"}, "option lidar_range"),
        ({"wait": "nan"}, "option wait"),
        ({"bounds": "1,2,3"}, "option bounds: '1,2,3' is not xmin,ymin,xmax,ymax"),
        ({"bounds": "5,0,1,1"}, "option bounds: xmin < xmax"),
        ({"map": "no/such/file.txt"}, "option map: cannot read"),
        ({"origin": "1"}, "option origin"),
    ],
)
def test_bad_options_raise_a_value_error_naming_them(options: dict[str, str], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make_robot("r1", "", options)


def test_no_router_and_a_silent_base_say_what_to_check(base: FakeBase) -> None:
    with pytest.raises(ValueError, match="zenoh could not open a session"):
        make_robot("r1", "", {"router": free_endpoints(1)[0]})
    with pytest.raises(ValueError, match=r"no odometry on /elsewhere/odom .*rmw_zenohd listens on") as caught:
        make_robot("r1", "", {"router": base.endpoint, "namespace": "/elsewhere", "wait": "0.3"})
    assert "namespace, odom and domain" in str(caught.value)


def test_the_plug_in_loads_the_driver_and_reports_bad_options_in_one_line(
    base: FakeBase, room: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    declared = tomllib.loads(Path("pyproject.toml").read_text(encoding="utf-8"))
    assert declared["project"]["entry-points"]["alica.robots"]["ros2"] == "alica.worldsim.ros2_base:make_robot"
    factory = load_factory("alica.worldsim.ros2_base")
    assert factory is make_robot
    plugin = RobotPlugin("ros2", factory, {"router": base.endpoint, "map": str(room)}, {})
    with base.heartbeat():
        world = plugin.make("r1", "Scout")
    try:
        assert world.bounds == (0.0, 0.0, 6.0, 5.0) and len(world.ground_truth_obstacles()) > 0
    finally:
        close_world(world)
    code = main(["skill", "run", "MoveToPosition", "--robot", "alica.worldsim.ros2_base", "--robot-option", "speed=3"])
    err = capfd.readouterr().err
    assert code != 0 and "making robot 'robot' failed: ValueError: the ros2 base has no option speed" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_move_to_position_drives_the_fake_base_to_the_goal_through_the_driver(base: FakeBase, room: Path) -> None:
    world = connect(base, map=str(room), timeout="60")  # the lock-step pauses the base between ticks
    try:
        lockstep = LockStep(world, base)
        goal = {"goal": [4.5, 4.0], "tolerance": 0.1}  # the straight line crosses the block in the middle
        run = run_skill("MoveToPosition", lockstep, "r1", goal, timeout=60.0)  # type: ignore[arg-type]
        assert run.ok, (run.status, run.reason, run.trace[-5:])
        x, y, _ = base.robot.pose  # where the base really is
        assert math.hypot(x - 4.5, y - 4.0) < 0.15
        assert world.robots["r1"].estimate == pytest.approx(base.robot.pose, abs=1e-6)
        assert len(lockstep.path) > 20 and not base.robot.bumped
        # Around the block (x 2.25..3.25, y 2..3), not through it: the centre keeps well clear of the block. The
        # follower may cut a corner by a few centimetres of the planner's margin, so this is not the full radius.
        clearance = min(
            math.hypot(max(2.25 - px, 0.0, px - 3.25), max(2.0 - py, 0.0, py - 3.0)) for px, py, _ in lockstep.path
        )
        assert clearance > 0.15, clearance
        assert world.dropped == 0 and len(base.twists) > 20  # the skill drove the base by cmd_vel
    finally:
        world.close()
