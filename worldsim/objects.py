"""Things in the world that are not robots: blocks, sample containers, rocks, tables, markers, terrain.

All bodies are built in code (no mesh files): boxes and cylinders, and rocks
as convex hulls of perturbed icospheres made with trimesh. Blocks and samples
are *movable* (dynamic, graspable); rocks and tables are static obstacles; the
collection point is a flat marker without collision.

The builders take the :class:`~worldsim.world.World` they add to; use the
world's ``add_*`` methods, which call them.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh

from worldsim.errors import WorldError
from worldsim.geometry import quat_rotate, quat_to_yaw, yaw_to_quat
from worldsim.grid import Obstacle2D

if TYPE_CHECKING:
    from worldsim.world import World

__all__ = ["COLOURS", "OBJECT_KINDS", "SAMPLE_KINDS", "WorldObject", "parse_colour", "sample_sections"]

logger = logging.getLogger(__name__)

#: Named colours (RGBA) accepted wherever a colour is asked for.
COLOURS: dict[str, tuple[float, float, float, float]] = {
    "red": (0.85, 0.12, 0.1, 1.0),
    "green": (0.1, 0.7, 0.15, 1.0),
    "blue": (0.15, 0.3, 0.85, 1.0),
    "yellow": (0.95, 0.85, 0.1, 1.0),
    "orange": (0.95, 0.5, 0.1, 1.0),
    "purple": (0.55, 0.2, 0.7, 1.0),
    "cyan": (0.1, 0.75, 0.8, 1.0),
    "white": (0.95, 0.95, 0.95, 1.0),
    "black": (0.06, 0.06, 0.06, 1.0),
    "grey": (0.5, 0.5, 0.5, 1.0),
    "brown": (0.5, 0.33, 0.18, 1.0),
}
_BLOCK_PALETTE = ("red", "blue", "green", "yellow", "orange", "purple", "cyan", "white")

#: The six IMPERA sample containers: upper and lower section green or red (unordered), middle black or white.
SAMPLE_KINDS: tuple[str, ...] = (
    "green-black-green",
    "green-black-red",
    "red-black-red",
    "green-white-green",
    "green-white-red",
    "red-white-red",
)

#: The ``kind`` values of :class:`WorldObject`.
OBJECT_KINDS: tuple[str, ...] = ("block", "sample", "rock", "table", "collection_point", "terrain")

#: Collision filter bit of movable objects; robot arms collide only with these.
MOVABLE_GROUP = 8
ARM_GROUP = 4


def parse_colour(colour: str | Sequence[float] | None, default: str = "grey") -> tuple[float, float, float, float]:
    """An RGBA tuple from a colour name, an RGB or RGBA sequence, or ``None`` (the default).

    Raises:
        WorldError: an unknown name or a sequence of the wrong length.
    """
    if colour is None:
        colour = default
    if isinstance(colour, str):
        try:
            return COLOURS[colour]
        except KeyError:
            raise WorldError(
                f"unknown colour {colour!r}; use one of {', '.join(sorted(COLOURS))} or an RGBA tuple"
            ) from None
    values = [float(c) for c in colour]
    if len(values) == 3:
        values.append(1.0)
    if len(values) != 4:
        raise WorldError(f"a colour needs 3 or 4 components (RGB or RGBA in 0..1), got {len(values)}")
    return (values[0], values[1], values[2], values[3])


def sample_sections(kind: str) -> tuple[str, str, str]:
    """The colours (upper, middle, lower) of a sample container kind.

    Raises:
        WorldError: not one of :data:`SAMPLE_KINDS`.
    """
    if kind not in SAMPLE_KINDS:
        raise WorldError(f"unknown sample kind {kind!r}; use one of {', '.join(SAMPLE_KINDS)}")
    upper, middle, lower = kind.split("-")
    return upper, middle, lower


class WorldObject:
    """One body in the world that is not a robot.

    Attributes:
        name: unique name in the world.
        kind: one of :data:`OBJECT_KINDS`.
        body_id: the pybullet body id (in the world's client).
        movable: blocks and samples (dynamic, graspable).
        mass: the mass in kg when free (0 for static bodies).
        size: edge of a block, height of a sample or table, radius of a rock or marker.
        radius: footprint radius (samples, rocks, markers); 0 for boxes.
        half_extents: box half extents (blocks, tables); zeros otherwise.
        colour: RGBA of the body (the middle section of a sample).
        sample_kind: the sample container kind (samples only).
        mesh: the rock's convex ``trimesh.Trimesh`` in the body frame (rocks only).
    """

    __slots__ = (
        "_client",
        "body_id",
        "colour",
        "half_extents",
        "kind",
        "mass",
        "mesh",
        "movable",
        "name",
        "radius",
        "sample_kind",
        "size",
    )

    def __init__(
        self,
        name: str,
        kind: str,
        body_id: int,
        client: Any,
        *,
        movable: bool = False,
        mass: float = 0.0,
        size: float = 0.0,
        radius: float = 0.0,
        half_extents: Sequence[float] = (0.0, 0.0, 0.0),
        colour: tuple[float, float, float, float] = COLOURS["grey"],
        sample_kind: str | None = None,
        mesh: trimesh.Trimesh | None = None,
    ) -> None:
        self.name = name
        self.kind = kind
        self.body_id = body_id
        self.movable = movable
        self.mass = float(mass)
        self.size = float(size)
        self.radius = float(radius)
        self.half_extents = tuple(float(h) for h in half_extents)
        self.colour = colour
        self.sample_kind = sample_kind
        self.mesh = mesh
        self._client = client

    def pose(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """Position and quaternion ``(x, y, z, w)`` of the body."""
        pos, quat = self._client.getBasePositionAndOrientation(self.body_id)
        return tuple(pos), tuple(quat)  # type: ignore[return-value]

    def position(self) -> np.ndarray:
        """The body position as a numpy array of 3."""
        return np.asarray(self._client.getBasePositionAndOrientation(self.body_id)[0], dtype=float)

    def yaw(self) -> float:
        """The heading of the body."""
        return quat_to_yaw(self._client.getBasePositionAndOrientation(self.body_id)[1])

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box ``(lower, upper)`` of the body's collision shape."""
        lo, hi = self._client.getAABB(self.body_id, -1)
        return np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)

    def footprint(self) -> Obstacle2D | None:
        """The 2-D footprint at the current pose (``None`` for markers and terrain)."""
        if self.kind in ("collection_point", "terrain"):
            return None
        pos, quat = self.pose()
        if self.half_extents[0] > 0.0:
            return Obstacle2D(
                "box",
                pos[0],
                pos[1],
                half_x=self.half_extents[0],
                half_y=self.half_extents[1],
                yaw=quat_to_yaw(quat),
                name=self.name,
            )
        return Obstacle2D("circle", pos[0], pos[1], radius=self.radius, name=self.name)

    def world_mesh(self) -> trimesh.Trimesh | None:
        """The rock mesh moved to the body's pose (``None`` for other objects)."""
        if self.mesh is None:
            return None
        pos, quat = self.pose()
        vertices = np.array([quat_rotate(quat, v) for v in self.mesh.vertices]) + np.asarray(pos)
        return trimesh.Trimesh(vertices=vertices, faces=self.mesh.faces.copy(), process=False)

    def __repr__(self) -> str:
        extra = f", {self.sample_kind}" if self.sample_kind else ""
        return f"WorldObject({self.name!r}, {self.kind!r}{extra}, body={self.body_id})"


def _xyz(position: Sequence[float], z_default: float, what: str) -> tuple[float, float, float]:
    values = [float(v) for v in position]
    if len(values) == 2:
        values.append(z_default)
    if len(values) != 3 or not all(np.isfinite(values)):
        raise WorldError(f"the position of {what} must be (x, y) or (x, y, z) of finite numbers, got {tuple(position)}")
    return values[0], values[1], values[2]


def _positive(value: float, what: str) -> float:
    value = float(value)
    if not (value > 0.0 and np.isfinite(value)):
        raise WorldError(f"{what} must be a positive number of metres, got {value}")
    return value


def _movable_dynamics(c: Any, body: int) -> None:
    """Friction for stable stacks, sleeping at rest (cheap steps), and the movable collision group."""
    c.changeDynamics(
        body,
        -1,
        lateralFriction=0.9,
        rollingFriction=0.0005,
        spinningFriction=0.001,
        restitution=0.0,
        activationState=c.ACTIVATION_STATE_ENABLE_SLEEPING,
    )
    c.setCollisionFilterGroupMask(body, -1, 1 | MOVABLE_GROUP, -1)


def make_block(
    world: World,
    name: str,
    position: Sequence[float],
    size: float = 0.05,
    colour: str | Sequence[float] | None = None,
    mass: float = 0.1,
) -> WorldObject:
    """A cube of edge ``size``; a 2-D position puts it on the ground."""
    c = world.client
    size = _positive(size, f"the size of block {name!r}")
    x, y, z = _xyz(position, 0.5 * size, f"block {name!r}")
    world._check_in_field(x, y, f"block {name!r}")
    if colour is None:
        colour = _BLOCK_PALETTE[sum(1 for o in world.objects.values() if o.kind == "block") % len(_BLOCK_PALETTE)]
    rgba = parse_colour(colour)
    half = [0.5 * size] * 3
    body = c.createMultiBody(
        baseMass=mass,
        baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_BOX, halfExtents=half),
        baseVisualShapeIndex=c.createVisualShape(c.GEOM_BOX, halfExtents=half, rgbaColor=rgba),
        basePosition=(x, y, z),
        useMaximalCoordinates=True,
    )
    _movable_dynamics(c, body)
    return WorldObject(name, "block", body, c, movable=True, mass=mass, size=size, half_extents=half, colour=rgba)


def make_sample(
    world: World,
    name: str,
    kind: str,
    position: Sequence[float],
    radius: float = 0.03,
    height: float = 0.1,
    mass: float = 0.2,
) -> WorldObject:
    """An IMPERA sample container: an upright cylinder of three coloured sections (see :data:`SAMPLE_KINDS`)."""
    c = world.client
    sections = sample_sections(kind)
    radius = _positive(radius, f"the radius of sample {name!r}")
    height = _positive(height, f"the height of sample {name!r}")
    x, y, z = _xyz(position, 0.5 * height, f"sample {name!r}")
    world._check_in_field(x, y, f"sample {name!r}")
    third = height / 3.0
    visuals = [
        c.createVisualShape(c.GEOM_CYLINDER, radius=radius, length=third, rgbaColor=COLOURS[s]) for s in sections
    ]
    body = c.createMultiBody(
        baseMass=mass,
        baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_CYLINDER, radius=radius, height=height),
        baseVisualShapeIndex=visuals[1],
        basePosition=(x, y, z),
        linkMasses=[1e-3, 1e-3],
        linkCollisionShapeIndices=[-1, -1],
        linkVisualShapeIndices=[visuals[0], visuals[2]],
        linkPositions=[(0.0, 0.0, third), (0.0, 0.0, -third)],
        linkOrientations=[(0.0, 0.0, 0.0, 1.0)] * 2,
        linkInertialFramePositions=[(0.0, 0.0, 0.0)] * 2,
        linkInertialFrameOrientations=[(0.0, 0.0, 0.0, 1.0)] * 2,
        linkParentIndices=[0, 0],
        linkJointTypes=[c.JOINT_FIXED] * 2,
        linkJointAxis=[(0.0, 0.0, 1.0)] * 2,
    )
    _movable_dynamics(c, body)
    return WorldObject(
        name,
        "sample",
        body,
        c,
        movable=True,
        mass=mass,
        size=height,
        radius=radius,
        colour=COLOURS[sections[1]],
        sample_kind=kind,
    )


def make_collection_point(world: World, name: str, position: Sequence[float], radius: float = 0.5) -> WorldObject:
    """A flat disc marker on the ground (no collision)."""
    c = world.client
    radius = _positive(radius, f"the radius of collection point {name!r}")
    x, y, _ = _xyz(position, 0.0, f"collection point {name!r}")
    world._check_in_field(x, y, f"collection point {name!r}")
    rgba = (0.95, 0.8, 0.1, 0.6)
    body = c.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=-1,
        baseVisualShapeIndex=c.createVisualShape(c.GEOM_CYLINDER, radius=radius, length=0.002, rgbaColor=rgba),
        basePosition=(x, y, 0.001),
        useMaximalCoordinates=True,
    )
    return WorldObject(name, "collection_point", body, c, size=radius, radius=radius, colour=rgba)


def make_table(
    world: World,
    name: str,
    position: Sequence[float],
    size: Sequence[float] = (1.0, 0.6),
    height: float = 0.4,
    yaw: float = 0.0,
) -> WorldObject:
    """A solid table (a box from the ground to ``height``), a static obstacle."""
    c = world.client
    if len(size) != 2:
        raise WorldError(f"the size of table {name!r} is (length, width) in metres, got {tuple(size)}")
    lx = _positive(size[0], f"the length of table {name!r}")
    ly = _positive(size[1], f"the width of table {name!r}")
    height = _positive(height, f"the height of table {name!r}")
    x, y, _ = _xyz(position, 0.0, f"table {name!r}")
    world._check_in_field(x, y, f"table {name!r}")
    half = [0.5 * lx, 0.5 * ly, 0.5 * height]
    rgba = COLOURS["brown"]
    body = c.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_BOX, halfExtents=half),
        baseVisualShapeIndex=c.createVisualShape(c.GEOM_BOX, halfExtents=half, rgbaColor=rgba),
        basePosition=(x, y, 0.5 * height),
        baseOrientation=yaw_to_quat(float(yaw)),
        useMaximalCoordinates=True,
    )
    c.changeDynamics(body, -1, lateralFriction=0.9)
    return WorldObject(name, "table", body, c, size=height, half_extents=half, colour=rgba)


def rock_mesh(radius: float, seed: int = 0, height_ratio: float = 0.7, subdivisions: int = 1) -> trimesh.Trimesh:
    """A convex rock: the hull of a randomly perturbed, flattened icosphere.

    The hull is scaled so that its widest horizontal extent from the centre is ``radius``.
    """
    rng = np.random.default_rng(seed)
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    vertices = sphere.vertices * rng.uniform(0.75, 1.15, (len(sphere.vertices), 1))
    vertices[:, 2] *= height_ratio * rng.uniform(0.85, 1.15)
    hull = trimesh.Trimesh(vertices=vertices).convex_hull
    scale = radius / float(np.hypot(hull.vertices[:, 0], hull.vertices[:, 1]).max())
    return trimesh.Trimesh(vertices=hull.vertices * scale, faces=hull.faces, process=False)


def make_rock(
    world: World, name: str, position: Sequence[float], radius: float, seed: int = 0, height_ratio: float = 0.7
) -> WorldObject:
    """A static convex rock; a 2-D position sinks its lower half into the ground."""
    c = world.client
    radius = _positive(radius, f"the radius of rock {name!r}")
    x, y, z = _xyz(position, 0.0, f"rock {name!r}")
    world._check_in_field(x, y, f"rock {name!r}")
    mesh = rock_mesh(radius, seed, height_ratio)
    vertices = mesh.vertices.tolist()
    shade = 0.42 + 0.12 * np.random.default_rng(seed).random()
    rgba = (shade, shade * 0.97, shade * 0.92, 1.0)
    body = c.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_MESH, vertices=vertices),
        baseVisualShapeIndex=c.createVisualShape(
            c.GEOM_MESH, vertices=vertices, indices=mesh.faces.reshape(-1).tolist(), rgbaColor=rgba
        ),
        basePosition=(x, y, z),
        useMaximalCoordinates=True,
    )
    return WorldObject(name, "rock", body, c, size=radius, radius=radius, colour=rgba, mesh=mesh)


def make_terrain(world: World, name: str = "ground", friction: float = 0.8) -> WorldObject:
    """A flat ground plane at z = 0 (a thin visual slab over the field)."""
    c = world.client
    xmin, ymin, xmax, ymax = world.bounds
    rgba = (0.62, 0.6, 0.56, 1.0)
    visual = c.createVisualShape(
        c.GEOM_BOX,
        halfExtents=[0.5 * (xmax - xmin), 0.5 * (ymax - ymin), 0.0005],
        rgbaColor=rgba,
        visualFramePosition=[0.5 * (xmin + xmax), 0.5 * (ymin + ymax), -0.0005],
    )
    body = c.createMultiBody(
        baseMass=0.0,
        baseCollisionShapeIndex=c.createCollisionShape(c.GEOM_PLANE),
        baseVisualShapeIndex=visual,
        useMaximalCoordinates=True,
    )
    c.changeDynamics(body, -1, lateralFriction=float(friction))
    return WorldObject(name, "terrain", body, c, colour=rgba)
