"""The C++ standard library's conditions as formulas, and cycles through plan types."""

from __future__ import annotations

from pathlib import Path

from alica.io.designer import Construct, import_designer
from alica.io.designer.conditions import STANDARD_LIBRARY, standard_formula
from alica.io.designer.json_view import Scalar
from alica.io.designer.records import KeyMap, RepoCondition
from alica.lang import parse
from tests.io.test_designer_broken import folder, plan
from tests.io.test_designer_helpers import write_json


def cond(name: str, library: str = STANDARD_LIBRARY) -> RepoCondition:
    return RepoCondition(1, name, "", library, (), "conditions[0]")


def const(key: str, value: Scalar) -> KeyMap:
    return KeyMap(None, key, value)


CHILDREN = [("Attack", "Attack"), ("Tackle", "TackleBehaviour"), ("Attack", "Attack")]


def test_child_conditions() -> None:
    assert (
        standard_formula(cond("AnyChildSuccess"), (), CHILDREN).text
        == "succeeded(Attack) or succeeded(TackleBehaviour)"
    )
    assert standard_formula(cond("AllChildFailure"), (), CHILDREN).text == "failed(Attack) and failed(TackleBehaviour)"
    assert standard_formula(cond("AllChildSuccess"), (), CHILDREN).text == "succeeded"
    assert standard_formula(cond("AnyChildFailure"), (), CHILDREN).text == "failed"
    none = standard_formula(cond("AnyChildSuccess"), (), [])
    assert none.text == "false" and "without children" in none.reason
    child = standard_formula(cond("IsChildSuccess"), (const("childName", "Tackle"),), CHILDREN)
    assert child.text == "succeeded(TackleBehaviour)"  # the designer's name, resolved to ours
    missing = standard_formula(cond("IsChildSuccess"), (const("childName", "Nobody"),), CHILDREN)
    assert missing.text is None and "not a child" in missing.reason


def test_constant_comparisons() -> None:
    def formula(name: str, left: Scalar, right: Scalar) -> str | None:
        return standard_formula(cond(name), (const("left", left), const("right", right)), ()).text

    assert formula("IsEqualInt64", -1234, 1234) == "-1234 == 1234"
    assert formula("IsLessThanDouble", 3.13, 3.15) == "3.13 < 3.15"
    assert formula("IsEqualString", 'say "hi"', "x") == '"say \\"hi\\"" == "x"'
    assert formula("IsEqualBool", True, True) == "true == true"
    assert formula("IsEqualInt64", True, 1) is None  # a truth value is not an int64
    for name in ("IsEqualInt64", "IsLessThanDouble", "IsEqualString", "IsEqualBool"):
        text = formula(name, 1, 2) or formula(name, "a", "b") or formula(name, True, False)
        assert text is not None and parse(text)
    read = standard_formula(cond("IsEqualInt64"), (const("left", 3), KeyMap("counter", "right", None)), ())
    assert read.text is None and "blackboard key 'counter'" in read.reason


def test_fixed_and_foreign_conditions() -> None:
    assert standard_formula(cond("AlwaysTrueCondition"), (), ()).text == "true"
    assert standard_formula(cond("AlwaysFalseCondition"), (), ()).text == "false"
    assert standard_formula(cond("AnyChildSuccess", "alica-tests"), (), CHILDREN).text is None


def test_a_cycle_through_a_plan_type_leaves_the_plan_out_of_the_type(tmp_path: Path) -> None:
    src = folder(tmp_path, {"A.pml": plan(100, "A", ["Choice.pty#300"]), "B.pml": plan(200, "B", ["Work.beh#30"])})
    choice = {
        "id": 300,
        "name": "Choice",
        "annotatedPlans": [
            {"id": 301, "plan": "A.pml#100", "activated": True},
            {"id": 302, "plan": "B.pml#200", "activated": True},
        ],
        "variableBindings": [],
        "variables": [],
    }
    write_json(src, "plans/Choice.pty", choice)
    result = import_designer(src)
    assert result.errors == []
    assert "    plans: [B]\n" in result.outputs["plans/Choice.yaml"]
    (note,) = [n for n in result.notes if n.construct is Construct.DROPPED]
    assert note.file == "plans/Choice.pty" and note.key == "annotatedPlans[0].plan"
    choice["annotatedPlans"] = choice["annotatedPlans"][:1]  # type: ignore[index]
    write_json(src, "plans/Choice.pty", choice)
    result = import_designer(src)
    (error,) = result.errors  # no other alternative: the file that closes the cycle is refused
    assert error.file == "plans/Choice.pty" and "closes a cycle" in error.message
    assert "plans/A.yaml" in result.outputs  # A drops its child Choice
