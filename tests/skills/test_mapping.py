"""Mapping and localization: the log-odds grid, the team map through the world model, BuildMap, Localize."""

from __future__ import annotations

import math
from itertools import permutations

import numpy as np
import pytest

from alica.errors import SkillError
from alica.skills.mapping import FREE, OCCUPIED, TILE, UNKNOWN, LogOddsGrid, RobotMapper, match_scan, team_map
from alica.skills.mapping.sharing import decode_tile, encode_tile
from alica.skills.testing import map_agreement, map_truth
from alica.worldmodel import WorldModel
from tests.worldmodel.test_worldmodel_partition import gossip

pytest.importorskip("pybullet")


def _angles(n: int) -> np.ndarray:
    return -math.pi + (2.0 * math.pi / n) * np.arange(n)


def _box_scan(pose: tuple[float, float, float], n: int = 720, half: float = 2.0) -> np.ndarray:
    """Ranges from ``pose`` to the walls of the square [-half, half]^2 (a hand-made room)."""
    x, y, yaw = pose
    a = yaw + _angles(n)
    c, s = np.cos(a), np.sin(a)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (half - x) / c, np.where(c < 0, (-half - x) / c, np.inf))
        ty = np.where(s > 0, (half - y) / s, np.where(s < 0, (-half - y) / s, np.inf))
    return np.minimum(tx, ty)


def test_a_scan_marks_free_cells_along_the_rays_and_occupied_cells_at_the_hits() -> None:
    grid = LogOddsGrid.covering((-3.0, -3.0, 3.0, 3.0), 0.1)
    ranges = _box_scan((0.0, 0.0, 0.0))
    updated = grid.update((0.0, 0.0, 0.0), ranges, _angles(720), max_range=5.0)
    occ = grid.occupancy()
    assert updated > 0 and occ.dtype == np.int8
    assert occ[grid.world_to_cell(0.5, 0.5)[::-1]] == FREE
    assert occ[grid.world_to_cell(2.02, 0.3)[::-1]] == OCCUPIED  # the wall x = 2
    assert occ[grid.world_to_cell(2.6, 0.3)[::-1]] == UNKNOWN  # behind it
    assert grid.cell_to_world(*grid.world_to_cell(0.25, -0.25)) == pytest.approx((0.25, -0.25))
    # repeated scans saturate at the clamp
    for _ in range(30):
        grid.update((0.0, 0.0, 0.0), ranges, _angles(720), max_range=5.0)
    assert grid.logodds.min() >= -4.0 and grid.logodds.max() <= 4.0
    assert grid.take_dirty_tiles() and not grid.take_dirty_tiles()


def _traced(grid: LogOddsGrid, pose, ranges, angles, max_range: float) -> np.ndarray:
    """The cells a scan updates, sampled the plain way: every ray at every half cell (the reference)."""
    x, y, yaw = pose
    res, (ox, oy) = grid.resolution, grid.origin
    hit = np.isfinite(ranges) & (ranges < max_range)
    reach = np.where(hit, np.maximum(ranges, 0.0), max_range)
    c, s = np.cos(yaw + angles), np.sin(yaw + angles)
    along = np.arange(0.0, float(reach.max()), 0.5 * res)
    keep = along[None, :] < reach[:, None]
    fi = np.floor((x + c[:, None] * along[None, :] - ox) / res).astype(np.intp)[keep]
    fj = np.floor((y + s[:, None] * along[None, :] - oy) / res).astype(np.intp)[keep]
    ok = (fi >= 0) & (fi < grid.nx) & (fj >= 0) & (fj < grid.ny)
    out = np.zeros((grid.ny, grid.nx), dtype=np.int8)
    out[fj[ok], fi[ok]] = -1
    hi = np.floor((x + c[hit] * reach[hit] - ox) / res).astype(np.intp)
    hj = np.floor((y + s[hit] * reach[hit] - oy) / res).astype(np.intp)
    ok = (hi >= 0) & (hi < grid.nx) & (hj >= 0) & (hj < grid.ny)
    out[hj[ok], hi[ok]] = 1
    return out


@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.3), (3.7, -3.2, -2.0), (-4.9, 4.95, 1.0)])
def test_a_scan_updates_the_cells_of_every_half_cell_sample_inside_the_grid_or_at_its_edge(pose) -> None:
    rng = np.random.default_rng(7)
    angles = np.linspace(-math.pi, math.pi, 400, endpoint=False)
    ranges = np.where(rng.random(400) < 0.3, 3.0, rng.uniform(0.1, 3.5, 400))
    ranges[::37] = np.inf
    grid = LogOddsGrid.covering((-5.0, -5.0, 5.0, 5.0), 0.05)
    grid.update(pose, ranges, angles, max_range=3.0)
    expected = _traced(grid, pose, ranges, angles, 3.0)
    assert np.array_equal(np.sign(grid.logodds).astype(np.int8), expected)


def test_the_grid_refuses_bad_input() -> None:
    with pytest.raises(ValueError, match="resolution"):
        LogOddsGrid.covering((0, 0, 1, 1), 0.0)
    with pytest.raises(ValueError, match="bounds"):
        LogOddsGrid.covering((0, 0, 0, 1), 0.1)
    grid = LogOddsGrid.covering((0, 0, 1, 1), 0.1)
    with pytest.raises(ValueError, match="same length"):
        grid.update((0.5, 0.5, 0.0), np.ones(3), np.zeros(4), 1.0)
    with pytest.raises(ValueError, match="max_range"):
        grid.update((0.5, 0.5, 0.0), np.ones(3), np.zeros(3), -1.0)


def test_tiles_round_trip_within_a_quantum() -> None:
    tile = np.random.default_rng(0).uniform(-4.0, 4.0, (TILE, TILE)).astype(np.float32)
    back = decode_tile(encode_tile(tile), tile.shape)
    assert np.abs(back - tile).max() <= 0.05 + 1e-6
    with pytest.raises(ValueError, match="not a map tile|cells where"):
        decode_tile(encode_tile(tile), (3, 3))


def test_icp_pulls_a_wrong_estimate_onto_the_map() -> None:
    grid = LogOddsGrid.covering((-3.0, -3.0, 3.0, 3.0), 0.05)
    # an L-shaped room with a pillar: no symmetry for ICP to slide along
    truth = (0.3, -0.2, 0.4)
    ranges = _box_scan(truth, n=1440)
    ranges[200:260] = 0.8  # a pillar
    for _ in range(3):
        grid.update(truth, ranges, _angles(1440), max_range=5.0)
    match = match_scan(grid, (0.5, -0.05, 0.45), ranges, _angles(1440), 5.0)
    assert match.ok, match.reason
    assert math.hypot(match.pose[0] - truth[0], match.pose[1] - truth[1]) < 0.05
    assert abs(match.pose[2] - truth[2]) < math.radians(1.0)
    empty = LogOddsGrid.covering((-3.0, -3.0, 3.0, 3.0), 0.05)
    assert not match_scan(empty, truth, ranges, _angles(1440), 5.0).ok


# -- the simulated field -----------------------------------------------------------


def _build(world, robot: str, wm: WorldModel, skill_run, **params: object):
    run = skill_run("BuildMap", world, robot, {"resolution": 0.05, "radius": 5.0, **params}, world_model=wm)
    assert run.ok, run.reason
    return run


def test_build_map_matches_the_ground_truth(lunar_world, skill_run) -> None:
    wm = WorldModel("scout", clock=lunar_world.clock)
    run = _build(lunar_world, "scout", wm, skill_run)
    assert run.holds("mapped")
    grid = team_map(wm)
    assert grid is not None and grid.resolution == 0.05
    occ = grid.occupancy()
    x, y, _ = lunar_world.robots["scout"].pose
    assert grid.known_fraction(x, y, 5.0) >= 0.8
    assert (occ == OCCUPIED).sum() > 50 and (occ == FREE).sum() > 10_000
    assert map_agreement(occ, map_truth(lunar_world, grid, skip=("scout",))) >= 0.95


def test_maps_built_apart_in_a_partition_converge_when_it_heals_and_a_late_joiner_gets_them(
    lunar_world, skill_run
) -> None:
    world = lunar_world
    scout, stummel = WorldModel("scout", clock=world.clock), WorldModel("stummel", clock=world.clock)
    # a shared start: scout maps first, the frame and its tiles reach stummel
    _build(world, "scout", scout, skill_run)
    gossip([scout, stummel])
    before = team_map(stummel)
    assert before is not None and np.array_equal(before.logodds, team_map(scout).logodds)  # type: ignore[union-attr]
    # the partition: each maps somewhere else
    world.robots["scout"].set_pose(8.0, 8.0, 0.0)
    world.robots["stummel"].set_pose(-8.0, -8.0, 0.0)
    _build(world, "scout", scout, skill_run)
    _build(world, "stummel", stummel, skill_run)
    a, b = team_map(scout).occupancy().copy(), team_map(stummel).occupancy().copy()  # type: ignore[union-attr]
    assert not np.array_equal(a, b)
    scout_cell = team_map(scout).world_to_cell(9.0, 8.0)[::-1]  # type: ignore[union-attr]
    stummel_cell = team_map(scout).world_to_cell(-7.0, -8.0)[::-1]  # type: ignore[union-attr]
    assert a[scout_cell] == FREE and b[scout_cell] == UNKNOWN
    assert b[stummel_cell] == FREE and a[stummel_cell] == UNKNOWN
    # the heal: digests answered both ways
    for receiver, sender in permutations([scout, stummel], 2):
        receiver.merge(sender.missing_for(receiver.digest()))
    ma, mb = team_map(scout), team_map(stummel)
    assert ma is not None and mb is not None and np.array_equal(ma.logodds, mb.logodds)
    merged = ma.occupancy()
    assert merged[scout_cell] == FREE and merged[stummel_cell] == FREE
    # nothing seen on either side is lost
    assert np.all(merged[a >= 0] >= 0) and np.all(merged[b >= 0] >= 0)
    # a late joiner gets the whole map from a snapshot
    amparo = WorldModel("amparo", clock=world.clock)
    amparo.merge(scout.snapshot())
    late = team_map(amparo)
    assert late is not None and np.array_equal(late.logodds, ma.logodds)
    # and a robot that starts its skill again continues its own layer
    layer = RobotMapper.for_robot(scout, "scout", world.bounds, 0.05).layer
    assert (np.abs(layer.logodds) > 0.2).sum() > 10_000


def test_localize_corrects_a_drifting_odometry(lunar_world, skill_run) -> None:
    world = lunar_world
    wm = WorldModel("scout", clock=world.clock)
    _build(world, "scout", wm, skill_run, max_range=10.0)
    world.faults.set_sensor_noise(odometry_drift=0.05)
    robot = world.robots["scout"]
    robot.drive(0.6, 0.5)  # a circle through the start area, about 4 m
    world.step(7.0)
    robot.drive(0.0, -0.8)
    world.step(3.0)
    robot.stop()
    error = math.hypot(robot.pose[0] - robot.estimate[0], robot.pose[1] - robot.estimate[1])
    heading = abs(math.remainder(robot.pose[2] - robot.estimate[2], 2 * math.pi))
    assert error > 0.05 or heading > math.radians(2.0)  # the odometry drifted
    run = skill_run("Localize", world, "scout", {}, world_model=wm)
    assert run.ok, run.reason
    assert math.hypot(robot.pose[0] - robot.estimate[0], robot.pose[1] - robot.estimate[1]) < 0.05
    assert abs(math.remainder(robot.pose[2] - robot.estimate[2], 2 * math.pi)) < math.radians(1.0)


def test_localize_alone_starts_the_map_where_it_stands(lunar_world, skill_run) -> None:
    run = skill_run("Localize", lunar_world, "scout", {})
    assert run.ok, run.reason
    robot = lunar_world.robots["scout"]
    assert math.hypot(robot.estimate[0] - robot.pose[0], robot.estimate[1] - robot.pose[1]) < 0.03
    assert run.holds("map_robots", "scout")


@pytest.mark.parametrize(
    ("skill", "params", "message"),
    [
        ("BuildMap", {"resolution": -0.1}, "parameter 'resolution'"),
        ("BuildMap", {"resolution": 2.0}, "parameter 'resolution'"),
        ("BuildMap", {"radius": 0.0}, "parameter 'radius'"),
        ("BuildMap", {"radius": 12.0, "max_range": 5.0}, "parameter 'max_range'"),
        ("BuildMap", {"resolution": "fine"}, "parameter 'resolution'"),
        ("Localize", {"period": 0.0}, "parameter 'period'"),
        ("Localize", {"timeout": -1.0}, "parameter 'timeout'"),
        ("Localize", {"continuous": "yes"}, "parameter 'continuous'"),
    ],
)
def test_bad_parameters_give_clear_errors(lunar_world, skill_run, skill: str, params: dict, message: str) -> None:
    with pytest.raises(SkillError, match=message):
        skill_run(skill, lunar_world, "scout", params)


def test_a_second_resolution_on_the_same_team_map_is_refused(lunar_world, skill_run) -> None:
    wm = WorldModel("scout", clock=lunar_world.clock)
    _build(lunar_world, "scout", wm, skill_run)
    with pytest.raises(SkillError, match="resolution"):
        skill_run("BuildMap", lunar_world, "scout", {"resolution": 0.1}, world_model=wm)
