"""One team map, shared through the replicated world model, tile by tile.

The world model (:mod:`alica.worldmodel`) is a CRDT of last-writer-wins
registers and grow-only sets. A map written into one register per cell, or
one per tile, by every robot would lose observations whenever two robots
wrote the same key during a partition (the later write wins). So every robot
keeps its **own layer** (a :class:`~alica.skills.mapping.grid.LogOddsGrid` of
only its own scans) and is the **only writer** of its layer's tiles:

* ``map_frame() = (resolution, x0, y0, nx, ny)``: the grid's frame, written by
  the first robot that maps (every robot derives the same one from the
  field's bounds and the plan's resolution);
* ``map_tile(robot, tj, ti) = (version, resolution, payload)``: the robot's
  log-odds in tile ``(tj, ti)`` (:data:`~alica.skills.mapping.grid.TILE` cells
  square), quantised to int8 steps of :data:`QUANTUM`, zlib-compressed and
  Ascii85-encoded; ``version`` counts the robot's writes of that tile;
* ``map_index(robot) = (count, payload)``: which tiles the robot has written,
  as a compressed bit mask over the tiles (rewritten only when a new tile
  appears), and the set ``map_robots`` of the robots with a layer, so that a
  reader finds every tile without listing every register.

The **team map** (:func:`team_map`) is the sum of all layers, clamped: the
usual fusion of independent log-odds observations. As no two robots write the
same key, merging replicas in any order keeps every robot's newest layer:
after a partition heals, all replicas hold the same tiles and compute the same
team map, and nothing seen on either side is lost; a robot that joins late
receives the tiles with the world model's snapshot or digest exchange. Only
tiles whose sent (quantised) content changed are written
(:meth:`RobotMapper.publish`), at most once per publish, so a robot standing
still in a mapped area sends nothing.
"""

from __future__ import annotations

import base64
import math
import weakref
import zlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alica.skills.mapping.grid import L_MAX, L_MIN, THRESHOLD, TILE, LogOddsGrid
from alica.worldmodel.encoding import encode
from alica.worldmodel.protocol import WorldModelLike

__all__ = [
    "FRAME",
    "INDEX",
    "QUANTUM",
    "ROBOTS",
    "TILE_REGISTER",
    "RobotMapper",
    "decode_tile",
    "encode_tile",
    "team_map",
    "team_map_changes",
    "team_resolution",
]

#: The register holding the map's frame.
FRAME = "map_frame"
#: The register of one robot's tile.
TILE_REGISTER = "map_tile"
#: The register of one robot's tile index (which tiles it wrote).
INDEX = "map_index"
#: The grow-only set of the robots with a layer.
ROBOTS = "map_robots"
#: Log-odds step of the int8 tiles that are sent.
QUANTUM = 0.1
#: A tile is sent again when a cell's log-odds moved this much since it was last sent (or a cell changed class).
RESEND = 1.0
#: Seconds between two publishes of a robot's changed tiles (see :meth:`RobotMapper.publish`).
PUBLISH_PERIOD = 1.0
#: Bytes of a write's stamp and framing on the wire, besides its name, arguments and value (an estimate).
WRITE_OVERHEAD = 24


def quantize(logodds: np.ndarray) -> np.ndarray:
    """Log-odds as int8 steps of :data:`QUANTUM`."""
    return np.clip(np.rint(logodds / QUANTUM), -127, 127).astype(np.int8)


def encode_tile(logodds: np.ndarray) -> str:
    """A tile's log-odds as text: int8 steps of :data:`QUANTUM`, zlib-compressed, Ascii85."""
    return _encode_steps(quantize(logodds))


def _encode_steps(steps: np.ndarray) -> str:
    return base64.b85encode(zlib.compress(steps.tobytes(), 9)).decode("ascii")


def significant(old: np.ndarray, new: np.ndarray) -> bool:
    """Whether a tile changed enough to send again: a cell changed its class, or its log-odds by :data:`RESEND`."""
    t = THRESHOLD / QUANTUM

    def classes(q: np.ndarray) -> np.ndarray:
        return (q > t).astype(np.int8) - (q < -t).astype(np.int8)

    if np.abs(new.astype(np.int16) - old).max(initial=0) * QUANTUM >= RESEND - 1e-9:
        return True
    return bool((classes(old) != classes(new)).any())


def decode_tile(payload: str, shape: tuple[int, int]) -> np.ndarray:
    """The float32 log-odds of a tile from :func:`encode_tile`'s text.

    Raises:
        ValueError: the payload is not a tile of that shape.
    """
    return _steps(payload, shape).astype(np.float32) * np.float32(QUANTUM)


def _steps(payload: str, shape: tuple[int, int]) -> np.ndarray:
    """A tile's int8 log-odds steps."""
    try:
        raw = zlib.decompress(base64.b85decode(payload.encode("ascii")))
    except (ValueError, zlib.error) as exc:
        raise ValueError(f"not a map tile: {exc}") from None
    if len(raw) != shape[0] * shape[1]:
        raise ValueError(f"a map tile of {len(raw)} cells where {shape[0]} x {shape[1]} were expected")
    return np.frombuffer(raw, dtype=np.int8).reshape(shape)


def encode_mask(mask: np.ndarray) -> str:
    """A boolean tile mask as text (packed bits, zlib, Ascii85)."""
    return base64.b85encode(zlib.compress(np.packbits(mask.reshape(-1)).tobytes(), 9)).decode("ascii")


def decode_mask(payload: str, shape: tuple[int, int]) -> np.ndarray:
    """The boolean tile mask of :func:`encode_mask`'s text.

    Raises:
        ValueError: the payload is not a mask of that shape.
    """
    try:
        raw = zlib.decompress(base64.b85decode(payload.encode("ascii")))
    except (ValueError, zlib.error) as exc:
        raise ValueError(f"not a tile index: {exc}") from None
    bits = np.unpackbits(np.frombuffer(raw, dtype=np.uint8))
    n = shape[0] * shape[1]
    if len(bits) < n:
        raise ValueError(f"a tile index of {len(bits)} tiles where {n} were expected")
    return bits[:n].reshape(shape).astype(bool)


def frame_of(grid: LogOddsGrid) -> tuple[float, float, float, int, int]:
    """The ``map_frame`` value of a grid."""
    return (grid.resolution, grid.origin[0], grid.origin[1], grid.nx, grid.ny)


def write_bytes(name: str, args: tuple[object, ...], value: object) -> int:
    """The size of one register write on the wire: its canonical text plus :data:`WRITE_OVERHEAD`."""
    return len(name) + len(encode(args)) + len(encode(value)) + WRITE_OVERHEAD


def _frame(world_model: WorldModelLike) -> tuple[float, float, float, int, int] | None:
    value = world_model.get(FRAME)
    if not (isinstance(value, tuple) and len(value) == 5):
        return None
    res, x0, y0, nx, ny = value
    return (float(res), float(x0), float(y0), int(nx), int(ny))


class RobotMapper:
    """One robot's layer of the team map: scans go in, changed tiles go out to the world model.

    Make it with :meth:`for_robot`, which resumes the robot's layer from its
    own tiles in the world model (a skill that starts again, or a robot that
    restarts, continues its layer instead of overwriting it with a blank one).

    Attributes:
        robot: the robot's name (its tiles' first argument).
        period: seconds between two publishes (see :meth:`publish`).
        layer: the robot's own log-odds (only its scans).
        bytes_sent: bytes of the tile writes so far (see :func:`write_bytes`).
        tiles_sent: tile writes so far.
    """

    def __init__(
        self, world_model: WorldModelLike | None, robot: str, layer: LogOddsGrid, *, period: float = PUBLISH_PERIOD
    ) -> None:
        self.world_model = world_model
        self.period = float(period)
        self.last_publish = -math.inf
        self.robot = robot
        self.layer = layer
        self.versions: dict[tuple[int, int], int] = {}
        self.sent: dict[tuple[int, int], np.ndarray] = {}
        self.pending: set[tuple[int, int]] = set()
        self.index = np.zeros(layer.tile_shape, dtype=bool)
        self.bytes_sent = 0
        self.tiles_sent = 0

    @classmethod
    def for_robot(
        cls,
        world_model: WorldModelLike | None,
        robot: str,
        bounds: tuple[float, float, float, float],
        resolution: float,
    ) -> RobotMapper:
        """The robot's mapper on the team's frame (or a new frame over ``bounds`` at ``resolution``).

        When the world model already has a frame, its resolution must be ``resolution``.

        Raises:
            ValueError: bad bounds or resolution, or a team frame of another resolution.
        """
        layer = LogOddsGrid.covering(bounds, resolution)
        frame = _frame(world_model) if world_model is not None else None
        if frame is not None:
            res, x0, y0, nx, ny = frame
            if not math.isclose(res, layer.resolution, rel_tol=1e-9):
                raise ValueError(f"the team map has {res} m cells, not {resolution} m")
            layer = LogOddsGrid((x0, y0), res, nx, ny)
        elif world_model is not None:
            world_model.set(FRAME, value=frame_of(layer))
        mapper = cls(world_model, robot, layer)
        if world_model is not None:
            for tj, ti, value in _tiles_of(world_model, robot, layer):
                view = layer.tile(tj, ti)
                try:
                    view[...] = decode_tile(str(value[2]), view.shape)
                except ValueError:
                    continue
                mapper.versions[(tj, ti)] = int(value[0])  # type: ignore[call-overload]
                mapper.sent[(tj, ti)] = quantize(view)
                mapper.index[tj, ti] = True
        return mapper

    def add_scan(
        self, pose: tuple[float, float, float], ranges: np.ndarray, angles: np.ndarray, max_range: float
    ) -> int:
        """Ray trace one scan into the robot's layer (see :meth:`LogOddsGrid.update`); the cells updated."""
        return self.layer.update(pose, ranges, angles, max_range)

    def publish(self, *, now: float | None = None, force: bool = False) -> int:
        """Write the tiles that changed significantly (see :func:`significant`) to the world model.

        Args:
            now: the time; a publish within :attr:`period` seconds of the last one sends nothing
                (the changes wait for the next), so a robot scanning often sends each tile at most
                once a period. ``None`` publishes now.
            force: send now every tile that changed at all since it was last sent.

        Returns:
            The bytes written.
        """
        if not force and now is not None and now - self.last_publish < self.period:
            return 0
        if now is not None:
            self.last_publish = now
        tiles = self.layer.take_dirty_tiles()
        if force:
            tiles = sorted(set(tiles) | self.pending)
        wm = self.world_model
        if wm is None or not tiles:
            return 0
        sent = 0
        grown = False
        for tj, ti in tiles:
            steps = quantize(self.layer.tile(tj, ti))
            old = self.sent.get((tj, ti))
            if old is not None and not (force and not np.array_equal(old, steps)) and not significant(old, steps):
                self.pending.add((tj, ti))
                continue  # no cell changed its class nor moved by RESEND since the last send: later
            self.pending.discard((tj, ti))
            self.sent[(tj, ti)] = steps
            payload = _encode_steps(steps)
            version = self.versions.get((tj, ti), 0) + 1
            self.versions[(tj, ti)] = version
            value = (version, self.layer.resolution, payload)
            wm.set(TILE_REGISTER, self.robot, tj, ti, value=value)
            sent += write_bytes(TILE_REGISTER, (self.robot, tj, ti), value)
            self.tiles_sent += 1
            if not self.index[tj, ti]:
                self.index[tj, ti] = True
                grown = True
        if grown:
            index = (int(self.index.sum()), encode_mask(self.index))
            wm.set(INDEX, self.robot, value=index)
            sent += write_bytes(INDEX, (self.robot,), index)
            if wm.add_to_set(ROBOTS, self.robot):
                sent += len(ROBOTS) + len(encode(self.robot)) + WRITE_OVERHEAD
        self.bytes_sent += sent
        return sent


def _tiles_of(
    world_model: WorldModelLike, robot: str, grid: LogOddsGrid, masks: dict[str, tuple[str, np.ndarray]] | None = None
) -> list[tuple[int, int, tuple[object, ...]]]:
    """``(tj, ti, value)`` of the tiles of ``robot``'s layer stored in the world model, on ``grid``'s frame."""
    index = world_model.get(INDEX, robot)
    if not (isinstance(index, tuple) and len(index) == 2 and isinstance(index[1], str)):
        return []
    cached = masks.get(robot) if masks is not None else None
    if cached is not None and cached[0] == index[1]:
        mask = cached[1]
    else:
        try:
            mask = decode_mask(index[1], grid.tile_shape)
        except ValueError:
            return []
        if masks is not None:
            masks[robot] = (index[1], mask)
    out: list[tuple[int, int, tuple[object, ...]]] = []
    for tj, ti in zip(*np.nonzero(mask), strict=True):
        value = world_model.get(TILE_REGISTER, robot, int(tj), int(ti))
        if isinstance(value, tuple) and len(value) == 3 and value[1] == grid.resolution:
            out.append((int(tj), int(ti), value))
    return out


@dataclass
class _Merged:
    """A replica's team map, kept up to date tile by tile (``total``: the summed int8 steps, exact in any order)."""

    frame: tuple[float, float, float, int, int]
    total: np.ndarray
    grid: LogOddsGrid
    seen: dict[tuple[str, int, int], tuple[int, np.ndarray]] = field(default_factory=dict)
    masks: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)
    revision: int = 0
    tile_revisions: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int64))


_MERGED: weakref.WeakKeyDictionary[Any, _Merged] = weakref.WeakKeyDictionary()


def team_resolution(world_model: WorldModelLike | None) -> float | None:
    """The cell size of the team's map in ``world_model`` (what :func:`team_map` would have), without merging it."""
    frame = _frame(world_model) if world_model is not None else None
    return frame[0] if frame is not None else None


def team_map(world_model: WorldModelLike | None) -> LogOddsGrid | None:
    """The team's map in ``world_model``: every robot's layer summed and clamped; ``None`` before anyone mapped.

    The grid is cached per replica and updated in place for the tiles whose
    version changed: treat it as read-only (``copy()`` it to change it).
    """
    if world_model is None:
        return None
    frame = _frame(world_model)
    if frame is None:
        return None
    try:
        merged = _MERGED.get(world_model)
    except TypeError:  # not weakly referenceable: no cache
        merged = None
    if merged is None or merged.frame != frame:
        res, x0, y0, nx, ny = frame
        grid = LogOddsGrid((x0, y0), res, nx, ny)
        merged = _Merged(frame, np.zeros(grid.logodds.shape, dtype=np.int32), grid)
        merged.tile_revisions = np.zeros(grid.tile_shape, dtype=np.int64)
        try:
            _MERGED[world_model] = merged
        except TypeError:
            pass
    grid = merged.grid
    for robot in sorted(str(r) for r in world_model.members(ROBOTS)):
        for tj, ti, value in _tiles_of(world_model, robot, grid, merged.masks):
            _merge_tile(merged, (robot, tj, ti), value)
    return grid


def team_map_changes(world_model: WorldModelLike | None, since: int) -> tuple[int, np.ndarray] | None:
    """What changed in :func:`team_map`'s cached grid of ``world_model`` since its revision ``since``.

    Returns ``(revision, tiles)``: the grid's revision now (it grows by one with
    every tile merged into it) and a boolean ``tile_shape`` mask of the tiles
    merged after revision ``since``. ``None`` when the replica keeps no cached
    grid (no map yet, or a world model that cannot be weakly referenced): then
    every :func:`team_map` call gives a new grid. Call :func:`team_map` first;
    this only reads its cache.
    """
    if world_model is None:
        return None
    try:
        merged = _MERGED.get(world_model)
    except TypeError:
        return None
    if merged is None:
        return None
    return merged.revision, merged.tile_revisions > since


def _merge_tile(merged: _Merged, key: tuple[str, int, int], value: tuple[object, ...]) -> None:
    """Replace a robot's old version of a tile in the team map by the new one."""
    grid = merged.grid
    old = merged.seen.get(key)
    if old is not None and old[0] == value[0]:
        return
    rows = slice(key[1] * TILE, (key[1] + 1) * TILE)
    cols = slice(key[2] * TILE, (key[2] + 1) * TILE)
    window = merged.total[rows, cols]
    try:
        tile = _steps(str(value[2]), window.shape).astype(np.int32)
    except ValueError:
        return
    if old is not None:
        window -= old[1]
    window += tile
    merged.seen[key] = (int(value[0]), tile)  # type: ignore[call-overload]
    merged.revision += 1
    merged.tile_revisions[key[1], key[2]] = merged.revision
    grid.logodds[rows, cols] = np.clip(window * np.float32(QUANTUM), L_MIN, L_MAX)
