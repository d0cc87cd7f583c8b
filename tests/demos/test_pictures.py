"""The demos' pictures: the blocks pictures zoom to the blocks and label every block and robot; the lunar map shows g."""

from __future__ import annotations

from collections.abc import Iterator
from itertools import combinations
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

from alica.app.demos.blocks_pictures import (
    BlockPose,
    block_poses,
    camera_labels,
    frame_camera,
    picture_figure,
    read_stacks,
    robot_boxes,
    scene_camera,
    stacks_camera,
    write_picture,
)
from alica.app.demos.labels import Label, overlap, place_labels, text_extent
from alica.app.demos.lunar import LunarConfig, Operator
from alica.app.demos.lunar_map import BASE_COLOUR, map_figure, map_labels
from alica.worldsim.scenarios import blocksworld, lunar

TOWER = [["a", "b", "c", "d", "e"]]
ROBOTS = {"r1", "r2", "r3", "o1"}


@pytest.fixture(scope="module")
def tower() -> Iterator[object]:
    """A five-block tower, three team robots and an opponent."""
    world = blocksworld([list(s) for s in TOWER], agents=3, opponents=1)
    yield world
    world.close()


def _block_corners(world: object) -> np.ndarray:
    corners = []
    for b in block_poses(world):
        h = 0.5 * b.size
        corners += [(b.x + sx * h, b.y + sy * h, b.z + sz * h) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    return np.asarray(corners)


def _texts(fig: object) -> list[object]:
    return [t for ax in fig.axes for t in ax.texts]  # type: ignore[attr-defined]


def test_the_close_up_fills_the_picture_with_the_blocks(tower):
    camera = stacks_camera(tower)
    pixels = camera.project(_block_corners(tower))
    (u0, v0), (u1, v1) = pixels.min(axis=0), pixels.max(axis=0)
    assert 0 <= u0 and u1 <= camera.width and 0 <= v0 and v1 <= camera.height  # all of the tower is in the picture
    # the 25 cm tower is most of the picture's height (the whole-field view made it about 20 px of 480)
    assert (v1 - v0) / camera.height > 0.5


def test_the_scene_is_framed_tightly_on_the_robots_and_blocks(tower):
    camera = scene_camera(tower)
    corners = [
        (x, y, z)
        for low, high in robot_boxes(tower).values()
        for x in (low[0], high[0])
        for y in (low[1], high[1])
        for z in (low[2], high[2])
    ]
    assert len(corners) == 8 * len(ROBOTS)
    both = np.vstack([camera.project(corners), camera.project(_block_corners(tower))])
    (u0, v0), (u1, v1) = both.min(axis=0), both.max(axis=0)
    assert 0 <= u0 and u1 <= camera.width and 0 <= v0 and v1 <= camera.height
    # the robots (bases and arms) and the blocks fill the picture on its tighter side, not a small middle part
    assert max((u1 - u0) / camera.width, (v1 - v0) / camera.height) > 0.9
    # and the blocks are many times larger than in the whole-field view that was used before
    whole = frame_camera([(x, y, 0.0) for x in tower.bounds[::2] for y in tower.bounds[1::2]])
    tall = np.ptp(stacks_camera(tower).project(_block_corners(tower))[:, 1])
    assert tall > 10 * np.ptp(whole.project(_block_corners(tower))[:, 1])


def test_the_projection_is_the_renderers(tower):
    """A block's face seen by the camera is where the camera model puts it: not the ground's colour there."""
    camera = stacks_camera(tower)
    image = camera.render(tower)
    faces = camera.project([(b.x, b.y - 0.5 * b.size, b.z) for b in block_poses(tower)])
    ground = camera.project([(camera.target[0] + 0.2, camera.target[1] + 0.1, 0.0)])[0]
    floor = image[int(ground[1]), int(ground[0])].astype(int)
    for u, v in faces:
        assert np.abs(image[int(v), int(u)].astype(int) - floor).max() > 40, (u, v)
    # and a point the model puts on the bare ground has the ground's colour
    assert np.abs(floor - image[int(ground[1]) + 3, int(ground[0]) + 3].astype(int)).max() < 20


def test_frame_camera_keeps_every_point_inside_with_the_margin():
    points = [(-1.0, -0.5, 0.0), (1.0, 0.5, 0.0), (0.2, 0.1, 0.8)]
    camera = frame_camera(points, margin=0.0)
    pixels = camera.project(points)
    assert (
        (pixels >= -1).all() and (pixels[:, 0] <= camera.width + 1).all() and (pixels[:, 1] <= camera.height + 1).all()
    )
    # tight: some point touches an edge of the picture
    gaps = np.r_[pixels[:, 0], camera.width - pixels[:, 0], pixels[:, 1], camera.height - pixels[:, 1]]
    assert gaps.min() < 10.0
    farther = frame_camera(points, margin=0.5)
    assert farther.distance > camera.distance


def test_every_block_and_robot_gets_one_label_at_its_place_in_the_picture(tower):
    for camera in (scene_camera(tower), stacks_camera(tower)):
        labels = camera_labels(tower, camera)
        assert sorted(lb.text for lb in labels if lb.kind == "block") == ["a", "b", "c", "d", "e"]
        assert {lb.text for lb in labels if lb.kind == "robot"} == ROBOTS
        assert len(labels) == 9
        for lb in labels:
            if lb.kind == "block" or camera is scene_camera(tower):
                assert 0 <= lb.x <= camera.width and 0 <= lb.y <= camera.height, lb
    # the tower's labels go up the picture in stacking order
    rows = {lb.text: lb.y for lb in camera_labels(tower, stacks_camera(tower)) if lb.kind == "block"}
    assert rows["a"] > rows["b"] > rows["c"] > rows["d"] > rows["e"]


def test_the_picture_names_every_block_and_robot_and_checks_the_goal(tower, tmp_path):
    fig = picture_figure(tower, goal=TOWER)
    try:
        texts = [t.get_text() for t in _texts(fig)]
        for name in ["a", "b", "c", "d", "e"]:
            assert texts.count(name) == 3  # overview, close-up, side view
        for robot in ROBOTS:
            assert texts.count(robot) == 1
        side = fig.axes[1].get_title()
        assert "stacks, bottom first: [a b c d e]" in side and "(holds)" in side
    finally:
        plt.close(fig)
    fig = picture_figure(tower, goal=[["e", "d", "c", "b", "a"]])
    try:
        assert "(does not hold)" in fig.axes[1].get_title()
    finally:
        plt.close(fig)
    path = write_picture(tower, tmp_path / "pics" / "final.png", goal=TOWER, title="final")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_read_stacks_groups_blocks_by_place_bottom_first_and_leaves_out_held_ones():
    blocks = [
        BlockPose("c", 0.8, 0.0, 0.025, 0.05),
        BlockPose("a", -0.8, 0.0, 0.075, 0.05),
        BlockPose("b", -0.8, 0.001, 0.025, 0.05),
        BlockPose("d", 0.3, -0.6, 0.4, 0.05, holder="r2"),
    ]
    assert read_stacks(blocks) == [["b", "a"], ["c"]]
    assert read_stacks([]) == []


def _extents(fig: object, texts: list[object]) -> list[tuple[float, float, float, float]]:
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    boxes = []
    for t in texts:
        e = text_extent(t, renderer)
        boxes.append((e.x0, e.y0, e.x1, e.y1))
    return boxes


def test_crowded_labels_are_placed_apart():
    fig, ax = plt.subplots(figsize=(4, 4), dpi=100)
    try:
        ax.set_xlim(0, 10)
        ax.set_ylim(0, 10)
        labels = [Label(f"label {i}", 5.0 + 0.05 * i, 5.0, "sample", size=10.0) for i in range(6)]
        drawn = place_labels(ax, labels)
        assert len(drawn) == 6
        boxes = _extents(fig, drawn)
        assert all(overlap(a, b) == 0.0 for a, b in combinations(boxes, 2))
    finally:
        plt.close(fig)


def test_overlap():
    assert overlap((0, 0, 2, 2), (1, 1, 3, 3)) == 1.0
    assert overlap((0, 0, 1, 1), (1, 0, 2, 1)) == 0.0


@pytest.fixture(scope="module")
def field() -> Iterator[object]:
    world = lunar(seed=1, samples=4, size=20.0, rocks=10)
    yield world
    world.close()


def test_the_lunar_map_labels_g_every_robot_and_every_sample(field):
    operator = Operator(LunarConfig())
    tracks = {"scout": [(0.0, 0.0), (3.0, 4.0)]}
    labels = map_labels(field, operator, tracks, {"amparo": (1.0, -1.0)})
    g = field.objects["g"].position()
    base = [lb for lb in labels if lb.kind == "base"]
    assert len(base) == 1 and base[0].text.startswith("g") and (base[0].x, base[0].y) == (g[0], g[1])
    by_name = {lb.text.split()[0]: lb for lb in labels if lb.kind in ("robot", "crash")}
    assert set(by_name) == {"scout", "stummel", "amparo"}
    assert (by_name["scout"].x, by_name["scout"].y) == (3.0, 4.0)  # where its track ended
    assert by_name["amparo"].kind == "crash" and by_name["amparo"].text == "amparo crashed"
    assert sum(lb.kind == "sample" for lb in labels) == 4
    assert min(lb.size for lb in labels) >= 9.0  # larger than the former 6 pt


def test_the_lunar_map_draws_g_with_a_marker_and_labels_that_do_not_overlap(field):
    fig = map_figure(field, None, Operator(LunarConfig()), {"scout": [(0.0, 0.0), (0.5, 0.3)]}, {})
    try:
        ax = fig.axes[0]
        g = field.objects["g"].position()
        stars = [
            line
            for line in ax.get_lines()
            if line.get_marker() == "*"
            and line.get_color() == BASE_COLOUR
            and np.allclose(line.get_xydata(), [[g[0], g[1]]])
        ]
        assert len(stars) == 1
        annotations = ax.texts
        assert any(t.get_text() == "g (collection point)" for t in annotations)
        boxes = _extents(fig, annotations)
        clashes = [(a, b) for a, b in combinations(range(len(boxes)), 2) if overlap(boxes[a], boxes[b]) > 0.0]
        assert not clashes, [(annotations[a].get_text(), annotations[b].get_text()) for a, b in clashes]
    finally:
        plt.close(fig)


def test_draw_map_writes_the_png(field, tmp_path: Path):
    from alica.app.demos.lunar_map import draw_map

    draw_map(field, None, Operator(LunarConfig()), {}, {}, tmp_path / "map.png")
    assert (tmp_path / "map.png").read_bytes()[:4] == b"\x89PNG"
