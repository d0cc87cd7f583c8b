"""Tree queries: walk, calls, free names, literals and atoms."""

from __future__ import annotations

import pytest

from alica.errors import FormulaError
from alica.lang import Call, Compare, Name, atoms, calls, free_names, literals, parse, walk


def test_walk_is_preorder() -> None:
    node = parse("f(a) and not b")
    kinds = [type(n).__name__ for n in walk(node)]
    assert kinds == ["And", "Call", "Name", "Not", "Name"]


def test_calls() -> None:
    node = parse("dist(pos(self), pos(target)) <= 0.3 and explored()")
    assert [c.name for c in calls(node)] == ["dist", "pos", "pos", "explored"]
    assert [c.column for c in calls(node)] == [1, 6, 17, 41]


def test_free_names() -> None:
    node = parse("forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2")
    assert free_names(node) == {"eps"}
    assert free_names(parse("p.x > d and exists p in T: q(p, r)")) == {"p", "d", "r"}
    assert free_names(parse("f(g(h))")) == {"h"}


def test_literals_of_a_conjunction() -> None:
    assert literals("not onground(?x) and holding(?r, ?x)") == [
        (False, "onground", ("?x",)),
        (True, "holding", ("?r", "?x")),
    ]
    assert literals("handempty(?r)") == [(True, "handempty", ("?r",))]
    assert literals("explored and !done") == [(True, "explored", ()), (False, "done", ())]
    assert literals("true") == []
    assert literals("(a and b) and c") == [(True, "a", ()), (True, "b", ()), (True, "c", ())]
    assert literals("at(?r, 'room 1', 3)") == [(True, "at", ("?r", "room 1", 3))]


def test_literals_equality() -> None:
    assert literals("?x = ?y and ?x != c and not ?y = c") == [
        (True, "=", ("?x", "?y")),
        (False, "=", ("?x", "c")),
        (False, "=", ("?y", "c")),
    ]


@pytest.mark.parametrize(
    ("text", "column"),
    [
        ("a or b", 1),
        ("a and (b or c)", 8),
        ("p(x) and q(f(x))", 12),
        ("a and not not b", 7),
        ("a and x < 3", 7),
        ("forall x in T: p(x)", 1),
        ("a and false", 7),
        ("p(x.y)", 3),
    ],
)
def test_non_literals_raise_with_column(text: str, column: int) -> None:
    with pytest.raises(FormulaError) as info:
        literals(text)
    assert info.value.column == column
    assert info.value.text == text


def test_literals_of_node_uses_given_text() -> None:
    with pytest.raises(FormulaError) as info:
        literals(parse("a or b"), text="a or b")
    assert info.value.text == "a or b"


def test_atoms() -> None:
    found = atoms("not onground(?x) and holding(?r, ?x) and done and ?a = ?b")
    assert found[0] == Call("onground", (Name("?x"),))
    assert found[2] == Name("done")
    assert isinstance(found[3], Compare)
    with pytest.raises(FormulaError):
        atoms("a -> b")
