"""The world server's messages: key expressions, the frame format, and the checks every payload passes.

A **frame** is a little-endian ``uint32`` header length, a JSON header (one
object), then the raw bytes of the arrays the header lists under ``"arrays"``
as ``[name, dtype, shape]`` (dtypes ``f8``, ``f4``, ``u1``, ``i4``, all
little-endian), one after the other. Small calls are JSON only; lidar scans,
camera pictures and arm paths travel as arrays. No pickle: decoding a frame
builds only dicts, lists, strings, numbers and numpy arrays of a listed dtype.

Every frame received is checked before use (:func:`decode`): its size
(:data:`MAX_FRAME`, :data:`MAX_HEADER`), the JSON (no ``NaN`` or ``Infinity``;
nesting deeper than the interpreter's recursion limit is refused), the
arrays' dtypes and shapes against the bytes present. The values are then checked by the one who reads them, with the helpers here
(:func:`number`, :func:`integer`, :func:`name`, ...), each raising
:class:`BadPayload` with a reason a log can count.

Keys, under the team's key prefix ``P``:

* ``P/world/alive``: the server's liveliness token;
* ``P/world/agent/NAME``: an agent's liveliness token (its robot is crashed when it leaves);
* ``P/world/call``: world calls (``info``, ``state``, ``obstacles``, ``blocker``, ``blocks_facts``, ``mesh``,
  ``tick``);
* ``P/world/robot/NAME/call``: calls on robot ``NAME`` (only its own agent's are served);
* ``P/world/state``: the state published after each world step (with the lidar scans asked for, as arrays
  ``scan/NAME``).
"""

from __future__ import annotations

import json
import math
import re
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alica.worldsim.errors import WorldError

__all__ = [
    "MAX_FRAME",
    "MAX_HEADER",
    "BadPayload",
    "Frame",
    "RobotState",
    "ThingState",
    "WorldState",
    "decode",
    "encode",
    "parse_state",
]

MAX_FRAME = 32 * 1024 * 1024
"""Largest frame accepted, bytes (a 1280x960 picture with float64 depth fits)."""
MAX_HEADER = 1024 * 1024
"""Largest JSON header accepted, bytes."""
MAX_ARRAYS = 256
"""Most arrays in one frame."""
MAX_NAME = 64
"""Longest robot, agent or object name."""
MAX_BOUND = 1e6
"""Largest magnitude of a coordinate or speed accepted."""
_DTYPES = {"f8": "<f8", "f4": "<f4", "u1": "|u1", "i4": "<i4"}
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_\-.]*$")
_LEN = struct.Struct("<I")


class BadPayload(WorldError):
    """A frame or a value in it that is refused (a :class:`~alica.worldsim.errors.WorldError`, so a client's
    caller sees a malformed answer as the world's error).

    Args:
        reason: a short word for counting (``size``, ``json``, ``type``, ``range``, ``array``, ...).
        message: what is wrong.
    """

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


def alive_key(prefix: str) -> str:
    """The server's liveliness token."""
    return f"{prefix}/world/alive"


def agent_key(prefix: str, agent: str) -> str:
    """Agent ``agent``'s liveliness token (``*`` for every agent)."""
    return f"{prefix}/world/agent/{agent}"


def call_key(prefix: str) -> str:
    """The world's queryable."""
    return f"{prefix}/world/call"


def robot_key(prefix: str, robot: str) -> str:
    """Robot ``robot``'s queryable."""
    return f"{prefix}/world/robot/{robot}/call"


def state_key(prefix: str) -> str:
    """The state publication."""
    return f"{prefix}/world/state"


@dataclass(frozen=True, slots=True)
class Frame:
    """A decoded frame: its JSON header and its arrays by name."""

    header: dict[str, Any]
    arrays: dict[str, np.ndarray] = field(default_factory=dict)


def encode(header: Mapping[str, Any], arrays: Mapping[str, np.ndarray] | None = None) -> bytes:
    """A frame of ``header`` (JSON-able, finite numbers) and ``arrays``.

    Raises:
        ValueError: a value JSON cannot hold, a non-finite number, or an array of another dtype.
    """
    listed: list[list[Any]] = []
    blobs: list[bytes] = []
    for key, array in (arrays or {}).items():
        code = f"{array.dtype.kind}{array.dtype.itemsize}"
        if code not in _DTYPES:
            raise ValueError(f"array {key!r} of dtype {array.dtype} cannot be sent; use one of {sorted(_DTYPES)}")
        listed.append([key, code, list(array.shape)])
        blobs.append(np.ascontiguousarray(array, dtype=_DTYPES[code]).tobytes())
    body = dict(header)
    if listed:
        body["arrays"] = listed
    text = json.dumps(body, allow_nan=False, separators=(",", ":")).encode()
    return b"".join((_LEN.pack(len(text)), text, *blobs))


def _no_constant(token: str) -> float:
    raise BadPayload("number", f"{token} is not a number a frame may carry")


def decode(data: bytes) -> Frame:
    """Check and decode a frame.

    Raises:
        BadPayload: too large, truncated, a header that is not a JSON object, too deep, with
            ``NaN``/``Infinity``, or arrays that do not match the bytes.
    """
    if len(data) > MAX_FRAME:
        raise BadPayload("size", f"a frame of {len(data)} bytes is over the limit of {MAX_FRAME}")
    if len(data) < _LEN.size:
        raise BadPayload("size", "a frame shorter than its length field")
    (n,) = _LEN.unpack_from(data)
    if n > MAX_HEADER or _LEN.size + n > len(data):
        raise BadPayload("size", f"a header of {n} bytes does not fit the frame or the limit of {MAX_HEADER}")
    try:
        header = json.loads(data[_LEN.size : _LEN.size + n].decode("utf-8"), parse_constant=_no_constant)
    except BadPayload:
        raise
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise BadPayload("json", f"the header is not JSON: {str(exc)[:80]}") from None
    if not isinstance(header, dict):
        raise BadPayload("json", "the header is not a JSON object")
    arrays: dict[str, np.ndarray] = {}
    listed = header.pop("arrays", [])
    if not isinstance(listed, list) or len(listed) > MAX_ARRAYS:
        raise BadPayload("array", f"'arrays' must be a list of at most {MAX_ARRAYS}")
    at = _LEN.size + n
    for item in listed:
        if not (isinstance(item, list) and len(item) == 3):
            raise BadPayload("array", "each array is [name, dtype, shape]")
        key, code, shape = item
        if not isinstance(key, str) or len(key) > 2 * MAX_NAME or key in arrays:
            raise BadPayload("array", "an array name must be a unique short string")
        if code not in _DTYPES:
            raise BadPayload("array", f"array {key!r}: dtype {code!r} is not one of {sorted(_DTYPES)}")
        if not (
            isinstance(shape, list)
            and len(shape) <= 4
            and all(isinstance(d, int) and not isinstance(d, bool) and 0 <= d <= MAX_FRAME for d in shape)
        ):
            raise BadPayload("array", f"array {key!r}: a shape is up to 4 sizes >= 0")
        dtype = np.dtype(_DTYPES[code])
        size = dtype.itemsize * math.prod(shape)
        if at + size > len(data):
            raise BadPayload("array", f"array {key!r} of shape {shape} is longer than the frame")
        arrays[key] = np.frombuffer(data, dtype=dtype, count=math.prod(shape), offset=at).reshape(shape)
        at += size
    if at != len(data):
        raise BadPayload("array", f"{len(data) - at} bytes after the arrays")
    return Frame(header, arrays)


# -- value checks ------------------------------------------------------------------------------------------


def number(value: Any, what: str, lo: float = -MAX_BOUND, hi: float = MAX_BOUND) -> float:
    """``value`` as a finite float in ``[lo, hi]``.

    Raises:
        BadPayload: not a number (booleans are not), not finite, or out of range.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise BadPayload("type", f"{what} must be a number, got {type(value).__name__}")
    x = float(value)
    if not math.isfinite(x):
        raise BadPayload("number", f"{what} must be finite")
    if not lo <= x <= hi:
        raise BadPayload("range", f"{what} must be in [{lo:g}, {hi:g}], got {x:g}")
    return x


def optional_number(value: Any, what: str, lo: float = -MAX_BOUND, hi: float = MAX_BOUND) -> float | None:
    """:func:`number`, or ``None``."""
    return None if value is None else number(value, what, lo, hi)


def integer(value: Any, what: str, lo: int, hi: int) -> int:
    """``value`` as an int in ``[lo, hi]``.

    Raises:
        BadPayload: not an int or out of range.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise BadPayload("type", f"{what} must be an integer, got {type(value).__name__}")
    if not lo <= value <= hi:
        raise BadPayload("range", f"{what} must be in [{lo}, {hi}], got {value}")
    return value


def flag(value: Any, what: str) -> bool:
    """``value`` as a bool.

    Raises:
        BadPayload: not a bool.
    """
    if not isinstance(value, bool):
        raise BadPayload("type", f"{what} must be true or false, got {type(value).__name__}")
    return value


def name(value: Any, what: str) -> str:
    """``value`` as a name (letters, digits, ``_``, ``-``, ``.``; at most :data:`MAX_NAME`).

    Raises:
        BadPayload: not such a string.
    """
    if not isinstance(value, str) or len(value) > MAX_NAME or not _NAME.match(value):
        raise BadPayload("name", f"{what} must be a name of at most {MAX_NAME} letters, digits, '_', '-', '.'")
    return value


def text(value: Any, what: str, limit: int = 4096) -> str:
    """``value`` as a string of at most ``limit`` characters.

    Raises:
        BadPayload: not such a string.
    """
    if not isinstance(value, str) or len(value) > limit:
        raise BadPayload("type", f"{what} must be a string of at most {limit} characters")
    return value


def numbers(value: Any, what: str, n: int, lo: float = -MAX_BOUND, hi: float = MAX_BOUND) -> tuple[float, ...]:
    """``value`` as ``n`` finite floats.

    Raises:
        BadPayload: not a list of ``n`` numbers in range.
    """
    if not isinstance(value, list) or len(value) != n:
        raise BadPayload("type", f"{what} must be a list of {n} numbers")
    return tuple(number(v, f"{what}[{i}]", lo, hi) for i, v in enumerate(value))


def triple(value: Any, what: str) -> tuple[float, float, float]:
    """``value`` as three finite floats ``(x, y, z)`` or ``(x, y, yaw)``."""
    x, y, z = numbers(value, what, 3)
    return (x, y, z)


def quaternion(value: Any, what: str) -> tuple[float, float, float, float]:
    """``value`` as a quaternion ``(x, y, z, w)`` of finite floats."""
    x, y, z, w = numbers(value, what, 4, -2.0, 2.0)
    return (x, y, z, w)


def pose(value: Any, what: str) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """``value`` as ``[[x, y, z], [qx, qy, qz, qw]]``."""
    if not isinstance(value, list) or len(value) != 2:
        raise BadPayload("type", f"{what} must be [position, quaternion]")
    return triple(value[0], f"{what} position"), quaternion(value[1], f"{what} quaternion")


def mapping(value: Any, what: str, limit: int = 10_000) -> dict[str, Any]:
    """``value`` as a JSON object of at most ``limit`` entries."""
    if not isinstance(value, dict) or len(value) > limit:
        raise BadPayload("type", f"{what} must be an object of at most {limit} entries")
    return value


def array(arrays: Mapping[str, np.ndarray], key: str, what: str, *, ndim: int, width: int | None = None) -> np.ndarray:
    """Array ``key`` of a frame: ``ndim`` dimensions (the last ``width`` long when given), finite values.

    Raises:
        BadPayload: missing, of another shape, or with non-finite values.
    """
    a = arrays.get(key)
    if a is None:
        raise BadPayload("array", f"{what}: array {key!r} is missing")
    if a.ndim != ndim or (width is not None and a.shape[-1] != width):
        raise BadPayload("array", f"{what}: array {key!r} has shape {a.shape}")
    if a.dtype.kind == "f" and not np.isfinite(a).all():
        raise BadPayload("number", f"{what}: array {key!r} holds non-finite values")
    return a


# -- the published state -------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class RobotState:
    """One robot as the last state or reply told it."""

    pose: tuple[float, float, float]
    estimate: tuple[float, float, float]
    crashed: bool
    bumped: bool
    arm_q: tuple[float, ...] | None = None
    arm_busy: bool = False
    arm_held: str | None = None


@dataclass(frozen=True, slots=True)
class ThingState:
    """One object as the last state told it."""

    kind: str
    size: float
    radius: float
    half_extents: tuple[float, ...]
    pose: tuple[tuple[float, float, float], tuple[float, float, float, float]]
    aabb: tuple[tuple[float, float, float], tuple[float, float, float]]
    footprint: dict[str, Any] | None


@dataclass(frozen=True, slots=True)
class WorldState:
    """The world after a step: time, robots and objects, and the order of states (``server``, ``version``).

    A full state (``static_names`` given) has every object; a published one only the movable objects:
    the static ones (rocks, tables, markers) stay as the last full state gave them while ``epoch``, the
    number of the set of static objects, stays the same.
    """

    server: int
    version: int
    step: int
    time: float
    robots: dict[str, RobotState]
    objects: dict[str, ThingState] | None
    epoch: int = 0
    static_names: frozenset[str] | None = None


def robot_state_json(
    pose: Sequence[float],
    estimate: Sequence[float],
    crashed: bool,
    bumped: bool,
    arm: tuple[Sequence[float] | np.ndarray, bool, str | None] | None,
) -> dict[str, Any]:
    """A robot's entry of a state."""
    out: dict[str, Any] = {
        "pose": [float(v) for v in pose],
        "estimate": [float(v) for v in estimate],
        "crashed": bool(crashed),
        "bumped": bool(bumped),
    }
    if arm is not None:
        q, busy, held = arm
        out["arm"] = {"q": [float(v) for v in q], "busy": bool(busy), "held": held}
    return out


def parse_robot(value: Any, what: str) -> RobotState:
    """Check a robot's entry of a state."""
    d = mapping(value, what, 8)
    arm = d.get("arm")
    q: tuple[float, ...] | None = None
    busy, held = False, None
    if arm is not None:
        a = mapping(arm, f"{what} arm", 4)
        q = numbers(a.get("q"), f"{what} arm q", 7, -100.0, 100.0)
        busy = flag(a.get("busy"), f"{what} arm busy")
        held = None if a.get("held") is None else name(a.get("held"), f"{what} arm held")
    return RobotState(
        pose=triple(d.get("pose"), f"{what} pose"),
        estimate=triple(d.get("estimate"), f"{what} estimate"),
        crashed=flag(d.get("crashed"), f"{what} crashed"),
        bumped=flag(d.get("bumped"), f"{what} bumped"),
        arm_q=q,
        arm_busy=busy,
        arm_held=held,
    )


_FOOTPRINT_KEYS = ("x", "y", "radius", "half_x", "half_y", "yaw")


def parse_thing(value: Any, what: str) -> ThingState:
    """Check an object's entry of a state."""
    d = mapping(value, what, 10)
    half = d.get("half_extents")
    if not isinstance(half, list) or len(half) > 3:
        raise BadPayload("type", f"{what} half_extents must be a list of up to 3 numbers")
    aabb = d.get("aabb")
    if not isinstance(aabb, list) or len(aabb) != 2:
        raise BadPayload("type", f"{what} aabb must be [lower, upper]")
    fp = d.get("footprint")
    footprint: dict[str, Any] | None = None
    if fp is not None:
        f = mapping(fp, f"{what} footprint", 8)
        kind = f.get("kind")
        if kind not in ("circle", "box"):
            raise BadPayload("type", f"{what} footprint kind must be circle or box")
        footprint = {"kind": kind, **{k: number(f.get(k, 0.0), f"{what} footprint {k}") for k in _FOOTPRINT_KEYS}}
    return ThingState(
        kind=name(d.get("kind"), f"{what} kind"),
        size=number(d.get("size"), f"{what} size", 0.0),
        radius=number(d.get("radius"), f"{what} radius", 0.0),
        half_extents=tuple(number(h, f"{what} half extent", 0.0) for h in half),
        pose=pose(d.get("pose"), f"{what} pose"),
        aabb=(triple(aabb[0], f"{what} aabb lower"), triple(aabb[1], f"{what} aabb upper")),
        footprint=footprint,
    )


def parse_state(header: Mapping[str, Any]) -> WorldState:
    """Check a state (published, or in a reply; ``objects`` may be left out of a reply).

    Raises:
        BadPayload: a value of the wrong type or out of range.
    """
    robots = mapping(header.get("robots", {}), "robots", 1000)
    objects = header.get("objects")
    statics = header.get("static_names")
    if statics is not None and not (isinstance(statics, list) and len(statics) <= 100_000):
        raise BadPayload("type", "static_names must be a list of names")
    return WorldState(
        epoch=integer(header.get("epoch", 0), "epoch", 0, 2**63),
        static_names=None if statics is None else frozenset(name(n, "static name") for n in statics),
        server=integer(header.get("server"), "server", 0, 2**63),
        version=integer(header.get("version"), "version", 0, 2**63),
        step=integer(header.get("step"), "step", 0, 2**63),
        time=number(header.get("t"), "time", 0.0, 1e12),
        robots={name(k, "robot name"): parse_robot(v, f"robot {k!r}") for k, v in robots.items()},
        objects=None
        if objects is None
        else {name(k, "object name"): parse_thing(v, f"object {k!r}") for k, v in mapping(objects, "objects").items()},
    )
