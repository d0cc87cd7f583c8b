"""Payloads as bytes for a middleware: pickle out, a restricted unpickler in.

The simulated network passes payloads by reference; a transport between
processes must turn them into bytes. Payloads are plain immutable data
(:mod:`alica.comm.transport`): tuples, ``str``, numbers, ``None``, and frozen
dataclasses, named tuples and enums made of those. :func:`encode` pickles them (the C
pickler is the fastest encoder of such data in the standard library);
:func:`decode` unpickles with an unpickler that loads no class except the
message classes of an allow-list (:data:`MESSAGES`: what the team sends, and
whatever a user's skills add with :func:`allow_module`). A peer on the network
therefore cannot make a receiver import a module, create a class or call a
function: a plain ``pickle.loads`` would run any code the sender asked for. An
enum of the list is only ever looked up by its value (a pickle that calls it
with more arguments, which would create a new enum class, is refused).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib
import io
import pickle
import threading

MESSAGES: frozenset[tuple[str, str]] = frozenset(
    {
        ("alica.engine.sync", "SyncTalk"),
        ("alica.engine.team", "AuthorityClaim"),
        ("alica.engine.team", "Claim"),
        ("alica.engine.team", "TeamMessage"),
        ("alica.lang.fact", "Fact"),
        ("alica.prophet.board", "PlanShare"),
        ("alica.prophet.board", "ReplanRequest"),
        ("alica.prophet.board", "ShareStatus"),
        ("alica.prophet.magic.messages", "Final"),
        ("alica.prophet.magic.messages", "Result"),
        ("alica.prophet.magic.messages", "Share"),
        ("alica.prophet.planner", "PlanStatus"),
        ("alica.prophet.planner", "PlanStep"),
        ("alica.prophet.search.anytime", "FirstSearch"),
        ("alica.worldmodel.delta", "Add"),
        ("alica.worldmodel.delta", "Delta"),
        ("alica.worldmodel.delta", "Key"),
        ("alica.worldmodel.delta", "Write"),
        ("alica.worldmodel.stamp", "Stamp"),
    }
)
"""(module, class) of every message class the team sends (the engine, the world model, pRoPhEt and MAGiC);
:func:`decode` builds these and no other ``alica`` class (issue 37)."""

#: Module prefixes of users' messages (:func:`allow_module`) whose dataclasses, named tuples and enums decode.
_ALLOWED: set[str] = set()
_LOCK = threading.Lock()
_CACHE: dict[tuple[str, str], type] = {}

_PROTOCOL = 5


class CodecError(ValueError):
    """Bytes that are not a payload this process may decode; the message says why."""


def allow_module(prefix: str) -> None:
    """Let :func:`decode` build the dataclasses and enums of modules starting with ``prefix``.

    A user whose skills publish their own frozen dataclasses (``myrobots.msgs``)
    allows their module once, in every agent process, before the team runs.

    Args:
        prefix: a module name (``"myrobots.msgs"``) or a package prefix ending
            in a dot (``"myrobots."``).

    Raises:
        ValueError: ``prefix`` is empty or not a string.
    """
    if not isinstance(prefix, str) or not prefix.strip("."):
        raise ValueError(f"allow_module needs a module name such as 'myrobots.msgs', got {prefix!r}")
    with _LOCK:
        _ALLOWED.add(prefix)


def _allowed(module: str) -> bool:
    for prefix in _ALLOWED:
        if prefix.endswith("."):
            if module.startswith(prefix):
                return True
        elif module == prefix or module.startswith(prefix + "."):
            return True
    return False


class _Unpickler(pickle.Unpickler):
    """Loads only the dataclasses and enums of allowed modules (and no function, no other class)."""

    def find_class(self, module: str, name: str) -> type:
        key = (module, name)
        cached = _CACHE.get(key)
        if cached is not None:
            return cached
        if key not in MESSAGES and not _allowed(module):
            raise CodecError(
                f"a payload names {module}.{name}, and module '{module}' is not allowed; "
                "call alica.comm.codec.allow_module() with it in every agent process"
            )
        try:
            found = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError) as exc:
            raise CodecError(f"a payload names {module}.{name}, which this process does not have: {exc}") from None
        if not isinstance(found, type) or not (
            dataclasses.is_dataclass(found) or issubclass(found, enum.Enum) or _named_tuple(found)
        ):
            raise CodecError(f"a payload names {module}.{name}, which is not a dataclass, a named tuple or an enum")
        if issubclass(found, enum.Enum):
            found = _by_value(found)
        _CACHE[key] = found
        return found


def _by_value(cls: type[enum.Enum]) -> type:
    """``cls`` as the unpickler may call it: looked up by one value, never called to make a new enum class."""

    def member(value: object) -> enum.Enum:
        return cls(value)

    return member  # type: ignore[return-value]


def _named_tuple(cls: type) -> bool:
    return issubclass(cls, tuple) and isinstance(getattr(cls, "_fields", None), tuple)


def encode(payload: object) -> bytes:
    """The bytes of a payload.

    Raises:
        CodecError: the payload cannot be pickled (a lambda, an open file, ...).
    """
    try:
        return pickle.dumps(payload, protocol=_PROTOCOL)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        raise CodecError(f"a payload must be plain data (tuples, str, numbers, frozen dataclasses): {exc}") from None


def decode(data: bytes) -> object:
    """The payload of bytes made by :func:`encode` in any process of the team.

    Raises:
        CodecError: the bytes are damaged, or name a class that is not an
            allowed dataclass or enum.
    """
    try:
        return _Unpickler(io.BytesIO(data)).load()
    except CodecError:
        raise
    except Exception as exc:  # (damaged bytes raise many kinds of errors)
        raise CodecError(f"damaged payload ({type(exc).__name__}: {exc})") from None
