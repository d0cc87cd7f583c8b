"""The C++ standard library's transition conditions as formulas of our language.

In the designer's format a transition names a condition of a condition
repository; its logic is C++ code. The conditions of the library
``alica_standard_library`` have fixed meanings with counterparts here:

- ``AlwaysTrueCondition``, ``AlwaysFalseCondition``: ``true``, ``false``;
- ``AllChildSuccess``: ``succeeded`` (every child of the state succeeded);
- ``AnyChildFailure``: ``failed`` (some child failed);
- ``AnyChildSuccess``: ``succeeded(A) or succeeded(B) ...`` over the state's children;
- ``AllChildFailure``: ``failed(A) and failed(B) ...``;
- ``IsChildSuccess``: ``succeeded(C)`` for the child named by the constant ``childName``;
- ``IsEqual<T>``, ``IsLessThan<T>``: ``left == right``, ``left < right`` when both
  inputs are constants of the key mapping.

:func:`standard_formula` gives the formula, or says why there is none (an
input read from a blackboard, a child not in the state); the caller then
declares the condition as a predicate.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from alica.io.designer.json_view import Scalar
from alica.io.designer.records import KeyMap, RepoCondition
from alica.lang import unparse
from alica.lang.ast import And, Bool, Call, Compare, Name, Node, Number, Or, String

#: The library name of the C++ engine's standard conditions.
STANDARD_LIBRARY = "alica_standard_library"

_COMPARISONS = {"IsEqual": "==", "IsLessThan": "<"}
_TYPES = {"Bool": "bool", "Int64": "int", "UInt64": "int", "Double": "number", "String": "text"}


@dataclass(frozen=True, slots=True)
class Formula:
    """The outcome of mapping a standard condition.

    Attributes:
        text: the formula, or ``None`` when the condition stays a predicate.
        reason: why there is no formula (or a remark on the one given); empty when there is nothing to say.
        consumed: whether the key mapping's inputs were used up by the formula.
    """

    text: str | None
    reason: str = ""
    consumed: bool = False


def _literal(value: Scalar, kind: str) -> Node | None:
    """``value`` as a literal of the formula language, if it is of ``kind``."""
    if kind == "bool":
        return Bool(value) if isinstance(value, bool) else None
    if isinstance(value, bool):
        return None
    if kind == "int":
        return Number(value) if isinstance(value, int) else None
    if kind == "number":
        return Number(value) if isinstance(value, (int, float)) else None
    return String(value) if isinstance(value, str) else None


def _children_formula(name: str, children: Sequence[str], joiner: str) -> Formula:
    unique = list(dict.fromkeys(children))
    if not unique:
        return Formula("false", f"{name} over a state without children never holds: imported as 'false'", True)
    predicate = "succeeded" if "Success" in name else "failed"
    atoms: list[Node] = [Call(predicate, (Name(c),)) for c in unique]
    if len(atoms) == 1:
        return Formula(unparse(atoms[0]), consumed=True)
    node: Node = Or(tuple(atoms)) if joiner == "or" else And(tuple(atoms))
    return Formula(unparse(node), consumed=True)


def standard_formula(
    condition: RepoCondition, inputs: Sequence[KeyMap], children: Sequence[tuple[str, str]]
) -> Formula:
    """The formula of a standard-library condition on a transition.

    Args:
        condition: the repository's condition.
        inputs: the transition's input key mapping (constants in ``value``).
        children: the children of the transition's source state: (designer name, our name).
    """
    name = condition.name
    if condition.library != STANDARD_LIBRARY:
        return Formula(None)
    if name == "AlwaysTrueCondition":
        return Formula("true", consumed=True)
    if name == "AlwaysFalseCondition":
        return Formula("false", consumed=True)
    if name == "AllChildSuccess":
        return Formula("succeeded", consumed=True)
    if name == "AnyChildFailure":
        return Formula("failed", consumed=True)
    ours = [c for _, c in children]
    if name == "AnyChildSuccess":
        return _children_formula(name, ours, "or")
    if name == "AllChildFailure":
        return _children_formula(name, ours, "and")
    constants = {m.child_key: m.value for m in inputs if m.value is not None}
    if name == "IsChildSuccess":
        child = constants.get("childName")
        if not isinstance(child, str):
            return Formula(None, "its input 'childName' is not a constant of the key mapping")
        found = [c for original, c in children if original == child]
        if not found:
            return Formula(None, f"its child '{child}' is not a child of the state")
        return Formula(unparse(Call("succeeded", (Name(found[0]),))), consumed=True)
    for prefix, op in _COMPARISONS.items():
        if name.startswith(prefix) and name[len(prefix) :] in _TYPES:
            kind = _TYPES[name[len(prefix) :]]
            sides: list[Node] = []
            for key in ("left", "right"):
                if key not in constants:
                    read = next((m.parent_key for m in inputs if m.child_key == key and m.parent_key), None)
                    source = f"blackboard key '{read}'" if read else "nothing"
                    return Formula(None, f"its input '{key}' is read from {source}, not a constant")
                literal = _literal(constants[key], kind)
                if literal is None:
                    return Formula(None, f"its input '{key}' = {constants[key]!r} is not of its type")
                sides.append(literal)
            return Formula(unparse(Compare(op, sides[0], sides[1])), consumed=True)
    return Formula(None, f"'{name}' of {STANDARD_LIBRARY} has no counterpart")
