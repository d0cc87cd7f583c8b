"""Typed slots of the scratch space (alica.skills.scratch) and the Verify2DObject steps' contract through them."""

from __future__ import annotations

from dataclasses import FrozenInstanceError

import pytest

from alica.errors import SkillError
from alica.skills.scratch import ScratchSlot
from alica.skills.vision2d_data import CANDIDATES, MEMORY, Candidate, Candidates, Memory


def test_a_slot_gives_back_what_was_put_with_its_type():
    scratch: dict[str, object] = {}
    c = Candidate("scout_c1", 1.0, 2.0, 0.03, 2.2, 0.1, 5)
    CANDIDATES.put(scratch, Candidates((c,), radius=0.03))
    got = CANDIDATES.get(scratch)
    assert got is not None and list(got) == [c] and len(got) == 1 and got.radius == 0.03
    with pytest.raises(FrozenInstanceError):
        c.x = 3.0  # type: ignore[misc]


def test_a_missing_step_is_named():
    assert CANDIDATES.get({}) is None
    with pytest.raises(
        SkillError, match=r"CropCandidate: no Candidates in scratch\['circles'\]: run DetectCircles first"
    ):
        CANDIDATES.require({}, "CropCandidate")


def test_something_else_under_the_key_is_refused_clearly():
    with pytest.raises(SkillError, match=r"scratch\['circles'\] holds a list, not the Candidates DetectCircles writes"):
        CANDIDATES.get({"circles": [{"id": "c1"}]})
    slot: ScratchSlot[int] = ScratchSlot("n", int, "Counter")
    with pytest.raises(TypeError, match="takes a int, not a str"):
        slot.put({}, "three")  # type: ignore[arg-type]


def test_setdefault_stores_one_memory_that_later_steps_share():
    scratch: dict[str, object] = {}
    memory = MEMORY.setdefault(scratch, Memory)
    memory.verdicts["scout_c1"] = "invalid"
    assert MEMORY.setdefault(scratch, Memory).verdicts == {"scout_c1": "invalid"}
