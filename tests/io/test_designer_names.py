"""The name sanitiser: valid, unique and deterministic names for any designer names."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from alica.io.designer.names import Namespace, is_identifier, is_placeholder, sanitize
from alica.lang import parse
from alica.lang.ast import KEYWORDS

names = st.text(max_size=20) | st.sampled_from(["", "MISSING_NAME", "1412252439927", "and", "Tackle", "a b", "Über"])


def _claim_all(raws: list[str], reserved: frozenset[str]) -> list[str]:
    space = Namespace(reserved)
    return [space.claim(raw, "Fallback", "Kind") for raw in raws]


@given(st.lists(names, max_size=30), st.frozensets(st.sampled_from(["succeeded", "self", "Tackle", "dist"])))
def test_names_are_valid_unique_and_deterministic(raws: list[str], reserved: frozenset[str]) -> None:
    claimed = _claim_all(raws, reserved)
    assert claimed == _claim_all(raws, reserved)  # the same input gives the same names
    assert len(set(claimed)) == len(claimed)  # unique
    for name in claimed:
        assert is_identifier(name) and name not in KEYWORDS and name not in reserved
        parse(f"succeeded({name})")  # formulas can read it


@given(st.lists(st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,10}", fullmatch=True), unique=True, max_size=20))
def test_valid_free_names_are_kept(raws: list[str]) -> None:
    kept = [r for r in raws if r not in KEYWORDS]
    assert _claim_all(kept, frozenset()) == kept


def test_examples() -> None:
    assert sanitize("FromPlanATo PlanB", "T") == "FromPlanATo_PlanB"
    assert sanitize("Default Name", "S") == "Default_Name"
    assert sanitize("", "State") == "State"
    assert sanitize("3D-Plan", "P") == "_3D_Plan"
    assert sanitize("Überholen", "P") == "Uberholen"
    assert sanitize("and", "P") == "and_"
    space = Namespace()
    assert [space.claim(n, "X", "Behaviour") for n in ("Tackle", "Tackle", "Tackle")] == [
        "Tackle",
        "TackleBehaviour",
        "TackleBehaviour_2",
    ]
    assert is_placeholder("MISSING_NAME") and is_placeholder("") and is_placeholder("1412252439927")
    assert not is_placeholder("NewEntryPoint")
