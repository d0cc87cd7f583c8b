"""Issue 37, item 10: the codec builds only the message classes the team sends."""

from __future__ import annotations

import enum
import pickle

import pytest

from alica.comm.codec import MESSAGES, CodecError, decode, encode
from alica.engine.team import TeamMessage
from alica.prophet.board import ShareStatus


def test_a_class_of_alica_that_is_no_message_is_refused():
    from alica.clock import ManualClock  # a class of alica, not a message

    with pytest.raises(CodecError, match="not allowed"):
        decode(pickle.dumps(ManualClock, protocol=5))


def test_an_enum_of_alica_that_is_no_message_is_refused():
    from alica.prophet.planner import Feature  # before: any enum of an alica module was built

    with pytest.raises(CodecError, match="not allowed"):
        decode(pickle.dumps(next(iter(Feature)), protocol=5))


def test_an_enum_message_is_only_looked_up_by_value():
    # a pickle calling ShareStatus('Evil', 'a b') (Enum's functional API) is refused
    head = b"\x80\x05\x8c\x13alica.prophet.board\x94\x8c\x0bShareStatus\x94\x93\x94"
    with pytest.raises(CodecError):
        decode(head + b"\x8c\x04Evil\x94\x8c\x03a b\x94\x86\x94R\x94.")


def test_every_listed_message_class_exists_and_round_trips_an_enum():
    import importlib

    for module, name in MESSAGES:
        assert isinstance(getattr(importlib.import_module(module), name), type)
    member = next(iter(ShareStatus))
    assert decode(encode(member)) is member
    assert isinstance(member, enum.Enum)


def test_a_team_message_is_still_decoded():
    assert "TeamMessage" in {name for _, name in MESSAGES}
    assert TeamMessage.__module__ == "alica.engine.team"
