"""OccupancyGrid and Obstacle2D: rasterisation, inflation, coordinates, outside = occupied."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.worldsim.grid import FREE, OCCUPIED, UNKNOWN, Obstacle2D, OccupancyGrid

RES = 0.05
DIAG = RES * math.sqrt(2.0)


def centres(grid: OccupancyGrid) -> tuple[np.ndarray, np.ndarray]:
    xs = grid.origin[0] + (np.arange(grid.width) + 0.5) * grid.resolution
    ys = grid.origin[1] + (np.arange(grid.height) + 0.5) * grid.resolution
    return np.meshgrid(xs, ys)


def test_circle_rasterisation_inside_occupied_outside_free() -> None:
    circle = Obstacle2D("circle", 1.03, -0.51, radius=0.7)
    for conservative, grow in ((False, 0.0), (True, 0.5 * DIAG)):
        grid = OccupancyGrid.from_obstacles([circle], (-3, -3, 3, 3), RES, conservative=conservative)
        cx, cy = centres(grid)
        d = np.hypot(cx - circle.x, cy - circle.y)
        occ = grid.cells == OCCUPIED
        assert occ[d <= circle.radius + grow - 1e-6].all()
        assert not occ[d > circle.radius + grow + 1e-6].any()
    assert grid.occupied(1.03, -0.51) and grid.occupied(1.03 + 0.69, -0.51)
    assert not grid.occupied(1.03 + 0.8, -0.51)


def test_rotated_box_rasterisation() -> None:
    yaw = math.radians(30.0)
    box = Obstacle2D("box", 0.4, 0.2, half_x=1.5, half_y=0.25, yaw=yaw)
    grid = OccupancyGrid.from_obstacles([box], (-3, -3, 3, 3), RES, conservative=False)
    cx, cy = centres(grid)
    u = np.cos(yaw) * (cx - box.x) + np.sin(yaw) * (cy - box.y)
    v = -np.sin(yaw) * (cx - box.x) + np.cos(yaw) * (cy - box.y)
    inside = (np.abs(u) <= box.half_x) & (np.abs(v) <= box.half_y)
    assert np.array_equal(grid.cells == OCCUPIED, inside)
    # Along the rotated long axis: occupied; where the unrotated box would be: free.
    tip = (box.x + 1.4 * math.cos(yaw), box.y + 1.4 * math.sin(yaw))
    assert grid.occupied(*tip)
    assert not grid.occupied(box.x + 1.4, box.y - 0.2)
    # Conservative raster: a superset, still free beyond half a diagonal.
    cons = OccupancyGrid.from_obstacles([box], (-3, -3, 3, 3), RES)
    assert (cons.cells[inside] == OCCUPIED).all()
    dist = box.distance(cx, cy)
    assert not (cons.cells[dist > 0.5 * DIAG + 1e-6] == OCCUPIED).any()


def test_inflation_is_a_disk_of_the_radius() -> None:
    grid = OccupancyGrid((0.0, 0.0), 0.1, 41, 41)
    grid.mark(np.array([[2.05, 2.05]]))
    inflated = grid.inflate(0.5)
    cx, cy = centres(grid)
    d = np.hypot(cx - 2.05, cy - 2.05)
    assert np.array_equal(inflated.cells == OCCUPIED, d <= 0.5 + 1e-9)
    assert (grid.cells == OCCUPIED).sum() == 1, "inflate returns a new grid"
    assert np.array_equal(grid.inflate(0.0).cells, grid.cells)
    with pytest.raises(ValueError, match="inflation radius"):
        grid.inflate(-0.1)


def test_inflation_matches_euclidean_distance_transform() -> None:
    from scipy import ndimage  # in the test extra

    rng = np.random.default_rng(4)
    cells = (rng.random((120, 90)) < 0.01).astype(np.uint8)
    cells[rng.random(cells.shape) < 0.05] = UNKNOWN
    grid = OccupancyGrid((-1.0, 2.0), RES, 90, 120, cells)
    for radius in (0.05, 0.12, 0.33, 0.5):
        inflated = grid.inflate(radius)
        expected = ndimage.distance_transform_edt(cells != OCCUPIED) * RES <= radius + 1e-9
        assert np.array_equal(inflated.cells == OCCUPIED, expected)
        # Unknown stays unknown unless inflated over; free stays free elsewhere.
        assert np.array_equal(inflated.cells == UNKNOWN, (cells == UNKNOWN) & ~expected)
        assert np.array_equal(inflated.cells == FREE, (cells == FREE) & ~expected)


def test_world_cell_round_trip() -> None:
    grid = OccupancyGrid((-3.2, 1.1), 0.1, 64, 30)
    rng = np.random.default_rng(0)
    for x, y in rng.uniform((-3.2, 1.1), (3.2, 4.1), size=(200, 2)):
        i, j = grid.world_to_cell(x, y)
        assert grid.cell_inside(i, j)
        wx, wy = grid.cell_to_world(i, j)
        assert abs(wx - x) <= 0.05 + 1e-9 and abs(wy - y) <= 0.05 + 1e-9
        assert grid.world_to_cell(wx, wy) == (i, j)
    pts = rng.uniform((-3.2, 1.1), (3.2, 4.1), size=(50, 2))
    ii, jj = grid.world_to_cells(pts)
    assert [grid.world_to_cell(*p) for p in pts] == list(zip(ii.tolist(), jj.tolist(), strict=True))


def test_outside_counts_as_occupied_and_mark_ignores_outside() -> None:
    grid = OccupancyGrid((0.0, 0.0), 0.5, 4, 2)
    assert grid.bounds == (0.0, 0.0, 2.0, 1.0)
    assert not grid.occupied(1.0, 0.5) and grid.inside(1.0, 0.5)
    for x, y in ((-0.01, 0.5), (2.0, 0.5), (1.0, 1.0), (1.0, -5.0)):
        assert not grid.inside(x, y)
        assert grid.occupied(x, y)
    assert grid.mark(np.array([[0.2, 0.2], [5.0, 5.0], [-1.0, 0.0]])) == 1
    assert grid.occupied(0.2, 0.2)
    grid.mark(np.array([[1.2, 0.7]]), UNKNOWN)
    assert not grid.occupied(1.2, 0.7) and grid.occupied(1.2, 0.7, unknown_is_occupied=True)
    with pytest.raises(ValueError, match="FREE"):
        grid.mark(np.array([[0.2, 0.2]]), 7)
    copy = grid.copy()
    copy.mark(np.array([[1.7, 0.2]]))
    assert copy.occupied(1.7, 0.2) and not grid.occupied(1.7, 0.2)


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="resolution"):
        OccupancyGrid((0, 0), 0.0, 3, 3)
    with pytest.raises(ValueError, match="shape"):
        OccupancyGrid((0, 0), 0.1, 3, 4, np.zeros((3, 4), dtype=np.uint8))
    with pytest.raises(ValueError, match="bounds"):
        OccupancyGrid.from_obstacles([], (0, 0, 0, 1))
    with pytest.raises(ValueError, match="radius"):
        Obstacle2D("circle", 0, 0)
    with pytest.raises(ValueError, match="kind"):
        Obstacle2D("cone", 0, 0, radius=1)
    assert OccupancyGrid.from_obstacles([], (0, 0, 1, 0.5), 0.1).cells.shape == (5, 10)


def test_checker_updated_in_windows_equals_a_new_checker() -> None:
    from alica.skills.motion import GridChecker

    rng = np.random.default_rng(1)
    cells = (rng.random((300, 400)) < 0.01).astype(np.uint8)
    cells[rng.random((300, 400)) < 0.05] = 255  # unknown
    grid = OccupancyGrid((-3.0, 2.0), 0.05, 400, 300, cells)
    for unknown_is_free in (True, False):
        checker = GridChecker(grid, 0.3, unknown_is_free=unknown_is_free)
        changed = cells.copy()
        windows = [(32, 64, 64, 96), (0, 32, 0, 32), (288, 300, 384, 400)]
        for j0, j1, i0, i1 in windows:
            changed[j0:j1, i0:i1] = rng.random((j1 - j0, i1 - i0)) < 0.02
        new = OccupancyGrid(grid.origin, grid.resolution, grid.width, grid.height, changed)
        updated = checker.updated(new, windows)
        assert updated.grid is new
        assert np.array_equal(updated.blocked, GridChecker(new, 0.3, unknown_is_free=unknown_is_free).blocked)
        assert np.array_equal(checker.blocked, GridChecker(grid, 0.3, unknown_is_free=unknown_is_free).blocked)


def test_checker_with_cleared_disks_forgets_the_cells_in_them() -> None:
    from alica.skills.motion import GridChecker

    # a robot's body as a teammate's lidar maps it: a ring of occupied cells around where it stands
    grid = OccupancyGrid.from_obstacles([Obstacle2D("circle", 2.0, 2.0, radius=0.3)], (0.0, 0.0, 6.0, 4.0), 0.05)
    grid.add_obstacles([Obstacle2D("circle", 4.5, 2.0, radius=0.3)])
    checker = GridChecker(grid, 0.3)
    assert not checker.valid_xy(2.0, 2.0)
    cleared = checker.with_cleared_disks([(2.0, 2.0, 0.4)])
    assert cleared.valid_xy(2.0, 2.0) and not cleared.valid_xy(4.5, 2.0)  # the other obstacle stays
    assert np.array_equal(cleared.blocked, GridChecker(cleared.grid, 0.3).blocked)
    assert not checker.valid_xy(2.0, 2.0)  # the checker itself is unchanged
    assert checker.with_cleared_disks([(1.0, 1.0, 0.2)]) is checker  # nothing to clear
