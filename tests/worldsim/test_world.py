"""World creation, isolation of worlds, determinism, stepping, snapshots and argument errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.clock import ManualClock
from alica.errors import AlicaError
from alica.worldsim.errors import WorldError
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.world import World


def test_defaults(world: World) -> None:
    assert world.seed == 0
    assert world.now() == 0.0
    assert world.bounds == (-10.0, -10.0, 10.0, 10.0)
    assert world.time_step == pytest.approx(1 / 240)
    assert world.objects["ground"].kind == "terrain"
    assert world.robots == {}
    assert isinstance(world.rng, np.random.Generator)
    assert world.client.getConnectionInfo()["connectionMethod"] == world.client.DIRECT


def test_step_runs_whole_physics_steps_and_advances_the_clock() -> None:
    clock = ManualClock(5.0)
    with World(clock=clock) as w:
        assert w.step(0.1) == 24
        assert clock.now() == pytest.approx(5.1)
        # fractions of a step carry over
        n = sum(w.step(0.001) for _ in range(10))
        assert n == 2
        assert w.steps == 26
        assert w.now() == pytest.approx(5.0 + 26 / 240)
        assert w.step(0.0) == 0


def test_two_worlds_do_not_interfere() -> None:
    a, b = World(seed=1), World(seed=1)
    try:
        ra = a.add_robot("scout", "s", (0.0, 0.0, 0.0))
        rb = b.add_robot("scout", "s", (0.0, 0.0, 0.0))
        block = b.add_block("x", (2.0, 2.0, 0.5))  # falls in b only
        ra.drive(1.0, 0.0)
        a.step(1.0)
        assert ra.pose[0] == pytest.approx(1.0, abs=0.01)
        assert rb.pose == (0.0, 0.0, 0.0)
        assert b.now() == 0.0
        assert block.position()[2] == pytest.approx(0.5)
        b.step(1.0)
        assert block.position()[2] == pytest.approx(0.025, abs=1e-3)
        assert "x" not in a.objects
        a.close()
        b.step(0.1)  # still works after the other world closed
        assert rb.pose == (0.0, 0.0, 0.0)
    finally:
        a.close()
        b.close()


def _run(seed: int) -> tuple[list[float], np.ndarray]:
    from alica.worldsim.sensors import lidar_scan

    with World(seed=seed) as w:
        w.faults.set_sensor_noise(lidar_sigma=0.02)
        w.add_rock("rock", (3.0, 1.0), 0.6, seed=4)
        w.add_block("b", (1.0, -1.0, 0.3))
        r = w.add_robot("stummel", "r", (0.0, 0.0, 0.0))
        r.drive(0.6, 0.3)
        r.arm.follow(np.vstack([r.arm.home_q, r.arm.home_q + 0.3]), 1.0)
        w.step(2.0)
        out = [*r.pose, *r.arm.q(), *w.objects["b"].position()]
        return out, lidar_scan(r)


def test_same_seed_same_state() -> None:
    s1, scan1 = _run(3)
    s2, scan2 = _run(3)
    assert s1 == s2
    assert np.array_equal(scan1, scan2)
    _, scan3 = _run(4)
    assert not np.array_equal(scan1, scan3)  # other noise draws


def test_save_and_restore_state(world: World) -> None:
    r = world.add_robot("manipulator", "r", (0.0, 0.0, 0.0))
    block = world.add_block("b", (1.0, 1.0))
    world.step(0.1)
    sid = world.snapshots.save()
    before = (r.pose, r.arm.q(), block.position())
    r.drive(0.5, 0.2)
    r.arm.set_q(r.arm.home_q + 0.2)
    world.client.resetBasePositionAndOrientation(block.body_id, (2.0, 2.0, 1.0), (0, 0, 0, 1))
    world.step(0.5)
    world.snapshots.restore(sid)
    assert r.pose == before[0]
    assert np.allclose(r.arm.q(), before[1])
    assert np.allclose(block.position(), before[2], atol=1e-9)
    assert r.velocity == (0.0, 0.0)
    with pytest.raises(WorldError, match="unknown state id"):
        world.snapshots.restore(sid + 100)
    world.add_block("new", (2.0, 2.0))
    with pytest.raises(WorldError, match="save a new state after adding bodies"):
        world.snapshots.restore(sid)


def test_restore_state_while_holding(world: World) -> None:
    r = world.add_robot("manipulator", "r", (0.0, 0.0, 0.0))
    block = world.add_block("b", (1.0, 1.0))
    sid = world.snapshots.save()
    ee = r.arm.ee_pose()[0]
    world.client.resetBasePositionAndOrientation(block.body_id, ee.tolist(), (0, 0, 0, 1))
    assert r.arm.attach(block)
    world.step(0.2)
    world.snapshots.restore(sid)
    assert r.arm.held is None
    world.step(0.5)
    assert block.position() == pytest.approx([1.0, 1.0, 0.025], abs=2e-3)


def test_ground_truth_obstacles(world: World) -> None:
    world.add_rock("rock", (3.0, 1.0), 0.6)
    world.add_table("table", (-3.0, 0.0), size=(1.0, 0.5), yaw=0.5)
    world.add_block("b", (0.0, 3.0))
    world.add_sample("s", "green-black-red", (0.0, -3.0))
    world.add_collection_point("g", (5.0, 5.0))
    obstacles = {o.name: o for o in world.ground_truth_obstacles()}
    assert set(obstacles) == {"rock", "table", "b"}
    assert all(isinstance(o, Obstacle2D) for o in obstacles.values())
    assert obstacles["rock"] == Obstacle2D("circle", 3.0, 1.0, radius=0.6, name="rock")
    table = obstacles["table"]
    assert (table.kind, table.half_x, table.half_y) == ("box", 0.5, 0.25)
    assert table.yaw == pytest.approx(0.5)
    assert obstacles["b"].kind == "box" and obstacles["b"].half_x == pytest.approx(0.025)
    names = {o.name for o in world.ground_truth_obstacles(include_samples=True)}
    assert "s" in names


def test_remove_and_names(world: World) -> None:
    world.add_robot("stummel", "s", (0.0, 0.0, 0.0))
    world.add_block("b", (2.0, 2.0))
    world.remove("s")
    world.remove("b")
    assert "s" not in world.robots and "b" not in world.objects
    world.add_robot("stummel", "s", (0.0, 0.0, 0.0))  # the name is free again


def test_gui_without_display_runs_direct(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    with World(gui=True) as w:
        assert w.client.getConnectionInfo()["connectionMethod"] == w.client.DIRECT


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda w: w.add_robot("rover", "x"),
            "unknown robot kind 'rover'; use one of scout, stummel, amparo, manipulator",
        ),
        (lambda w: w.add_robot("scout", "ground"), "the name 'ground' is taken by a terrain"),
        (lambda w: w.add_robot("scout", "far", (50.0, 0.0, 0.0)), "off the field"),
        (lambda w: w.add_robot("scout", "edge", (9.9, 0.0, 0.0)), "with its radius"),
        (lambda w: w.add_robot("scout", "p", (0.0, 0.0)), r"\(x, y, yaw\)"),
        (lambda w: w.add_block("b", (0.0, 0.0), size=-1.0), "positive number of metres"),
        (lambda w: w.add_block("b", (0.0, 0.0), colour="mauve"), "unknown colour 'mauve'"),
        (lambda w: w.add_sample("s", "blue-black-red", (0.0, 0.0)), "unknown sample kind"),
        (lambda w: w.add_rock("r", (11.0, 0.0), 0.5), "off the field"),
        (lambda w: w.step(-1.0), "duration >= 0"),
        (lambda w: w.remove("nobody"), "no robot or object named 'nobody'"),
        (lambda w: w.faults.set_grasp_slip(1.5), r"probability in \[0, 1\]"),
        (lambda w: w.faults.set_sensor_noise(lidar_sigma=-1.0), "standard deviation"),
    ],
)
def test_bad_arguments_raise_world_error(world: World, call, match: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(WorldError, match=match) as info:
        call(world)
    assert isinstance(info.value, AlicaError) and isinstance(info.value, ValueError)


def test_overlapping_robot_is_refused(world: World) -> None:
    world.add_rock("rock", (2.0, 0.0), 0.5)
    world.add_robot("scout", "a", (0.0, 0.0, 0.0))
    with pytest.raises(WorldError, match="would overlap robot 'a'"):
        world.add_robot("scout", "b", (0.3, 0.0, 0.0))
    with pytest.raises(WorldError, match="would overlap rock 'rock'"):
        world.add_robot("scout", "c", (2.5, 0.3, 0.0))


def test_bad_world_arguments() -> None:
    with pytest.raises(WorldError, match="time_step"):
        World(time_step=0.0)
    with pytest.raises(WorldError, match="bounds"):
        World(bounds=(0.0, 0.0, -1.0, 1.0))


def test_closed_world() -> None:
    w = World()
    w.close()
    w.close()  # idempotent
    assert w.closed
    with pytest.raises(WorldError, match="closed"):
        w.step(0.1)


def test_contacts(world: World) -> None:
    r = world.add_robot("scout", "s", (0.0, 0.0, 0.0))
    world.add_block("b", (0.28, 0.0))  # 5 mm from the base
    world.add_block("far", (3.0, 0.0))
    assert world.contacts(r) == set()
    assert world.contacts(r, margin=0.01) == {"b"}
    assert "ground" in world.contacts(r, margin=0.01, include_ground=True)
    assert math.isfinite(r.pose[0])


def test_the_field_checks_positions() -> None:
    from alica.worldsim.field import Field

    field = Field((-1.0, -2.0, 3.0, 4.0))
    assert field.inside(0.0, 0.0) and field.inside(3.0, 4.0) and not field.inside(2.5, 0.0, radius=1.0)
    field.check(0.0, 0.0, "block 'b'")
    with pytest.raises(WorldError, match=r"block 'b' at \(5.0, 0.0\) is off the field"):
        field.check(5.0, 0.0, "block 'b'")
    with pytest.raises(WorldError, match="with its radius 1.0 m"):
        field.check(2.5, 0.0, "robot 'r'", 1.0)
    with pytest.raises(WorldError, match="off the field"):
        field.check(float("nan"), 0.0, "robot 'r'")
