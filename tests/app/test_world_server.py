"""The world server and the remote robot (issue 38): calls, lock-step, refusals, bad frames, faults.

Each test serves a small world from a thread of the test process (or a
subprocess, killed in ``finally``) on a free loopback endpoint under a key
prefix of its own; every wait is bounded.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
import zenoh

from alica.app.world_server import RemoteWorld, WorldServer, wire
from alica.comm.zenoh_transport import free_endpoints, zenoh_config
from alica.worldsim.errors import WorldError
from alica.worldsim.interface import RobotWorld
from alica.worldsim.scenarios import blocksworld, lunar
from alica.worldsim.world import World


def _lunar(seed: int = 1) -> World:
    return lunar(seed=seed, rocks=6, samples=1, size=20.0)


@contextlib.contextmanager
def _served(world: World, **options: object) -> Iterator[tuple[WorldServer, str, str]]:
    """A server of ``world`` in a thread: ``(server, endpoint, prefix)``; stopped and closed afterwards."""
    endpoint = free_endpoints(1)[0]
    prefix = f"t{uuid.uuid4().hex[:8]}"
    server = WorldServer(world, listen=[endpoint], prefix=prefix, **options)  # type: ignore[arg-type]
    failed: list[BaseException] = []

    def run() -> None:
        try:
            server.serve()
        except BaseException as exc:  # (reported by the test below)
            failed.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    try:
        yield server, endpoint, prefix
    finally:
        server.stop()
        thread.join(5.0)
        server.close()
        world.close()
    assert not thread.is_alive()
    assert not failed, failed


def _until(check: Callable[[], bool], seconds: float = 5.0) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if check():
            return True
        time.sleep(0.02)
    return check()


def test_a_client_drives_its_robot_and_reads_its_sensors() -> None:
    with _served(_lunar(), speed=4.0) as (_server, endpoint, prefix):
        with RemoteWorld([endpoint], "scout", prefix=prefix) as world:
            assert isinstance(world, RobotWorld)
            robot = world.robots["scout"]
            assert set(world.robots) == {"scout", "stummel", "amparo"}
            assert robot.spec.kind == "scout" and robot.arm is None
            assert world.robots["stummel"].arm is not None
            start, t0 = robot.pose, world.now()
            robot.drive(0.4, 0.0)
            assert _until(lambda: robot.pose[0] > start[0] + 0.1)
            assert world.now() > t0
            robot.stop()
            scan = robot.lidar(90)
            assert scan.shape == (90,) and np.all(scan > 0)
            assert robot.lidar_angles(90).shape == (90,)
            image = robot.camera(width=32, height=24)
            assert image.rgb.shape == (24, 32, 3) and image.depth.shape == (24, 32)
            position, rotation = robot.camera_pose()
            assert position.shape == (3,) and rotation.shape == (3, 3)
            kinds = {obj.kind for obj in world.objects.values()}
            assert {"rock", "sample", "collection_point"} <= kinds
            rock = next(o for o in world.objects.values() if o.kind == "rock")
            assert rock.footprint() is not None and rock.world_mesh() is not None
            assert world.ground_truth_obstacles()
            assert world.blocker(*world.objects[rock.name].position()[:2], 0.1) == f"rock '{rock.name}'"
            assert not world.lockstep
            with pytest.raises(WorldError, match="not in lock-step"):
                world.tick_done()


def test_the_arm_of_a_remote_robot_reads_its_own_writes() -> None:
    with _served(_lunar()) as (_server, endpoint, prefix), RemoteWorld([endpoint], "stummel", prefix=prefix) as world:
        arm = world.robots["stummel"].arm
        assert arm is not None
        q0 = arm.q()
        path = np.array([q0, q0 + np.array([0.2, 0, 0, 0, 0, 0, 0])])
        duration = arm.follow(path)
        assert duration > 0 and arm.busy  # at once, not only after the next state
        assert _until(lambda: not arm.busy)
        assert arm.q()[0] == pytest.approx(q0[0] + 0.2, abs=1e-6)
        assert arm.held is None and arm.grip_force() == 0.0
        arm.open()
        scene = arm.planning_scene()  # the agent's own kinematic model
        assert np.allclose(scene.base_pose()[0], arm.base_pose()[0])


def _run_skill(world: RemoteWorld, robot: str, name: str, params: dict[str, object], ticks: int) -> str:
    """Run a shipped skill on the remote robot, one tick per lock-step; its status and reason."""
    from alica.skills.testing import SkillSession, resolve_registry

    session = SkillSession(name, world, robot, params, resolve_registry(None, (), "test"))  # type: ignore[arg-type]
    for _ in range(ticks):
        if session.tick():
            break
        world.tick_done(timeout=5.0)
    result = session.result()
    return f"{result.status}: {result.reason}"


def test_shipped_skills_run_on_a_remote_robot_as_on_a_local_one() -> None:
    with (
        _served(_lunar(), lockstep=True, frequency=10.0) as (_server, endpoint, prefix),
        RemoteWorld([endpoint], "scout", prefix=prefix) as world,
    ):
        assert _run_skill(world, "scout", "MoveToPosition", {"goal": [4.0, 3.0]}, 300).startswith("success")
        x, y, _ = world.robots["scout"].pose
        assert math.hypot(x - 4.0, y - 3.0) < 0.5
    with (
        _served(blocksworld([["a", "b"], ["c"]], agents=1), lockstep=True, frequency=10.0) as (_s, endpoint, prefix),
        RemoteWorld([endpoint], "r1", prefix=prefix) as world,
    ):
        assert _run_skill(world, "r1", "Unstack", {"object": "b", "from": "a"}, 600).startswith("success")
        assert ("holding", "r1", "b") in world.blocks_facts()
        assert _run_skill(world, "r1", "Putdown", {"object": "b"}, 600).startswith("success")
        assert {("ontable", "b"), ("handempty", "r1")} <= world.blocks_facts()


Outcome = dict[str, tuple[tuple[float, float, float], list[float], list[int]]]


def _lockstep_run(seed: int, steps: int) -> tuple[Outcome, float]:
    """Two agents, each in a thread of its own, drive, scan and look every tick; what each ended with."""
    agents = {"scout": (0.5, (-0.6, 0.0, 0.9)), "stummel": (0.3, (0.4, -0.2))}
    outcome: Outcome = {}
    with _served(_lunar(seed), lockstep=True, agents=list(agents)) as (_server, endpoint, prefix):
        worlds = {name: RemoteWorld([endpoint], name, prefix=prefix) for name in agents}
        t0 = worlds["scout"].now()
        failed: list[BaseException] = []

        def agent(name: str) -> None:
            world, (v, turns) = worlds[name], agents[name]
            robot = world.robots[name]
            try:
                for k in range(steps):
                    robot.drive(v, turns[k % len(turns)])
                    scan = robot.lidar(36)  # (streamed from the second tick on)
                    picture = robot.camera(width=16, height=12) if k % 5 == 0 else None
                    if picture is not None:
                        outcome.setdefault(name, (robot.pose, [], []))[2].append(int(picture.rgb.sum()))
                    world.tick_done(timeout=5.0)
                pictures = outcome.get(name, ((0.0, 0.0, 0.0), [], []))[2]
                outcome[name] = (robot.pose, scan.tolist(), pictures)
            except BaseException as exc:
                failed.append(exc)

        threads = [threading.Thread(target=agent, args=(name,)) for name in agents]
        try:
            for t in threads:
                t.start()
            for t in threads:
                t.join(30.0)
        finally:
            for world in worlds.values():
                world.close()
        assert not failed, failed
        elapsed = worlds["scout"].period * steps
        assert all(world.now() == pytest.approx(t0 + elapsed) for world in worlds.values())
    return outcome, elapsed


def test_lock_step_repeats_with_the_same_seed() -> None:
    first, elapsed = _lockstep_run(3, 25)
    second, _ = _lockstep_run(3, 25)
    assert first == second
    assert first["scout"][0] != (1.5, 0.0, 0.0) and elapsed > 0.8


def test_a_robot_answers_only_its_own_agent() -> None:
    with _served(_lunar()) as (server, endpoint, prefix), RemoteWorld([endpoint], "scout", prefix=prefix) as world:
        other = world.robots["stummel"]
        before = other.pose
        with pytest.raises(WorldError, match="answers only its own agent, not 'scout'"):
            other.drive(1.0, 0.0)
        with pytest.raises(WorldError, match="answers only its own agent"):
            other.lidar(10)
        assert server.stats.refused == 2
        time.sleep(0.1)
        assert other.pose == before


def test_a_malformed_payload_is_counted_and_refused_not_fatal() -> None:
    with _served(_lunar()) as (server, endpoint, prefix):
        session = zenoh.open(zenoh_config((endpoint,), (), "peer", 2.0, None))
        try:
            head = json.dumps({"caller": "scout", "call": "drive", "args": {"v": "fast", "w": 0}}).encode()
            nan = b'{"caller": "scout", "call": "drive", "args": {"v": NaN, "w": 0}}'
            bad = [
                b"xx",
                (1 << 30).to_bytes(4, "little") + b"{}",
                len(nan).to_bytes(4, "little") + nan,
                len(head).to_bytes(4, "little") + head,
                wire.encode({"caller": "scout", "call": "lidar", "args": {"n_rays": 10**9}}),
                wire.encode({"caller": "../scout", "call": "drive"}),
            ]
            for payload in bad:
                replies = list(session.get(wire.robot_key(prefix, "scout"), payload=payload, timeout=2.0))
                assert len(replies) == 1 and replies[0].ok is not None
                answer = wire.decode(replies[0].ok.payload.to_bytes()).header
                assert answer["ok"] is False and "malformed" in answer["error"]
            assert sum(server.stats.rejected.values()) == len(bad)
            own = free_endpoints(1)[0]
            with RemoteWorld([endpoint], "scout", prefix=prefix, listen=[own]) as world:  # the server still serves
                world.robots["scout"].drive(0.1, 0.0)
                liar = zenoh.open(zenoh_config((own,), (), "peer", 2.0, None))  # (a peer of the client's)
                time.sleep(0.3)
                forged = wire.encode({"server": 1, "version": 2**40, "step": 0, "t": -5.0, "robots": {}})
                for garbage in (b"\xff" * 9, forged):  # where clients listen
                    liar.put(wire.state_key(prefix), garbage)
                liar.close()
                assert _until(lambda: sum(world.rejected.values()) == 2)
                assert world.now() >= 0 and world.robots["scout"].pose is not None
        finally:
            session.close()


def test_wire_refuses_what_it_cannot_check() -> None:
    frame = wire.decode(wire.encode({"a": [1, 2.5]}, {"x": np.arange(6, dtype=np.float64).reshape(2, 3)}))
    assert frame.header == {"a": [1, 2.5]} and frame.arrays["x"].shape == (2, 3)
    good = wire.encode({}, {"x": np.zeros(4)})
    deep = b"[" * 100_000 + b"]" * 100_000
    for broken, reason in [
        (good[:-1], "array"),
        (good + b"\0", "array"),
        (b"\0" * 3, "size"),
        (b"\x02\0\0\0[]", "json"),
        (len(deep).to_bytes(4, "little") + deep, "json"),
    ]:
        with pytest.raises(wire.BadPayload) as caught:
            wire.decode(broken)
        assert caught.value.reason == reason, broken
    with pytest.raises(wire.BadPayload, match="finite"):
        wire.number(math.inf, "v")
    with pytest.raises(wire.BadPayload, match="must be a number"):
        wire.number(True, "v")


def test_with_team_credentials_an_agent_cannot_even_ask_another_robot(tmp_path: Path) -> None:
    from alica.app.world_server.access import WORLD, world_settings
    from alica.comm.credentials import TeamKeys, make_keys, tls_endpoint

    folder = tmp_path / "keys"
    make_keys(folder, ["scout", "stummel", WORLD])
    endpoint = tls_endpoint(free_endpoints(1)[0])
    prefix = f"t{uuid.uuid4().hex[:8]}"
    world = _lunar()
    server = WorldServer(
        world, listen=[endpoint], prefix=prefix, settings=world_settings(TeamKeys.load(folder, WORLD), prefix)
    )
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    try:
        own = world_settings(TeamKeys.load(folder, "scout"), prefix)
        with RemoteWorld([endpoint], "scout", prefix=prefix, settings=own, wait=10.0) as scout:
            robot = scout.robots["scout"]
            robot.drive(0.2, 0.0)
            assert robot.lidar(8).shape == (8,)
            with pytest.raises(WorldError, match="nobody took drive of robot 'stummel'"):
                scout.robots["stummel"].drive(1.0, 0.0)
        with RemoteWorld([endpoint], "stummel", prefix=prefix, settings=own, wait=5.0) as liar:
            with pytest.raises(WorldError, match="nobody took"):  # scout's keys, stummel's name
                liar.robots["stummel"].drive(1.0, 0.0)
        assert server.stats.refused == 0  # (refused by zenoh on arrival, before the server's own check)
    finally:
        server.stop()
        thread.join(5.0)
        server.close()
        world.close()


_AGENT = """
import sys, time
from alica.app.world_server import RemoteWorld
world = RemoteWorld([sys.argv[1]], "stummel", prefix=sys.argv[2])
print("open", flush=True)
time.sleep(60)
"""


def test_an_agent_killed_is_its_robots_crash_and_its_return_a_recovery() -> None:
    with (
        _served(_lunar()) as (server, endpoint, prefix),
        RemoteWorld([endpoint], "scout", prefix=prefix) as observer,
    ):
        stummel = observer.robots["stummel"]
        agent = subprocess.Popen([sys.executable, "-c", _AGENT, endpoint, prefix], stdout=subprocess.PIPE, text=True)
        try:
            assert agent.stdout is not None and agent.stdout.readline().strip() == "open"
            assert not stummel.crashed
            os.kill(agent.pid, signal.SIGKILL)
            agent.wait(5.0)
            assert _until(lambda: stummel.crashed), "the killed agent's robot did not crash"
            assert server.stats.crashes == 1
        finally:
            if agent.poll() is None:
                agent.kill()
                agent.wait(5.0)
        with RemoteWorld([endpoint], "stummel", prefix=prefix):  # the agent restarted
            assert _until(lambda: not stummel.crashed), "the returning agent's robot did not recover"
        assert server.stats.recoveries == 1


def test_a_dead_server_gives_a_clear_world_error_and_the_client_reconnects() -> None:
    endpoint = free_endpoints(1)[0]
    prefix = f"t{uuid.uuid4().hex[:8]}"
    with pytest.raises(WorldError, match="no world server at .* answered within 0.5 s"):
        RemoteWorld([endpoint], "scout", prefix=prefix, wait=0.5)
    world = _lunar()
    server = WorldServer(world, listen=[endpoint], prefix=prefix)
    thread = threading.Thread(target=server.serve, daemon=True)
    thread.start()
    client = RemoteWorld([endpoint], "scout", prefix=prefix, timeout=1.0)
    try:
        robot = client.robots["scout"]
        robot.drive(0.1, 0.0)
        server.stop()
        thread.join(5.0)
        server.close()
        start = time.monotonic()
        with pytest.raises(
            WorldError, match=r"the world server at tcp/127\.0\.0\.1:\d+ \(key prefix 't\w+'\) does not"
        ):
            _until(lambda: (robot.drive(0.0, 0.0), False)[1], 3.0)
        assert time.monotonic() - start < 3.5
        with pytest.raises(WorldError, match="does not answer"):
            _ = robot.pose
        server = _reopen(world, endpoint, prefix)  # it comes back
        thread = threading.Thread(target=server.serve, daemon=True)
        thread.start()

        def answers() -> bool:
            try:
                robot.drive(0.0, 0.0)
            except WorldError:
                return False
            return True

        assert _until(answers, 10.0), "the client did not reconnect to the server that came back"
        assert robot.pose is not None
    finally:
        client.close()
        server.stop()
        thread.join(5.0)
        server.close()
        world.close()


def _reopen(world: World, endpoint: str, prefix: str) -> WorldServer:
    """A new server on the endpoint a closed one left (the port may take a moment to be free again)."""
    end = time.monotonic() + 10.0
    while True:
        try:
            return WorldServer(world, listen=[endpoint], prefix=prefix)
        except WorldError:
            if time.monotonic() > end:
                raise
            time.sleep(0.1)


def test_alica_world_serve_in_a_process_serves_a_lock_step_world() -> None:
    endpoint = free_endpoints(1)[0]
    prefix = f"t{uuid.uuid4().hex[:8]}"
    argv = [sys.executable, "-m", "alica.app.cli", "world", "serve", "--world", "lunar", "--rocks", "4"]
    argv += ["--size", "20", "--samples", "1", "--lockstep", "--listen", endpoint, "--key-prefix", prefix, "--json"]
    server = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert server.stdout is not None
        started = json.loads(server.stdout.readline())
        assert started["event"] == "serving" and started["lockstep"] is True
        with RemoteWorld([endpoint], "amparo", prefix=prefix, wait=10.0) as world:
            robot = world.robots["amparo"]
            t0 = world.now()
            robot.drive(0.3, 0.0)
            for _ in range(5):
                world.tick_done(timeout=5.0)
            assert world.now() == pytest.approx(t0 + 5 / 30)
        server.send_signal(signal.SIGTERM)
        out, _err = server.communicate(timeout=10.0)
        stopped = json.loads(out.strip().splitlines()[-1])
        assert stopped["event"] == "stopped" and stopped["steps"] == 5
        assert server.returncode == 0
    finally:
        if server.poll() is None:
            server.kill()
            server.wait(5.0)
