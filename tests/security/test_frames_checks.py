"""Issue 37: no frame can hurt an agent. The pure checks of alica.comm.frames, and a fuzzer over the decoder."""

from __future__ import annotations

import pickle
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.comm import frames
from alica.comm.codec import encode
from alica.comm.reliable import History

GOOD = (1, "a", "news", 1, 1, 1, 2.0, encode("hello"))


def deep_tuple(depth: int) -> object:
    value: object = "leaf"
    for _ in range(depth):
        value = (value,)
    return value


def deep_frame(depth: int) -> bytes:
    """The bytes of a frame whose topic is a tuple nested ``depth`` deep, written opcode by opcode (no recursion)."""
    payload = encode("x")
    return b"".join(
        [
            b"\x80\x05(K\x01\x8c\x01a",  # PROTO 5, MARK, 1, "a"
            b"\x8c\x04leaf" + b"\x85" * depth,  # "leaf", then TUPLE1 ``depth`` times
            b"K\x01K\x01K\x01G" + struct.pack(">d", 2.0),
            b"C" + bytes([len(payload)]) + payload,
            b"t.",
        ]
    )


def test_a_good_frame_passes():
    assert frames.frame(frames.load(encode(GOOD), 8)) == GOOD


@pytest.mark.parametrize(
    ("index", "bad", "reason"),
    [
        (0, "1", frames.Reason.NUMBER),  # incarnation not an int
        (0, float("inf"), frames.Reason.NUMBER),
        (0, 2**64, frames.Reason.NUMBER),
        (0, True, frames.Reason.NUMBER),
        (1, ["a"], frames.Reason.SENDER),  # unhashable sender
        (1, "x" * 1000, frames.Reason.SENDER),
        (2, ("news",), frames.Reason.TOPIC),
        (2, "t" * 1000, frames.Reason.TOPIC),
        (3, 0, frames.Reason.NUMBER),
        (4, "1", frames.Reason.NUMBER),  # non-int rseq
        (4, -1, frames.Reason.NUMBER),
        (6, float("nan"), frames.Reason.NUMBER),
        (7, "not bytes", frames.Reason.SHAPE),
    ],
)
def test_each_bad_field_is_rejected_with_its_reason(index, bad, reason):
    value = list(GOOD)
    value[index] = bad
    with pytest.raises(frames.BadFrame) as caught:
        frames.frame(frames.load(encode(tuple(value)), 8))
    assert caught.value.reason is reason


def test_a_topic_nested_100000_deep_is_rejected_without_recursion():
    data = deep_frame(100_000)
    assert frames.load(deep_frame(3), 8)[2] == ((("leaf",),),)  # the same bytes, shallow: decoded
    with pytest.raises(frames.BadFrame, match="topic"):
        frames.frame(frames.load(deep_frame(3), 8))
    with pytest.raises(frames.BadFrame) as caught:
        frames.load(data, 8)
    assert caught.value.reason is frames.Reason.NESTING


def test_sizes_and_shapes_are_bounded():
    with pytest.raises(frames.BadFrame, match="size"):
        frames.load(b"x" * (frames.MAX_FRAME_BYTES + 1), 8)
    with pytest.raises(frames.BadFrame, match="undecodable"):
        frames.load(b"\x80\x05garbage", 8)
    with pytest.raises(frames.BadFrame, match="shape"):
        frames.load(encode((1, 2)), 8)
    with pytest.raises(frames.BadFrame, match="shape"):
        frames.load(encode([1] * 8), 8)


def test_heartbeats_questions_and_answers_are_checked():
    assert frames.heartbeat((1, "a", {"news": 3})) == (1, "a", {"news": 3})
    for bad in ((1, "a", ["news"]), (1, "a", {"news": "3"}), ("1", "a", {}), (1, "a", {("x",): 1})):
        with pytest.raises(frames.BadFrame):
            frames.heartbeat(bad)
    assert frames.question(("b", 1, {"news": (None, 0.0)})) == ("b", 1, {"news": (None, 0.0)})
    for bad in (("b", 1, {"news": 5}), ("b", 1, {"news": (1, float("nan"))}), ("b", 1, [])):
        with pytest.raises(frames.BadFrame):
            frames.question(bad)  # before: History.answer raised TypeError on such entries
    assert frames.answer((1, "a", (b"x",), {"n": 1}, {"n": 1}))[2] == (b"x",)
    for bad in ((1, "a", 5, {}, {}), (1, "a", ("x",), {}, {}), (1, "a", (), [], {})):
        with pytest.raises(frames.BadFrame):
            frames.answer(bad)


def test_a_checked_question_is_answered():
    history = History(1, seconds=10.0, max_bytes=1e6)
    _, incarnation, wanted = frames.question(("b", 1, {"news": (None, 0.0)}))
    assert history.answer(incarnation, wanted) == ((), {"news": 1}, {"news": 1})


def test_nesting_counts_dataclasses_and_dicts():
    frames.check_nesting({"a": [1, (2, 3)]})
    with pytest.raises(frames.BadFrame):
        frames.check_nesting(deep_tuple(frames.MAX_DEPTH + 1))
    frames.check_nesting(deep_tuple(frames.MAX_DEPTH))
    with pytest.raises(frames.BadFrame):
        frames.check_nesting(list(range(10)), items=5)


values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=300) | st.binary(max_size=50),
    lambda inner: (
        st.tuples(inner, inner) | st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=30,
)
CHECKS = {8: frames.frame, 3: frames.heartbeat, 5: frames.answer}


def _decode_and_check(data: bytes) -> None:
    """What the transport does with bytes: either a checked value or BadFrame, never another exception."""
    for size, check in CHECKS.items():
        try:
            check(frames.load(data, size))
        except frames.BadFrame as bad:
            assert isinstance(bad.reason, frames.Reason)
    try:
        frames.question(frames.load(data, 3))
    except frames.BadFrame:
        pass


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=200))
def test_fuzz_arbitrary_bytes_never_raise_anything_but_bad_frame(data):
    _decode_and_check(data)
    _decode_and_check(b"\x80\x05" + data)


@settings(max_examples=300, deadline=None)
@given(st.lists(values, min_size=3, max_size=8).map(tuple) | values)
def test_fuzz_arbitrary_values_never_raise_anything_but_bad_frame(value):
    _decode_and_check(pickle.dumps(value, protocol=5))


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 7), values)
def test_fuzz_one_field_of_a_good_frame_replaced(index, bad):
    value = list(GOOD)
    value[index] = bad
    _decode_and_check(pickle.dumps(tuple(value), protocol=5))
