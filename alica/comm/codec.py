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

Before unpickling, :func:`decode` reads the pickle's opcodes without building
anything (:func:`scan`) and refuses (:class:`TooDeep`) a pickle whose
containers nest deeper than :data:`MAX_DEPTH`: CPython hashes a tuple without
a recursion check, so a tuple nested a million deep that a pickle makes a dict
key or a set member would crash the process inside the unpickler (issue 37).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib
import io
import pickle
import pickletools
import threading
from collections.abc import Iterator

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


MAX_DEPTH = 64
"""The deepest nesting of containers in a payload :func:`decode` takes (tuples, lists, dicts, sets, objects)."""


class CodecError(ValueError):
    """Bytes that are not a payload this process may decode; the message says why."""


class TooDeep(CodecError):
    """A pickle whose containers nest deeper than :data:`MAX_DEPTH` (refused before it is unpickled)."""


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
        TooDeep: the bytes nest containers deeper than :data:`MAX_DEPTH`
            (checked by :func:`scan` before anything is built).
        CodecError: the bytes are damaged, or name a class that is not an
            allowed dataclass or enum.
    """
    try:
        scan(data)
        return _Unpickler(io.BytesIO(data)).load()
    except CodecError:
        raise
    except Exception as exc:  # (damaged bytes raise many kinds of errors)
        raise CodecError(f"damaged payload ({type(exc).__name__}: {exc})") from None


# --- The scan: the depth of every object a pickle builds, read from its opcodes, before anything is built. ---
#
# Every item of the simulated stack is an int: its depth (0 for a leaf, 1 for an empty container, one more than
# its deepest member for a container) shifted left by _SHIFT, or-ed with an identity (0: none). An item that is
# memoized (or duplicated) gets an identity, so that a copy fetched from the memo has the depth its object has
# now, not the depth it had when memoized. An object fetched again (or duplicated) is "shared": a copy of it may
# sit in another container already, whose depth would be stale if the object grew deeper; a pickle of plain data
# never makes an object deeper after referring to it again (only a cycle does), so that is refused.
# An object that BUILD fills, or that REDUCE/NEWOBJ makes, counts as deep as its state or arguments (a dataclass's
# state is the list or dict of its fields): a class that kept its whole state as one field would nest one level
# more per object than counted, so at most twice the bound, far from what crashes the hash.

_SHIFT = 40
_SHARED = 1 << (_SHIFT - 1)
"""In a memo entry: its object was fetched before, so its depth no longer changes (a GET can take the entry as is)."""
_IDENT = _SHARED - 1
_LEVEL = tuple(depth << _SHIFT for depth in range(MAX_DEPTH * 4 + 2))
_CLASS = 1
"""The identity of every class or function a pickle names (GLOBAL, STACK_GLOBAL, EXT); BUILD never changes one."""

# The actions of the opcodes, in groups of six that the loop tests by range, then one by one: the single-byte
# opcodes (the most a pickle of a given size can hold) first, so that no pickle costs much more per byte than another.
(
    _PUSH,
    _POP,
    _MEMOIZE,
    _MARK,
    _EMPTY,
    _TUPLE1,
    _APPEND,
    _SETITEM,
    _TUPLE2,
    _TUPLE3,
    _TO_MARK,
    _FROM_MARK,
    _POP_MARK,
    _PUSH_LEN1,
    _GET1,
    _BUILD,
    _CALL,
    _STACK_GLOBAL,
    _DUP,
    _NOTHING,
    _PUSH_ARG1,
    _PUT1,
    _PUSH_ARG,
    _NEWOBJ_EX,
    _GET,
    _PUT,
    _PUSH_LEN4,
    _PUSH_LEN8,
    _PUSH_LINE,
    _GLOBAL,
    _PUSH_CLASS,
    _INST,
    _POP_PUSH,
    _SKIP,
    _STOP,
    _UNKNOWN,
) = range(36)

_ACTIONS: dict[str, int] = {
    "NONE": _PUSH,
    "NEWTRUE": _PUSH,
    "NEWFALSE": _PUSH,
    "NEXT_BUFFER": _PUSH,
    "BININT1": _PUSH_ARG1,
    "BININT": _PUSH_ARG,
    "BININT2": _PUSH_ARG,
    "BINFLOAT": _PUSH_ARG,
    "LONG1": _PUSH_LEN1,
    "SHORT_BINSTRING": _PUSH_LEN1,
    "SHORT_BINBYTES": _PUSH_LEN1,
    "SHORT_BINUNICODE": _PUSH_LEN1,
    "LONG4": _PUSH_LEN4,
    "BINSTRING": _PUSH_LEN4,
    "BINBYTES": _PUSH_LEN4,
    "BINUNICODE": _PUSH_LEN4,
    "BINBYTES8": _PUSH_LEN8,
    "BYTEARRAY8": _PUSH_LEN8,
    "BINUNICODE8": _PUSH_LEN8,
    "INT": _PUSH_LINE,
    "LONG": _PUSH_LINE,
    "STRING": _PUSH_LINE,
    "UNICODE": _PUSH_LINE,
    "FLOAT": _PUSH_LINE,
    "PERSID": _PUSH_LINE,
    "EXT1": _PUSH_CLASS,
    "EXT2": _PUSH_CLASS,
    "EXT4": _PUSH_CLASS,
    "GLOBAL": _GLOBAL,
    "MEMOIZE": _MEMOIZE,
    "BINPUT": _PUT1,
    "PUT": _PUT,
    "LONG_BINPUT": _PUT,
    "BINGET": _GET1,
    "GET": _GET,
    "LONG_BINGET": _GET,
    "MARK": _MARK,
    "POP": _POP,
    "POP_MARK": _POP_MARK,
    "DUP": _DUP,
    "TUPLE": _FROM_MARK,
    "LIST": _FROM_MARK,
    "DICT": _FROM_MARK,
    "FROZENSET": _FROM_MARK,
    "OBJ": _FROM_MARK,
    "TUPLE1": _TUPLE1,
    "TUPLE2": _TUPLE2,
    "TUPLE3": _TUPLE3,
    "EMPTY_TUPLE": _EMPTY,
    "EMPTY_LIST": _EMPTY,
    "EMPTY_DICT": _EMPTY,
    "EMPTY_SET": _EMPTY,
    "APPEND": _APPEND,
    "SETITEM": _SETITEM,
    "APPENDS": _TO_MARK,
    "SETITEMS": _TO_MARK,
    "ADDITEMS": _TO_MARK,
    "BUILD": _BUILD,
    "REDUCE": _CALL,
    "NEWOBJ": _CALL,
    "NEWOBJ_EX": _NEWOBJ_EX,
    "INST": _INST,
    "STACK_GLOBAL": _STACK_GLOBAL,
    "BINPERSID": _POP_PUSH,
    "READONLY_BUFFER": _NOTHING,
    "PROTO": _SKIP,
    "FRAME": _SKIP,
    "STOP": _STOP,
}


def _tables() -> tuple[tuple[int, ...], tuple[int, ...]]:
    """The action and the width of the fixed-size argument of each opcode byte (every opcode of :mod:`pickletools`)."""
    action = [_UNKNOWN] * 256
    width = [0] * 256
    for op in pickletools.opcodes:
        code = op.code.encode("latin-1")[0]
        action[code] = _ACTIONS[op.name]  # (a KeyError here: a Python with a new opcode, which the scan must learn)
        width[code] = op.arg.n if op.arg is not None and op.arg.n > 0 else 0
    return tuple(action), tuple(width)


_ACTION, _WIDTH = _tables()


def scan(data: bytes, limit: int = MAX_DEPTH) -> None:
    """Check, from its opcodes and without building anything, that the pickle ``data`` nests at most ``limit`` deep.

    The scan follows the unpickler's stack, marks and memo, keeping of each
    object only how deep it nests, up to the first STOP (where ``load``
    stops). It costs 40 to 135 ns per opcode on pickles made to be slow to scan
    (under 2 s for 16 MB), about 200 ns on team messages (``bench/codec_scan.py``).

    Raises:
        TooDeep: a container would nest deeper than ``limit``, or an object
            would grow deeper after the pickle referred to it again.
        CodecError: the opcodes are damaged (no STOP, an unknown opcode, a
            stack, mark or memo that lacks what an opcode takes, a memo index
            out of order, BUILD on a class or function).
    """
    if limit >= len(_LEVEL) - 1:
        raise ValueError(f"the depth limit is at most {len(_LEVEL) - 2}")
    try:
        _scan(data, limit)
    except CodecError:
        raise
    except (LookupError, ValueError, TypeError, ArithmeticError, StopIteration) as exc:
        raise CodecError(f"damaged payload ({type(exc).__name__} in its opcodes)") from None


def _too_deep(limit: int) -> TooDeep:
    return TooDeep(f"a payload nests containers deeper than {limit}")


def _scan(data: bytes, limit: int) -> None:  # (one loop, no call per opcode: a call would double the cost)
    action_of, width_of, level = _ACTION, _WIDTH, _LEVEL
    shift, ident_mask, fetched = _SHIFT, _IDENT, _SHARED
    over = level[limit + 1]  # an item at least this big is too deep
    stack: list[int] = []
    push, pop = stack.append, stack.pop
    marks: list[int] = []
    memo: list[int] = []
    depth_of = [0, 0]  # by identity (0: none, 1: a class or function)
    shared: set[int] = set()
    size = len(data)
    it = iter(data)
    move, left = it.__setstate__, it.__length_hint__  # type: ignore[attr-defined]
    for op in it:
        action = action_of[op]
        if action < 6:
            if action == _PUSH:
                push(0)
            elif action == _POP:
                if marks and marks[-1] == len(stack):
                    marks.pop()
                else:
                    pop()
            elif action == _MEMOIZE:
                value = stack[-1]
                if value and not value & ident_mask:
                    value |= len(depth_of)
                    depth_of.append(value >> shift)
                    stack[-1] = value
                memo.append(value)
            elif action == _MARK:
                marks.append(len(stack))
            elif action == _EMPTY:
                push(level[1])
            else:  # _TUPLE1
                value = level[(stack[-1] >> shift) + 1]
                if value >= over:
                    raise _too_deep(limit)
                stack[-1] = value
        elif action < 12:
            if action == _APPEND or action == _SETITEM:
                value = pop()
                if action == _SETITEM:
                    value = max(value, pop())
                value = level[(value >> shift) + 1]
                if value >= over:
                    raise _too_deep(limit)
                if value > stack[-1]:
                    _grow(stack, value, shared, depth_of)
            elif action == _TUPLE2 or action == _TUPLE3:
                value = pop()
                if action == _TUPLE3:
                    value = max(value, pop())
                value = level[(max(value, stack[-1]) >> shift) + 1]
                if value >= over:
                    raise _too_deep(limit)
                stack[-1] = value
            else:  # _TO_MARK (APPENDS, SETITEMS, ADDITEMS), _FROM_MARK (TUPLE, LIST, DICT, FROZENSET, OBJ)
                start = marks.pop()
                value = level[(max(stack[start:], default=0) >> shift) + 1]
                if value >= over:
                    raise _too_deep(limit)
                del stack[start:]
                if action == _FROM_MARK:
                    push(value)
                elif value > stack[-1]:  # the container below the mark holds members this deep
                    _grow(stack, value, shared, depth_of)
        elif action < 18:
            if action == _POP_MARK:
                start = marks.pop()
                if start < len(stack):
                    del stack[start:]
            elif action == _PUSH_LEN1:
                length = next(it)
                if length:
                    move(size - left() + length)
                push(0)
            elif action == _GET1:
                index = next(it)
                value = memo[index]
                if not value & fetched and value & ident_mask:  # the first fetch: the object's depth now
                    ident = value & ident_mask
                    shared.add(ident)
                    value = memo[index] = level[depth_of[ident]] | ident | fetched
                push(value)
            elif action == _BUILD:
                value = pop()  # (the state: a dict or list of the fields, as deep as the object it fills)
                if stack[-1] & ident_mask == _CLASS:
                    raise CodecError("a payload changes a class or a function it names (BUILD)")
                if value >> shift > stack[-1] >> shift:
                    _grow(stack, level[value >> shift], shared, depth_of)
            elif action == _CALL:  # REDUCE, NEWOBJ: a new object as deep as its arguments
                value = pop()
                stack[-1] = level[max(stack[-1], value) >> shift]
            else:  # _STACK_GLOBAL
                pop()
                stack[-1] = _CLASS
        elif action < 24:
            if action == _DUP:
                value = stack[-1]
                if value:  # (a leaf needs no identity: nothing makes it deeper)
                    ident = value & ident_mask
                    if not ident:
                        ident = len(depth_of)
                        depth_of.append(value >> shift)
                        value |= ident
                        stack[-1] = value
                    shared.add(ident)
                push(value)
            elif action == _NOTHING:
                pass
            elif action == _PUSH_ARG1:
                next(it)
                push(0)
            elif action == _PUT1:
                _put(stack, memo, next(it), depth_of)
            elif action == _PUSH_ARG:
                move(size - left() + width_of[op])
                push(0)
            else:  # _NEWOBJ_EX: (class, arguments, keywords)
                value = max(pop(), pop())
                stack[-1] = level[max(stack[-1], value) >> shift]
        elif action == _GET:
            index = _argument(data, it, op)
            value = memo[index]
            if not value & fetched and value & ident_mask:
                ident = value & ident_mask
                shared.add(ident)
                value = memo[index] = level[depth_of[ident]] | ident | fetched
            push(value)
        elif action == _PUT:
            _put(stack, memo, _argument(data, it, op), depth_of)
        elif action == _PUSH_LEN4 or action == _PUSH_LEN8:
            width = 4 if action == _PUSH_LEN4 else 8
            at = size - left()
            move(at + width + int.from_bytes(data[at : at + width], "little"))
            push(0)
        elif action == _PUSH_LINE or action == _GLOBAL or action == _INST:
            at = data.index(b"\n", size - left())
            if action != _PUSH_LINE:  # (module and name: two lines)
                at = data.index(b"\n", at + 1)
            move(at + 1)
            if action == _INST:
                start = marks.pop()
                value = level[(max(stack[start:], default=0) >> shift) + 1]
                if value >= over:
                    raise _too_deep(limit)
                del stack[start:]
                push(value)
            else:
                push(_CLASS if action == _GLOBAL else 0)
        elif action == _PUSH_CLASS:
            move(size - left() + width_of[op])
            push(_CLASS)
        elif action == _POP_PUSH:
            stack[-1] = 0
        elif action == _SKIP:
            move(size - left() + width_of[op])
        elif action == _STOP:
            return
        else:
            raise CodecError(f"damaged payload (unknown opcode {op:#04x})")
    raise CodecError("damaged payload (no STOP)")


def _argument(data: bytes, it: Iterator[int], op: int) -> int:
    """The memo index after a GET, PUT, LONG_BINGET or LONG_BINPUT opcode, ``it`` moved past it."""
    at = len(data) - it.__length_hint__()  # type: ignore[attr-defined]
    if op in (0x6A, 0x72):  # LONG_BINGET, LONG_BINPUT: 4 bytes
        end = at + 4
        if end > len(data):
            raise IndexError
        index = int.from_bytes(data[at:end], "little")
    else:  # GET, PUT: a decimal line
        end = data.index(b"\n", at)
        index = int(data[at:end])
        end += 1
    it.__setstate__(end)  # type: ignore[attr-defined]
    return index


def _put(stack: list[int], memo: list[int], index: int, depth_of: list[int]) -> None:
    """Put the top of ``stack`` in ``memo`` at ``index`` (PUT), giving it an identity first when it is a container."""
    if index > len(memo):  # (the pickler numbers its memo in order; a far index makes the unpickler allocate it)
        raise CodecError(f"damaged payload (memo index {index} out of order)")
    value = stack[-1]
    if value and not value & _IDENT:
        value |= len(depth_of)
        depth_of.append(value >> _SHIFT)
        stack[-1] = value
    if index == len(memo):
        memo.append(value)
    else:
        memo[index] = value


def _grow(stack: list[int], value: int, shared: set[int], depth_of: list[int]) -> None:
    """The object on top of ``stack`` holds members that make it as deep as ``value`` (deeper than it was)."""
    ident = stack[-1] & _IDENT
    if ident:
        if ident in shared:
            raise TooDeep("a payload makes an object deeper after referring to it again (a cycle)")
        depth_of[ident] = value >> _SHIFT
    stack[-1] = value | ident
