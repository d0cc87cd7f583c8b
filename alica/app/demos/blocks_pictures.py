"""The blocks-world demo's pictures (``initial.png``, ``final.png``): a labelled camera view and a side view of the stacks.

A picture has two panels:

- **camera**: pybullet's off-screen image (:func:`alica.worldsim.camera.render`), framed tightly on the
  blocks and the robots (their bases and arms) instead of the whole field, with every robot's and every
  block's name drawn where the camera sees it (:func:`camera_labels`);
- **side view**: a schematic of the blocks from their true poses, seen from the same side as the camera
  (x to the right, height up, drawn to scale), each block a square with its name, a block held in a
  gripper marked with its robot, and the stacks read from the poses (bottom first) under it, next to
  the goal when one is given. The goal can be checked here at a glance.

Example::

    from alica.app.demos.blocks_pictures import write_picture
    from alica.worldsim.scenarios import blocksworld

    world = blocksworld([["a", "c"], ["b"]], agents=2)
    write_picture(world, "build/blocks.png", goal=[["c", "b", "a"]])
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alica.app.demos.labels import BESIDE, Label, place_labels

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from alica.worldsim.world import World

__all__ = [
    "BlockPose",
    "Camera",
    "block_poses",
    "camera_labels",
    "frame_camera",
    "picture_figure",
    "read_stacks",
    "robot_boxes",
    "scene_camera",
    "stacks_camera",
    "write_picture",
]

#: World points: ``(n, 3)`` metres.
Points = Sequence[Sequence[float]] | np.ndarray
#: Camera yaw (degrees): the camera looks along +y, so x runs left to right as in the side view.
YAW = 0.0
#: Camera pitch (degrees): from above at a slant, so that robots in front hide little of the stacks.
PITCH = -55.0
#: Pitch (degrees) of the close-up of the stacks: lower, so that the blocks' sides show.
CLOSE_PITCH = -30.0
#: Width in pixels of the close-up (its height follows the stacks' shape).
CLOSE_WIDTH = 1200
#: Room (metres) kept around the framed content.
MARGIN = 0.15
#: Nearest camera distance (metres).
NEAREST = 0.2
#: Rounds of re-centring and moving in of :func:`frame_camera`.
REFINE = 8
#: Size of the camera image in pixels.
WIDTH, HEIGHT = 960, 720
#: Two blocks whose centres are this close in x (in block edges) are on one stack.
SAME_STACK = 0.5
#: Colour of the block labels on the camera image, and of the robots'.
BLOCK_COLOUR, ROBOT_COLOUR = "black", "darkblue"


@dataclass(frozen=True, slots=True)
class Camera:
    """A pinhole camera as pybullet's renderer uses it (see :func:`alica.worldsim.camera.render`).

    Attributes:
        target: the point looked at (x, y, z), metres.
        distance: metres from the camera to the target.
        yaw: degrees (0 looks along +y).
        pitch: degrees (negative looks down).
        width: image width in pixels.
        height: image height in pixels.
    """

    target: tuple[float, float, float]
    distance: float
    yaw: float = YAW
    pitch: float = PITCH
    width: int = WIDTH
    height: int = HEIGHT

    def render(self, world: World) -> np.ndarray:
        """The world's picture through this camera (pybullet's renderer)."""
        from alica.worldsim.camera import render

        return render(
            world,
            width=self.width,
            height=self.height,
            target=self.target,
            distance=self.distance,
            yaw=self.yaw,
            pitch=self.pitch,
        )

    def project(self, points: Points) -> np.ndarray:
        """Image pixels ``(n, 2)`` (column right, row down) of world points ``(n, 3)``, by pybullet's own matrices."""
        import pybullet

        from alica.worldsim.camera import FOV

        view = (
            np.asarray(
                pybullet.computeViewMatrixFromYawPitchRoll(
                    list(self.target), self.distance, self.yaw, self.pitch, 0.0, 2
                )
            )
            .reshape(4, 4)
            .T
        )  # pybullet's matrices are column-major
        proj = (
            np.asarray(
                pybullet.computeProjectionMatrixFOV(FOV, self.width / self.height, 0.01, 4.0 * self.distance + 10.0)
            )
            .reshape(4, 4)
            .T
        )
        homogeneous = np.c_[np.asarray(points, dtype=float).reshape(-1, 3), np.ones(len(points))]
        clip = homogeneous @ (proj @ view).T
        ndc = clip[:, :2] / clip[:, 3:4]
        return np.c_[(ndc[:, 0] + 1.0) * 0.5 * self.width, (1.0 - ndc[:, 1]) * 0.5 * self.height]


def frame_camera(
    points: Points,
    *,
    yaw: float = YAW,
    pitch: float = PITCH,
    width: int = WIDTH,
    height: int | None = HEIGHT,
    margin: float = MARGIN,
) -> Camera:
    """The camera that looks at the middle of ``points`` from as close as keeps them all (with ``margin``) in the image.

    The points are taken into the camera's frame (right, up, forward); each one needs the camera far
    enough back that its right and up offsets, plus the margin, fit the half angles of the view. The
    camera is then re-centred on the projected points and moved in until they span the picture less
    the margin (perspective makes the first distance loose). With ``height=None`` the image takes the content's shape (between 1/4 and 1 of ``width``).
    """
    from alica.worldsim.camera import FOV

    cloud = np.asarray(points, dtype=float).reshape(-1, 3)
    low, high = cloud.min(axis=0), cloud.max(axis=0)
    aim = 0.5 * (low + high)
    yaw_r, pitch_r = math.radians(yaw), math.radians(pitch)
    forward = np.array([-math.sin(yaw_r) * math.cos(pitch_r), math.cos(yaw_r) * math.cos(pitch_r), math.sin(pitch_r)])
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    # centre the content in the image: the middle of its extent across and up, not of its box
    offsets = cloud - aim
    aim = aim + right * 0.5 * ((offsets @ right).max() + (offsets @ right).min())
    aim = aim + up * 0.5 * ((offsets @ up).max() + (offsets @ up).min())
    offsets = cloud - aim
    if height is None:
        across, upward = np.ptp(offsets @ right) + 2 * margin, np.ptp(offsets @ up) + 2 * margin
        height = round(width * min(1.0, max(0.25, float(upward / max(across, 1e-9)))))
    tan_v = math.tan(math.radians(FOV) / 2.0)
    tan_h = tan_v * width / height
    depth = offsets @ forward
    needed = max(
        float(np.max((np.abs(offsets @ right) + margin) / tan_h - depth)),
        float(np.max((np.abs(offsets @ up) + margin) / tan_v - depth)),
        NEAREST,
    )
    camera = Camera((float(aim[0]), float(aim[1]), float(aim[2])), needed, yaw, pitch, width, height)
    # That distance holds for the farthest-out point at every side at once; in perspective the near
    # points take more of the picture than the far ones. Re-centre on the projected content and move
    # in until it spans the picture less the margin, a few times (the size goes as 1 / distance).
    for _ in range(REFINE):
        pixels = camera.project(cloud)
        lo, hi = pixels.min(axis=0), pixels.max(axis=0)
        per_px = 2.0 * camera.distance * tan_v / height  # metres per pixel at the target
        du, dv = 0.5 * (lo + hi) - (0.5 * width, 0.5 * height)
        aim = np.asarray(camera.target) + right * du * per_px - up * dv * per_px
        span = np.maximum(hi - lo, 1.0)
        room = np.array([width, height]) - 2.0 * margin / per_px
        scale = float(np.min(room / span))
        camera = Camera(
            (float(aim[0]), float(aim[1]), float(aim[2])),
            max(NEAREST, camera.distance / scale),
            yaw,
            pitch,
            width,
            height,
        )
    for _ in range(500):  # a last check that everything is in the picture
        pixels = camera.project(cloud)
        if (pixels >= 0).all() and (pixels <= (width, height)).all():
            break
        camera = Camera(camera.target, camera.distance * 1.01, yaw, pitch, width, height)
    return camera


@dataclass(frozen=True, slots=True)
class BlockPose:
    """A block where the world has it.

    Attributes:
        name: the block's name.
        x: centre, metres.
        y: centre, metres.
        z: centre height, metres.
        size: edge, metres.
        holder: the robot whose gripper holds it, or ``""``.
    """

    name: str
    x: float
    y: float
    z: float
    size: float
    holder: str = ""


def block_poses(world: World) -> list[BlockPose]:
    """Every block of ``world`` with its true centre, edge and holder, in name order."""
    held = {}
    for robot in world.robots.values():
        obj = robot.arm.held if robot.arm is not None else None
        if obj is not None:
            held[obj.name] = robot.name
    poses = []
    for obj in world.objects.values():
        if obj.kind != "block":
            continue
        low, high = obj.aabb()
        x, y, z = (float(v) for v in obj.position())
        size = float(min(high[0] - low[0], high[1] - low[1], high[2] - low[2]))
        poses.append(BlockPose(obj.name, x, y, z, size, held.get(obj.name, "")))
    return sorted(poses, key=lambda b: b.name)


def read_stacks(blocks: Sequence[BlockPose]) -> list[list[str]]:
    """The stacks the free blocks form, left to right, each bottom first (held blocks are in no stack).

    Blocks whose centres are within :data:`SAME_STACK` edges in x and y are on one stack.
    """
    stacks: list[list[BlockPose]] = []
    for block in sorted((b for b in blocks if not b.holder), key=lambda b: (b.x, b.z)):
        for stack in stacks:
            base = stack[0]
            if abs(base.x - block.x) < SAME_STACK * base.size and abs(base.y - block.y) < SAME_STACK * base.size:
                stack.append(block)
                break
        else:
            stacks.append([block])
    return [[b.name for b in sorted(stack, key=lambda b: b.z)] for stack in sorted(stacks, key=lambda s: s[0].x)]


def robot_boxes(world: World) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each robot's axis-aligned box (low, high), its base and its arm's links together."""
    client = world.client
    boxes = {}
    for name, robot in world.robots.items():
        parts = [client.getAABB(robot.body_id)]
        arm = robot.arm
        if arm is not None:
            parts += [client.getAABB(arm.body_id, link) for link in range(-1, client.getNumJoints(arm.body_id))]
        low = np.min([p[0] for p in parts], axis=0)
        high = np.max([p[1] for p in parts], axis=0)
        boxes[name] = (low, high)
    return boxes


def _corners(low: Sequence[float] | np.ndarray, high: Sequence[float] | np.ndarray) -> list[tuple[float, float, float]]:
    return [
        (float(x), float(y), float(z)) for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])
    ]


def scene_camera(world: World) -> Camera:
    """The camera framed on the blocks and the robots of ``world``."""
    points = []
    for block in block_poses(world):
        half = 0.5 * block.size
        points += _corners(
            (block.x - half, block.y - half, block.z - half), (block.x + half, block.y + half, block.z + half)
        )
    for low, high in robot_boxes(world).values():
        points += _corners(low, high)
    if not points:
        xmin, ymin, xmax, ymax = world.bounds
        points = [(xmin, ymin, 0.0), (xmax, ymax, 0.0)]
    return frame_camera(points)


def stacks_camera(world: World) -> Camera:
    """The camera framed on the blocks alone (the close-up), from a lower angle than :func:`scene_camera`."""
    points = []
    for block in block_poses(world):
        half = 0.5 * block.size
        points += _corners(
            (block.x - half, block.y - half, block.z - half), (block.x + half, block.y + half, block.z + half)
        )
    if not points:
        return scene_camera(world)
    size = max(b.size for b in block_poses(world))
    return frame_camera(points, pitch=CLOSE_PITCH, margin=1.5 * size, width=CLOSE_WIDTH, height=None)


def camera_labels(world: World, camera: Camera) -> list[Label]:
    """A label for every robot (at the top of its base) and every block (on the face seen), in image pixels.

    Robots come first (fewer, larger), then the blocks from the top of each stack down, so that the
    placement of :func:`place_labels` keeps the robots' labels next to them.
    """
    labels = []
    for name, robot in sorted(world.robots.items()):
        x, y, _ = robot.pose
        ((u, v),) = camera.project([(x, y, float(robot.spec.height))])
        labels.append(Label(name, float(u), float(v), "robot", colour=ROBOT_COLOUR, size=12.0, bold=True))
    blocks = block_poses(world)
    if blocks:
        pixels = camera.project([(b.x, b.y - 0.5 * b.size, b.z) for b in blocks])  # the face the camera sees
        for block, (u, v) in sorted(zip(blocks, pixels, strict=True), key=lambda bp: -bp[0].z):
            labels.append(Label(block.name, float(u), float(v), "block", colour=BLOCK_COLOUR, size=11.0, bold=True))
    return labels


def _stacks_text(stacks: Sequence[Sequence[str]]) -> str:
    return "  ".join("[" + " ".join(stack) + "]" for stack in stacks) or "none"


def _side_view(ax: Axes, blocks: Sequence[BlockPose], goal: Sequence[Sequence[str]] | None) -> None:
    """The schematic: each stack a column of squares at the blocks' true heights, the held blocks after them."""
    from matplotlib.patches import Rectangle

    stacks = read_stacks(blocks)
    by_name = {b.name: b for b in blocks}
    columns = [[by_name[n] for n in stack] for stack in stacks] + [[b] for b in blocks if b.holder]
    size = max((b.size for b in blocks), default=0.05)
    ticks, names = [], []
    for i, column in enumerate(columns):
        left = i * 2.0 * size
        ticks.append(left + 0.5 * size)
        held = column[0].holder
        names.append(f"held by\n{held}" if held else f"x = {column[0].x + 0.0:.2f}".replace("-0.00", "0.00"))
        for block in column:
            bottom = block.z - 0.5 * block.size
            colour = "lightsteelblue" if held else "wheat"
            ax.add_patch(Rectangle((left, bottom), size, block.size, fc=colour, ec="black", lw=1.0))
            fit = max(6.0, 15.0 - 1.5 * max(0, len(block.name) - 1))
            ax.text(left + 0.5 * size, block.z, block.name, ha="center", va="center", fontsize=fit, fontweight="bold")
    top = max((b.z + 0.5 * b.size for b in blocks), default=size)
    ax.axhline(0.0, color="saddlebrown", lw=2.0)
    ax.set_xlim(-size, max(1, len(columns)) * 2.0 * size)
    ax.set_ylim(-0.3 * size, top + 0.7 * size)
    ax.set_aspect("equal")
    ax.set_xticks(ticks, names, fontsize=9)
    ax.set_ylabel("height (m)")
    lines = [f"stacks, bottom first: {_stacks_text(stacks)}"]
    if goal is not None:
        want = sorted(list(s) for s in goal)
        lines.append(f"goal: {_stacks_text(goal)} ({'holds' if sorted(stacks) == want else 'does not hold'})")
    ax.set_title("side view from the true poses (stacks left to right)\n" + "\n".join(lines), fontsize=11)


def picture_figure(world: World, *, goal: Sequence[Sequence[str]] | None = None, title: str = "") -> Figure:
    """The picture (see the module docstring) as a matplotlib figure; the caller closes it.

    Args:
        world: the blocks world, not closed.
        goal: the goal stacks (each bottom first), shown and compared with the stacks read from the poses.
        title: the figure's title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scene, close = scene_camera(world), stacks_camera(world)
    fig = plt.figure(figsize=(18, 13), dpi=100)
    grid = fig.add_gridspec(2, 2, width_ratios=[4, 3], height_ratios=[3, 2])
    left, right, middle = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, :])
    for ax, camera, what in ((left, scene, "robots and blocks"), (middle, close, "close-up of the stacks")):
        pixels = camera.render(world)
        ax.imshow(pixels)
        ax.set_xlim(0, camera.width)
        ax.set_ylim(camera.height, 0)
        ax.set_axis_off()
        ax.set_title(f"camera: {what}", fontsize=11)
    _side_view(right, block_poses(world), goal)
    if title:
        fig.suptitle(title, fontsize=14)
    fig.tight_layout()
    beside = {"block": BESIDE}
    place_labels(left, camera_labels(world, scene), marker_px=4.0, offsets=beside)
    place_labels(
        middle, [lb for lb in camera_labels(world, close) if lb.kind == "block"], marker_px=4.0, offsets=beside
    )
    return fig


def write_picture(
    world: World, path: str | Path, *, goal: Sequence[Sequence[str]] | None = None, title: str = ""
) -> Path:
    """Write the picture of ``world`` (see the module docstring) as a PNG; missing folders are made.

    Returns:
        The path written.
    """
    import matplotlib.pyplot as plt

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig = picture_figure(world, goal=goal, title=title)
    fig.savefig(out, bbox_inches="tight")
    plt.close(fig)
    return out
