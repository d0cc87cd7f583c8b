"""Building the bodies of :mod:`alica.worldsim.objects` in code (no mesh files).

Boxes and cylinders from pybullet primitives; rocks as convex hulls of
perturbed, flattened icospheres made with trimesh. Each builder takes the
world it adds to (a :class:`BuildingWorld`: its client, field and objects); use
the :class:`~alica.worldsim.world.World`'s ``add_*`` methods, which call them and
register the result.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import trimesh

from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import yaw_to_quat
from alica.worldsim.objects import BLOCK_PALETTE, COLOURS, MOVABLE_GROUP, WorldObject, parse_colour, sample_sections

if TYPE_CHECKING:
    from alica.worldsim.field import Field

__all__ = [
    "BuildingWorld",
    "make_block",
    "make_collection_point",
    "make_rock",
    "make_sample",
    "make_table",
    "make_terrain",
    "rock_mesh",
]


class BuildingWorld(Protocol):
    """What the builders use of the world they add to."""

    @property
    def client(self) -> Any:
        """The world's pybullet client: the bodies are made in it."""
        ...

    @property
    def field(self) -> Field:
        """The field every position is checked against."""
        ...

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The field's ``(xmin, ymin, xmax, ymax)`` (the terrain covers it)."""
        ...

    @property
    def objects(self) -> Mapping[str, WorldObject]:
        """The objects so far (a new block takes the next colour of the palette)."""
        ...


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
    world: BuildingWorld,
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
    world.field.check(x, y, f"block {name!r}")
    if colour is None:
        colour = BLOCK_PALETTE[sum(1 for o in world.objects.values() if o.kind == "block") % len(BLOCK_PALETTE)]
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
    world: BuildingWorld,
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
    world.field.check(x, y, f"sample {name!r}")
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


def make_collection_point(
    world: BuildingWorld, name: str, position: Sequence[float], radius: float = 0.5
) -> WorldObject:
    """A flat disc marker on the ground (no collision)."""
    c = world.client
    radius = _positive(radius, f"the radius of collection point {name!r}")
    x, y, _ = _xyz(position, 0.0, f"collection point {name!r}")
    world.field.check(x, y, f"collection point {name!r}")
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
    world: BuildingWorld,
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
    world.field.check(x, y, f"table {name!r}")
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
    world: BuildingWorld, name: str, position: Sequence[float], radius: float, seed: int = 0, height_ratio: float = 0.7
) -> WorldObject:
    """A static convex rock; a 2-D position sinks its lower half into the ground."""
    c = world.client
    radius = _positive(radius, f"the radius of rock {name!r}")
    x, y, z = _xyz(position, 0.0, f"rock {name!r}")
    world.field.check(x, y, f"rock {name!r}")
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


def make_terrain(world: BuildingWorld, name: str = "ground", friction: float = 0.8) -> WorldObject:
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
