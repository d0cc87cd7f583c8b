"""Things in the world that are not robots: blocks, sample containers, rocks, tables, markers, terrain.

Blocks and samples are *movable* (dynamic, graspable); rocks and tables are
static obstacles; the collection point is a flat marker without collision.
The bodies are built by :mod:`alica.worldsim.bodies` (through the world's ``add_*``
methods); this module holds :class:`WorldObject`, the colours and the collision groups;
the kinds of objects and samples are data of :mod:`alica.worldsim.kinds` (re-exported here).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import trimesh

from alica.worldsim.errors import WorldError
from alica.worldsim.geometry import quat_rotate, quat_to_yaw
from alica.worldsim.grid import Obstacle2D
from alica.worldsim.kinds import OBJECT_KINDS, SAMPLE_KINDS

__all__ = ["COLOURS", "OBJECT_KINDS", "SAMPLE_KINDS", "WorldObject", "parse_colour", "sample_sections"]

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
BLOCK_PALETTE = ("red", "blue", "green", "yellow", "orange", "purple", "cyan", "white")

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
        return tuple(pos), tuple(quat)

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
