"""Ready-made worlds: the blocks world (IMPERA Section 8.2), the lunar field (Sections 2 and 6) and lunar sites.

:func:`lunar_sites` is the lunar ground with robots and sample containers
where the caller puts them (a dispatcher's grid, say), and a few rocks kept
clear of given places. All are deterministic functions of their arguments.
"""

from __future__ import annotations

import logging
import math
import random
import string
from collections.abc import Sequence

import numpy as np

from alica.worldsim.errors import WorldError
from alica.worldsim.interface import RobotWorld
from alica.worldsim.objects import SAMPLE_KINDS
from alica.worldsim.perception import FactPerception, Place
from alica.worldsim.queries import blocks_facts
from alica.worldsim.robots import ROBOT_KINDS
from alica.worldsim.world import World

__all__ = ["block_names", "blocks_facts", "blocksworld", "lunar", "lunar_sites", "random_stacks", "sample_names"]

logger = logging.getLogger(__name__)

#: Distance between stack centres in the blocks world.
STACK_SPACING = 0.8
#: Distance from the line of stacks to the robots' centres.
ROBOT_STANDOFF = 1.2
#: Distance along x from the last stack of the row to the first opponent at that end.
OPPONENT_GAP = 1.5
#: Distance along x between opponents at the same end of the row.
OPPONENT_SPACING = 0.8
#: Free room (m) kept between the outermost opponent's centre and the field border.
OPPONENT_ROOM = 1.5
#: Extra room (m) behind both lines of team robots when there are opponents (more robots drive around).
OPPONENT_EXTRA_Y = 1.0


def blocksworld(
    stacks: list[list[str]] | None = None,
    agents: int = 2,
    seed: int = 0,
    block_size: float = 0.05,
    *,
    time_step: float = 1.0 / 240.0,
    opponents: int = 0,
    gui: bool = False,
    arm_visuals: bool | None = None,
) -> World:
    """A blocks world: stacks of blocks on the ground in a row, manipulators ``r1..rN`` around them, opponents ``o1..oK``.

    Args:
        stacks: the stacks, each bottom block first (default ``[["a", "c"], ["b"]]``: c on a, b alone,
            the Sussman anomaly for the goal tower a on b on c).
        agents: number of team robots of kind ``manipulator``; they stand on both sides of the
            row, facing it, :data:`ROBOT_STANDOFF` away.
        seed: the world seed.
        block_size: edge of the blocks in metres.
        time_step: the physics step.
        opponents: number of opponent robots (kind ``manipulator``, named ``o1..oK``); they stand on
            the line of the row beyond its ends, alternately left and right, facing the row,
            :data:`OPPONENT_GAP` from the last stack and :data:`OPPONENT_SPACING` apart; the field
            grows along x to leave :data:`OPPONENT_ROOM` behind the outermost ones, and by
            :data:`OPPONENT_EXTRA_Y` in y, so that every robot can drive around the stacks.
            Without opponents the field is unchanged.
        gui: show the pybullet window (when a display is available).
        arm_visuals: the arms' detailed visual meshes (see :class:`World`); default only with ``gui``:
            they cost about 48 MB per robot, and pictures without them show the arms' collision hulls.

    Raises:
        WorldError: empty stacks, repeated block names, or fewer than 0 agents or opponents.
    """
    if stacks is None:
        stacks = [["a", "c"], ["b"]]
    _check_blocks_arguments(stacks, agents, opponents)
    agents, opponents = int(agents), int(opponents)
    n = max(1, len(stacks))
    row = (n - 1) * STACK_SPACING
    per_side = max(1, math.ceil(agents / 2))
    robots_row = (per_side - 1) * 1.0
    half_x = max(2.5, 0.5 * max(row, robots_row) + 1.5)
    if opponents:
        half_x = max(half_x, abs(_opponent_x(opponents - 1, row)) + OPPONENT_ROOM)  # the outermost opponent
    half_y = ROBOT_STANDOFF + 1.5 + (OPPONENT_EXTRA_Y if opponents else 0.0)
    world = World(
        seed,
        gui=gui,
        time_step=time_step,
        bounds=(-half_x, -half_y, half_x, half_y),
        rest_when_still=True,
        arm_visuals=gui if arm_visuals is None else arm_visuals,
    )
    for i, stack in enumerate(stacks):
        x = -0.5 * row + i * STACK_SPACING
        for level, name in enumerate(stack):
            world.add_block(name, (x, 0.0, (level + 0.5) * block_size + 0.0005 * level), size=block_size)
    for k in range(agents):
        side = -1.0 if k % 2 == 0 else 1.0
        slot = k // 2
        x = -0.5 * robots_row + slot * 1.0
        world.add_robot("manipulator", f"r{k + 1}", (x, side * ROBOT_STANDOFF, -side * 0.5 * math.pi))
    for k in range(opponents):
        x = _opponent_x(k, row)
        world.add_robot("manipulator", f"o{k + 1}", (x, 0.0, 0.0 if x < 0 else math.pi))
    world.step(0.25)  # let the stacks settle
    return world


def _check_blocks_arguments(stacks: list[list[str]], agents: int, opponents: int) -> None:
    """Raise :class:`WorldError` for empty stacks, repeated names or negative robot counts."""
    names = [b for stack in stacks for b in stack]
    if any(not stack for stack in stacks):
        raise WorldError("blocksworld: every stack needs at least one block; drop empty stacks")
    if len(set(names)) != len(names):
        raise WorldError(f"blocksworld: block names must be unique, got {names}")
    if int(agents) < 0:
        raise WorldError(f"blocksworld: agents must be >= 0, got {agents}")
    if int(opponents) < 0:
        raise WorldError(f"blocksworld: opponents must be >= 0, got {opponents}")


def _opponent_x(k: int, row: float) -> float:
    """The x of opponent ``k`` (0-based): even ones left of the row, odd ones right, outwards in pairs."""
    side = -1.0 if k % 2 == 0 else 1.0
    return side * (0.5 * row + OPPONENT_GAP + (k // 2) * OPPONENT_SPACING)


def block_names(count: int) -> list[str]:
    """Names of ``count`` blocks: ``a``, ``b``, ``c``, ... (no letter skipped).

    Raises:
        WorldError: ``count`` is below 1 or above 26.
    """
    if not 1 <= int(count) <= len(string.ascii_lowercase):
        raise WorldError(f"blocks are named a..z: ask for 1 to {len(string.ascii_lowercase)} blocks, got {count}")
    return list(string.ascii_lowercase[: int(count)])


def random_stacks(blocks: int, seed: int, max_height: int | None = None) -> list[list[str]]:
    """A random configuration of the blocks ``a, b, c, ...`` in stacks (each bottom first), the same for the same seed.

    Every configuration (a set of stacks, each an ordered list, at most
    ``max_height`` high) is equally likely: the stack holding the first
    block not yet placed gets a size drawn with the number of configurations
    each size leaves, then random members and a random order. Stacks come in
    the order of their lowest block name.

    Args:
        blocks: how many blocks (1 to 26).
        seed: seeds a ``random.Random``.
        max_height: the highest stack allowed; no limit when None.

    Raises:
        WorldError: a block count out of range or a ``max_height`` below 1.
    """
    names = block_names(blocks)
    if max_height is not None and int(max_height) < 1:
        raise WorldError(f"random_stacks: max_height must be at least 1 (or None for no limit), got {max_height}")
    height = len(names) if max_height is None else min(len(names), int(max_height))
    rng = random.Random(int(seed))
    counts = _configuration_counts(len(names), height)
    left = list(names)
    stacks: list[list[str]] = []
    while left:
        m = len(left)
        pick = rng.randrange(counts[m])
        size = 1
        for size in range(1, min(height, m) + 1):
            ways = math.comb(m - 1, size - 1) * math.factorial(size) * counts[m - size]
            if pick < ways:
                break
            pick -= ways
        first, rest = left[0], left[1:]
        members = [first, *rng.sample(rest, size - 1)]
        rng.shuffle(members)
        stacks.append(members)
        left = [b for b in rest if b not in members]
    return stacks


def _configuration_counts(n: int, height: int) -> list[int]:
    """``counts[m]``: the configurations of ``m`` named blocks in stacks at most ``height`` high, for m = 0..n."""
    counts = [1] + [0] * n
    for m in range(1, n + 1):
        counts[m] = sum(
            math.comb(m - 1, j - 1) * math.factorial(j) * counts[m - j] for j in range(1, min(height, m) + 1)
        )
    return counts


#: The IPC facts the blocks world's perception writes into every agent's world model.
BLOCKS_PREDICATES = ("on", "ontable", "clear", "holding", "handempty")


#: Metres a block (at rest) or a robot moves before the perception writes its ``pos`` again.
BLOCK_MOVED, ROBOT_MOVED = 0.05, 0.5


def blocks_places(world: RobotWorld) -> dict[str, Place]:
    """Where the blocks no robot holds and the robots are: name -> ``(x, y, tolerance)`` (see :class:`FactPerception`)."""
    held = {r.arm.held.name for r in world.robots.values() if r.arm is not None and r.arm.held is not None}
    out: dict[str, Place] = {}
    for name, obj in world.objects.items():
        if obj.kind == "block" and name not in held:
            x, y = (float(v) for v in obj.position()[:2])
            out[name] = (x, y, BLOCK_MOVED)
    for name, robot in world.robots.items():
        x, y, _ = robot.pose
        out[name] = (float(x), float(y), ROBOT_MOVED)
    return out


def blocks_perception(every: float = 0.2) -> FactPerception:
    """The blocks world's team perception: :func:`blocks_facts` and :func:`blocks_places` every ``every`` simulated seconds."""
    return FactPerception(blocks_facts, every=every, predicates=BLOCKS_PREDICATES, places=blocks_places)


def sample_names(count: int) -> list[str]:
    """Names of ``count`` samples: ``a``, ``b``, ... (``g`` is the collection point), then ``s27``, ..."""
    letters = [ch for ch in string.ascii_lowercase if ch != "g"]
    return [letters[i] if i < len(letters) else f"s{i + 1}" for i in range(count)]


def lunar(
    seed: int = 0,
    rocks: int = 60,
    samples: int = 2,
    size: float = 40.0,
    *,
    time_step: float = 1.0 / 240.0,
    start_radius: float = 3.0,
    gui: bool = False,
) -> World:
    """The IMPERA field: rocks, sample containers, the collection point ``g`` and the three robots.

    The field spans ``[-size/2, size/2]`` in x and y with ``g`` at the centre.
    Rocks (radius 0.2-1.0 m) keep out of the start area (``start_radius``
    around ``g``) and off each other; samples ``a``, ``b``, ... of random
    kinds lie in free space at least 0.8 m from rocks and away from ``g``;
    ``scout``, ``stummel`` and ``amparo`` stand around ``g`` facing outwards.

    Raises:
        WorldError: negative counts, a field too small, or rocks or samples that do not fit.
    """
    if rocks < 0 or samples < 0:
        raise WorldError(f"lunar: rocks and samples must be >= 0, got {rocks} and {samples}")
    if not size >= 2.0 * (start_radius + 2.0):
        raise WorldError(f"lunar: size must be at least {2.0 * (start_radius + 2.0)} m for the start area, got {size}")
    half = 0.5 * float(size)
    world = World(seed, gui=gui, time_step=time_step, bounds=(-half, -half, half, half))
    layout = np.random.default_rng([int(seed), 7])
    placed: list[tuple[float, float, float]] = []
    attempts = 0
    while len(placed) < rocks:
        attempts += 1
        if attempts > 200 * max(1, rocks):
            raise WorldError(
                f"lunar: could only place {len(placed)} of {rocks} rocks in a {size} m field; "
                f"ask for fewer rocks or a larger size"
            )
        r = float(layout.uniform(0.2, 1.0))
        x, y = (float(v) for v in layout.uniform(-half + r + 0.5, half - r - 0.5, 2))
        if math.hypot(x, y) < start_radius + r:
            continue
        if any(math.hypot(x - px, y - py) < r + pr + 0.3 for px, py, pr in placed):
            continue
        placed.append((x, y, r))
        world.add_rock(f"rock{len(placed)}", (x, y), r, seed=int(layout.integers(2**31)))
    world.add_collection_point("g", (0.0, 0.0), radius=0.5)
    kinds = list(layout.permutation(len(SAMPLE_KINDS)))
    spots: list[tuple[float, float]] = []
    away = min(6.0, half - 1.5)
    attempts = 0
    for i, name in enumerate(sample_names(samples)):
        while True:
            attempts += 1
            if attempts > 2000 * max(1, samples):
                raise WorldError(f"lunar: no free space for sample '{name}'; ask for fewer rocks or samples")
            x, y = (float(v) for v in layout.uniform(-half + 1.0, half - 1.0, 2))
            if math.hypot(x, y) < away:
                continue
            if any(math.hypot(x - px, y - py) < pr + 0.8 for px, py, pr in placed):
                continue
            if any(math.hypot(x - sx, y - sy) < 1.0 for sx, sy in spots):
                continue
            break
        spots.append((x, y))
        kind = SAMPLE_KINDS[int(kinds[i % len(kinds)])] if i < len(kinds) else SAMPLE_KINDS[int(layout.integers(6))]
        world.add_sample(name, kind, (x, y))
    for name, angle in (("scout", 0.0), ("stummel", 2.0 * math.pi / 3.0), ("amparo", -2.0 * math.pi / 3.0)):
        world.add_robot(name, name, (1.5 * math.cos(angle), 1.5 * math.sin(angle), angle))
    world.step(0.1)  # let the samples settle
    return world


#: Free room (m) kept between a rock of :func:`lunar_sites` and a robot's footprint, a sample, another rock.
SITE_ROOM = {"robot": 0.5, "sample": 0.8, "rock": 0.3, "border": 0.5}


def lunar_sites(
    seed: int = 0,
    *,
    bounds: Sequence[float],
    robots: Sequence[tuple[str, str, Sequence[float]]] = (),
    samples: Sequence[tuple[str, str, Sequence[float]]] = (),
    rocks: int = 0,
    keep_clear: Sequence[tuple[float, float, float]] = (),
    rock_radius: tuple[float, float] = (0.2, 0.45),
    time_step: float = 1.0 / 240.0,
    gui: bool = False,
) -> World:
    """A lunar field with robots and sample containers at given places and a few seeded rocks.

    The generic half of a scenario: positions in, world out. The caller (a
    dispatcher laying a grid over the field, say) decides where robots and
    samples go; this function adds the ground and the bodies, and places
    ``rocks`` rocks at random (seeded) where they keep clear of every disc of
    ``keep_clear``, of the robots and samples, of each other and of the
    field's border (by :data:`SITE_ROOM`).

    Args:
        seed: seeds the world and the rocks' layout.
        bounds: the field ``(xmin, ymin, xmax, ymax)`` in metres.
        robots: ``(name, kind, (x, y, yaw))`` per robot (kinds of
            :data:`~alica.worldsim.robots.ROBOT_KINDS`).
        samples: ``(name, kind, (x, y))`` per sample container (kinds of
            :data:`~alica.worldsim.objects.SAMPLE_KINDS`).
        rocks: how many rocks.
        keep_clear: ``(x, y, radius)`` discs no rock may touch (where robots
            will drive and stand, say).
        rock_radius: the smallest and largest rock radius in metres.
        time_step: the physics step.
        gui: show the pybullet window (when a display is available).

    Raises:
        WorldError: a negative rock count, a bad radius range, rocks that do
            not fit, or a robot or sample off the field or overlapping another
            body (the message says which).
    """
    if rocks < 0:
        raise WorldError(f"lunar_sites: rocks must be >= 0, got {rocks}")
    low, high = (float(v) for v in rock_radius)
    if not 0.0 < low <= high:
        raise WorldError(
            f"lunar_sites: rock_radius is (smallest, largest) with 0 < smallest <= largest, got {rock_radius}"
        )
    world = World(seed, gui=gui, time_step=time_step, bounds=bounds)
    try:
        xmin, ymin, xmax, ymax = world.bounds
        taken: list[tuple[float, float, float]] = [(float(x), float(y), float(radius)) for x, y, radius in keep_clear]
        for _, kind, pose in robots:
            radius = ROBOT_KINDS[kind].radius if kind in ROBOT_KINDS else 0.5
            taken.append((float(pose[0]), float(pose[1]), radius + SITE_ROOM["robot"]))
        taken.extend((float(position[0]), float(position[1]), SITE_ROOM["sample"]) for _, _, position in samples)
        layout = np.random.default_rng([int(seed), 11])
        placed = 0
        attempts = 0
        border = SITE_ROOM["border"]
        while placed < rocks:
            attempts += 1
            if attempts > 500 * rocks:
                raise WorldError(
                    f"lunar_sites: could only place {placed} of {rocks} rocks clear of the robots, the samples and "
                    f"the places to keep clear; ask for fewer rocks or a larger field"
                )
            r = float(layout.uniform(low, high))
            if xmax - xmin <= 2.0 * (r + border) or ymax - ymin <= 2.0 * (r + border):
                continue
            x = float(layout.uniform(xmin + r + border, xmax - r - border))
            y = float(layout.uniform(ymin + r + border, ymax - r - border))
            if any(math.hypot(x - cx, y - cy) < r + cr for cx, cy, cr in taken):
                continue
            placed += 1
            world.add_rock(f"rock{placed}", (x, y), r, seed=int(layout.integers(2**31)))
            taken.append((x, y, r + SITE_ROOM["rock"]))
        for name, kind, position in samples:
            world.add_sample(name, kind, (float(position[0]), float(position[1])))
        for name, kind, pose in robots:
            world.add_robot(kind, name, tuple(float(v) for v in pose))
        world.step(0.1)  # let the samples settle
    except BaseException:
        world.close()
        raise
    return world
