"""The world in a trace: robot poses, objects that moved and the team map, at a low rate.

The engine traces what the agents do; a viewer that replays a run also needs
where the robots were and what the team knew of the field. :class:`WorldTrace`
samples the simulated world into a trace file (:class:`alica.engine.JsonlTrace`)
after every tick, in simulated time:

* ``pose`` events at ``pose_hz`` (2 Hz by default): at the first tick of every
  period, each robot that moved more than :data:`STILL` metres or radians, or
  whose agent crashed or came back, since its last pose; a robot that stands
  still is recorded again every :data:`KEYFRAME_EVERY` seconds all the same;
* ``object`` events: every object but the terrain once at the start, then, at
  the pose rate, a block or sample that moved more than :data:`MOVED` metres
  (3 cm) from where the trace last put it;
* ``map`` events every ``map_every`` seconds (5 s) when the team map changed, with
  the occupancy grid coarsened to :data:`MAP_RESOLUTION` (a cell is occupied
  when any of its finer cells is, else free when any is free, else unknown) and
  compressed (:func:`alica.engine.trace.encode_cells`).

``docs/trace.md`` documents the fields. :func:`world_header` gives a header's world fields.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from alica.engine.trace import MAP_ENCODING, encode_cells

if TYPE_CHECKING:
    from alica.engine import SimulatedTeam
    from alica.skills.mapping import LogOddsGrid
    from alica.worldsim.world import World

#: Robot poses per simulated second, by default.
POSE_HZ = 2.0
#: Metres an object moves before the trace records it again.
MOVED = 0.03
#: Metres (and radians of heading) a robot moves before the trace records its pose again.
STILL = 0.01
#: Simulated seconds after which the pose of a robot standing still is recorded again.
KEYFRAME_EVERY = 10.0
#: Simulated seconds between two looks at the team map.
MAP_EVERY = 5.0
#: The coarsest cell side of a traced map in metres: a finer team map is coarsened to it (whole multiples).
MAP_RESOLUTION = 0.2

Sink = Callable[[dict[str, Any]], None]


def tee(sinks: Sequence[Sink]) -> Sink:
    """One sink that hands every event to each of ``sinks`` (the trace file and the control center, say)."""
    if len(sinks) == 1:
        return sinks[0]

    def each(event: dict[str, Any]) -> None:
        for sink in sinks:
            sink(event)

    return each


def team_grid(team: SimulatedTeam) -> LogOddsGrid | None:
    """The team map (:func:`alica.skills.mapping.team_map`) of the first running agent that has one, else ``None``."""
    from alica.skills.mapping import team_map

    for engine in team.running() or list(team.engines.values()):
        grid = team_map(engine.world_model)
        if grid is not None:
            return grid
    return None


def world_header(
    world: World | None, kind: str, *, pose_hz: float = POSE_HZ, map_every: float | None = None
) -> dict[str, Any]:
    """The header fields (:func:`alica.engine.trace.trace_header`) of a run in ``world`` (``None``: no world)."""
    if world is None:
        return {"world": "none", "bounds": None}
    fields: dict[str, Any] = {
        "world": kind,
        "bounds": list(world.bounds),
        "robots": {name: robot.spec.kind for name, robot in sorted(world.robots.items())},
        "pose_hz": pose_hz,
        "still_m": STILL,
        "keyframe_every_s": KEYFRAME_EVERY,
        "moved_m": MOVED,
    }
    if map_every is not None:
        fields["map_every_s"] = map_every
        fields["map_resolution_m"] = MAP_RESOLUTION
    return fields


class WorldTrace:
    """Samples the world into ``sink`` (see the module docstring); call it with the time after every tick.

    Args:
        sink: where the events go (the trace file).
        world: the simulated world (:class:`alica.worldsim.World`).
        alive: whether a robot's agent runs (``False`` once it crashed); every robot is alive without it.
        team_map: the team's map now (a grid with ``occupancy()``, ``origin``, ``resolution``), or ``None``;
            no ``map`` events without it.
        pose_hz: robot poses per simulated second.
        map_every: simulated seconds between two looks at the team map.

    Raises:
        ValueError: a rate that is not positive.
    """

    def __init__(
        self,
        sink: Sink,
        world: World,
        *,
        alive: Callable[[str], bool] | None = None,
        team_map: Callable[[], LogOddsGrid | None] | None = None,
        pose_hz: float = POSE_HZ,
        map_every: float = MAP_EVERY,
    ) -> None:
        if not (pose_hz > 0 and math.isfinite(pose_hz)) or not (map_every > 0 and math.isfinite(map_every)):
            raise ValueError(f"pose rate and map period must be positive, got {pose_hz} Hz and {map_every} s")
        self.sink = sink
        self.world = world
        self.alive = alive
        self.team_map = team_map
        self.period = 1.0 / pose_hz
        self.map_every = map_every
        self._next_pose = 0.0
        self._next_map = 0.0
        self._looked = False
        self._placed: dict[str, tuple[float, float, float]] = {}
        self._posed: dict[str, tuple[float, float, float, bool, float]] = {}  # x, y, yaw, alive, t
        self._map_digest = ""

    def __call__(self, now: float) -> None:
        """Record what is due at simulated time ``now``."""
        t = round(now, 6)
        if now + 1e-9 >= self._next_pose:
            self._next_pose = (math.floor(now / self.period + 1e-9) + 1) * self.period
            self._poses(t)
            self._objects(t)
        if self.team_map is not None and now + 1e-9 >= self._next_map:
            self._next_map = now + self.map_every
            self._map(t)

    def _poses(self, t: float) -> None:
        for name, robot in sorted(self.world.robots.items()):
            x, y, yaw = (float(v) for v in robot.pose)
            alive = self.alive is None or bool(self.alive(name))
            last = self._posed.get(name)
            if (
                last is not None
                and last[3] == alive
                and t - last[4] < KEYFRAME_EVERY - 1e-9
                and math.hypot(x - last[0], y - last[1]) <= STILL
                and abs(math.remainder(yaw - last[2], math.tau)) <= STILL
            ):
                continue
            self._posed[name] = (x, y, yaw, alive, t)
            event: dict[str, Any] = {
                "t": t,
                "agent": name,
                "event": "pose",
                "x": round(x, 3),
                "y": round(y, 3),
                "yaw": round(yaw, 3),
            }
            if self.alive is not None:
                event["alive"] = alive
            self.sink(event)

    def _objects(self, t: float) -> None:
        first, self._looked = not self._looked, True
        for name, obj in sorted(self.world.objects.items()):
            if obj.kind == "terrain" or (not first and not obj.movable):
                continue
            x, y, z = (float(v) for v in obj.position())
            last = self._placed.get(name)
            if last is not None and math.dist(last, (x, y, z)) <= MOVED:
                continue
            self._placed[name] = (x, y, z)
            event: dict[str, Any] = {
                "t": t,
                "agent": "-",
                "event": "object",
                "name": name,
                "kind": obj.kind,
                "x": round(x, 3),
                "y": round(y, 3),
                "z": round(z, 3),
            }
            if obj.sample_kind is not None:
                event["sample_kind"] = obj.sample_kind
            if last is None:
                event["size"] = round(obj.size, 3)
                if obj.radius > 0:
                    event["radius"] = round(obj.radius, 3)
            self.sink(event)

    def _map(self, t: float) -> None:
        assert self.team_map is not None
        grid = self.team_map()
        if grid is None:
            return
        occupancy, resolution = coarsened(grid.occupancy(), float(grid.resolution), MAP_RESOLUTION)
        height, width = occupancy.shape
        cells = (occupancy + 1).astype("uint8").tobytes()  # -1 unknown, 0 free, 1 occupied -> 0, 1, 2
        digest = hashlib.blake2b(cells, digest_size=8).hexdigest()
        if digest == self._map_digest:
            return
        self._map_digest = digest
        self.sink(
            {
                "t": t,
                "agent": "-",
                "event": "map",
                "origin": [round(float(grid.origin[0]), 3), round(float(grid.origin[1]), 3)],
                "resolution": resolution,
                "width": int(width),
                "height": int(height),
                "encoding": MAP_ENCODING,
                "cells": encode_cells(cells, int(width), int(height)),
            }
        )


def coarsened(occupancy: np.ndarray, resolution: float, target: float) -> tuple[np.ndarray, float]:
    """``occupancy`` (-1 unknown, 0 free, 1 occupied) in cells of the whole multiple of ``resolution`` nearest ``target``.

    A coarse cell is occupied when any of its cells is, else free when any is, else
    unknown; the grid is padded with unknown cells on its high sides to whole blocks.

    Returns:
        The coarse grid and its cell side in metres.
    """
    factor = max(1, round(target / resolution))
    if factor == 1:
        return occupancy, resolution
    height, width = occupancy.shape
    rows, cols = -(-height // factor), -(-width // factor)
    padded = np.full((rows * factor, cols * factor), -1, dtype=np.int8)
    padded[:height, :width] = occupancy
    blocks = padded.reshape(rows, factor, cols, factor)
    out = np.full((rows, cols), -1, dtype=np.int8)
    out[(blocks == 0).any(axis=(1, 3))] = 0
    out[(blocks == 1).any(axis=(1, 3))] = 1
    return out, resolution * factor
