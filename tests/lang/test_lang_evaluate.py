"""Evaluation of formulas against a FactBase."""

from __future__ import annotations

from collections import namedtuple
from typing import Any

import pytest

from alica.errors import EvaluationError, FormulaError
from alica.lang import FactBase, Registry, compile_formula, default_registry, evaluate, holds, parse

Point = namedtuple("Point", "x y")


@pytest.fixture
def blocks() -> FactBase:
    return FactBase(
        facts=[
            ("On", "a", "g"),
            ("On", "b", "a"),
            ("onground", "c"),
            ("handempty", "r1"),
            "explored",
        ],
        values={("pos", "r1"): (0.0, 0.0), ("pos", "target"): (0.3, 0.4), "limit": 3},
        objects={"Block": ["a", "b", "c"], "Robot": ["r1"], "Sample": ["s1", "s2"]},
    )


def frontier(points: dict[str, tuple[float, float]], eps: float = 2.0) -> FactBase:
    fb = FactBase(values={"eps": eps})
    for name, point in points.items():
        fb.add_object(name, "Frontier")
        fb.set("Pos", name, value=point)
    return fb


EQ1 = "forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2"


# -- facts and names ------------------------------------------------------


def test_facts_with_symbol_arguments(blocks: FactBase) -> None:
    assert holds("On(a, g) and On(b, a)", blocks)
    assert not holds("On(a, b)", blocks)
    assert holds("On('a', \"g\")", blocks)


def test_closed_world(blocks: FactBase) -> None:
    assert not holds("On(c, a)", blocks)  # known predicate, missing fact
    assert not holds("Unheard(a)", blocks)  # never mentioned
    assert holds("not Unheard(a)", blocks)
    assert not holds("nothing_known", blocks)
    assert holds("not nothing_known", blocks)


def test_zero_ary_facts(blocks: FactBase) -> None:
    assert holds("explored", blocks)
    assert not holds("not explored", blocks)
    assert holds("explored()", blocks)
    blocks.remove("explored")
    assert holds("not explored", blocks)
    assert evaluate("explored", blocks) is False


def test_names_resolve_env_then_registry_then_belief_then_symbol(blocks: FactBase) -> None:
    registry = default_registry()
    registry.register("now", lambda: 7, 0, kind="function")
    assert evaluate("now", blocks, registry=registry) == 7
    assert evaluate("now", blocks, {"now": 1}, registry=registry) == 1
    assert evaluate("limit", blocks) == 3
    assert evaluate("somewhere", blocks) == "somewhere"
    assert evaluate("limit", blocks, {"limit": 5}) == 5


def test_env_binds_self(blocks: FactBase) -> None:
    assert holds("handempty(self)", blocks, {"self": "r1"})
    assert not holds("handempty(self)", blocks, {"self": "r2"})


def test_function_values_and_dist(blocks: FactBase) -> None:
    assert evaluate("pos(self)", blocks, {"self": "r1"}) == (0.0, 0.0)
    assert evaluate("dist(pos(self), pos(target))", blocks, {"self": "r1"}) == pytest.approx(0.5)
    assert holds("dist(pos(self), pos(target)) <= 0.5", blocks, {"self": "r1"})
    assert not holds("dist(pos(self), pos(target)) <= 0.3", blocks, {"self": "r1"})


def test_missing_function_value_is_an_error(blocks: FactBase) -> None:
    with pytest.raises(EvaluationError, match=r"no value for pos\(a\) in the belief base") as info:
        evaluate("dist(pos(a), pos(r1)) < 1", blocks)
    assert info.value.column == 6  # type: ignore[attr-defined]


# -- logic ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("true and false", False),
        ("true or false", True),
        ("false -> false", True),
        ("true -> false", False),
        ("false <-> false", True),
        ("true iff false", False),
        ("not not true", True),
        ("true && !false || false", True),
    ],
)
def test_connectives(text: str, expected: bool) -> None:
    assert holds(text, FactBase()) is expected


def test_short_circuit_skips_errors() -> None:
    fb = FactBase()
    assert not holds("false and 1 / 0 > 0", fb)
    assert holds("true or 1 / 0 > 0", fb)
    assert holds("false -> 1 / 0 > 0", fb)
    with pytest.raises(EvaluationError, match="division by zero"):
        holds("true and 1 / 0 > 0", fb)


def test_quantifiers(blocks: FactBase) -> None:
    assert holds("exists x in Block: onground(x)", blocks)
    assert not holds("forall x in Block: onground(x)", blocks)
    assert holds("forall x in Block: onground(x) or exists y in Block: On(x, y) or x = a", blocks)
    assert holds("forall x in Block, r in Robot: handempty(r)", blocks)
    assert holds("exists x, y in Block: On(x, y)", blocks)
    assert not holds("exists x, y in Block: On(y, x) and x = c", blocks)


def test_quantifier_over_empty_domain() -> None:
    fb = FactBase()
    assert holds("forall x in Nothing: false", fb)
    assert not holds("exists x in Nothing: true", fb)


def test_quantifier_variables_shadow_and_do_not_leak(blocks: FactBase) -> None:
    env = {"x": "outer"}
    assert holds("exists x in Block: x = c", blocks, env)
    assert env == {"x": "outer"}
    assert holds("(exists x in Block: x = c) and x = outer", blocks, env)


def test_count(blocks: FactBase) -> None:
    assert evaluate("count(Sample)", blocks) == 2
    assert holds("count(Sample) >= 2", blocks)
    assert holds("count(Nothing) = 0", blocks)


# -- IMPERA distance predicates --------------------------------------------


def test_maximal_and_minimal_dist() -> None:
    fb = frontier({"f1": (0, 0), "f2": (3, 4)})
    assert holds("MaximalDist(f1, f2, 4.9)", fb)
    assert not holds("MaximalDist(f1, f2, 5)", fb)
    assert holds("MinimalDist(f1, f2, 5.1)", fb)
    assert not holds("MinimalDist(f1, f2, 5)", fb)


def test_distance_predicates_are_false_for_unknown_positions() -> None:
    fb = frontier({"f1": (0, 0)})
    assert not holds("MaximalDist(f1, nowhere, 0)", fb)
    assert not holds("MinimalDist(f1, nowhere, 100)", fb)


def test_eq1_constraint_over_three_frontier_points() -> None:
    spread = frontier({"f1": (0, 0), "f2": (5, 0), "f3": (0, 5)}, eps=2.0)
    assert holds(EQ1, spread)
    crowded = frontier({"f1": (0, 0), "f2": (5, 0), "f3": (1, 1)}, eps=2.0)
    assert not holds(EQ1, crowded)
    # without "or f1 = f2" a point is never far from itself
    assert not holds("forall f1, f2 in Frontier: MaximalDist(f1, f2, eps)", spread)


def test_eq1_with_eps_from_env_and_mapping_positions() -> None:
    fb = FactBase(objects={"Frontier": ["f1", "f2"]})
    fb.set("Pos", "f1", value={"x": 0, "y": 0})
    fb.set("Pos", "f2", value=Point(1, 1))
    assert holds(EQ1, fb, {"eps": 1.0})
    assert not holds(EQ1, fb, {"eps": 2.0})


def test_minimal_dist_between_types() -> None:
    fb = frontier({"f1": (0, 0), "f2": (10, 0)})
    fb.add_object("r1", "Agent")
    fb.set("Pos", "r1", value=(9, 0))
    assert holds("exists f in Frontier, r in Agent: MinimalDist(f, r, eps)", fb)
    assert not holds("forall f in Frontier, r in Agent: MinimalDist(f, r, eps)", fb)


# -- values, attributes, arithmetic -----------------------------------------


class Obj:
    def __init__(self, **kwargs: Any) -> None:
        self.__dict__.update(kwargs)


def test_attribute_access() -> None:
    fb = FactBase()
    env = {"t": (1, 2, 3), "m": {"x": 4, "name": "m"}, "o": Obj(x=5, y=6), "p": Point(7, 8)}
    assert evaluate("t.x + t.y + t.z", fb, env) == 6
    assert evaluate("m.x", fb, env) == 4
    assert evaluate("m.name", fb, env) == "m"
    assert evaluate("o.y", fb, env) == 6
    assert evaluate("p.y", fb, env) == 8
    assert holds("sqrt((p1.x - p2.x)^2 + (p1.y - p2.y)^2) > d", fb, {"p1": (0, 0), "p2": o2(), "d": 4.9})


def o2() -> Obj:
    return Obj(x=3, y=4)


@pytest.mark.parametrize("text", ["t.w", "m.y", "o._secret", "o.__class__", "s.x"])
def test_missing_attributes_are_errors(text: str) -> None:
    env = {"t": (1, 2), "m": {"x": 1}, "o": Obj(_secret=1), "s": "abc"}
    with pytest.raises(EvaluationError, match="has no attribute"):
        evaluate(text, FactBase(), env)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1 + 2 * 3", 7),
        ("(1 + 2) * 3", 9),
        ("7 / 2", 3.5),
        ("7 % 4", 3),
        ("2 ^ 3 ^ 2", 512),
        ("-2 ^ 2", -4),
        ("2 ** -1", 0.5),
        ("abs(-3)", 3),
        ("min(3, 1, 2)", 1),
        ("max(3, 1, 2)", 3),
        ("floor(2.7)", 2),
        ("ceil(2.1)", 3),
        ("round(2.567, 2)", 2.57),
        ("round(2.5)", 2),
        ("sqrt(16)", 4.0),
        ("dist(p, q)", 5.0),
        ("'a' < 'b'", True),
        ("1 = 1.0", True),
        ("1 = true", False),
        ("a != b", True),
    ],
)
def test_values(text: str, expected: object) -> None:
    env = {"p": (0, 0), "q": {"x": 3, "y": 4}}
    assert evaluate(text, FactBase(), env) == expected


def test_min_accepts_one_iterable() -> None:
    assert evaluate("min(xs)", FactBase(), {"xs": [4, 2, 9]}) == 2
    assert evaluate("max(xs)", FactBase(), {"xs": (4, 2, 9)}) == 9


def test_dist_in_three_dimensions() -> None:
    assert evaluate("dist(p, q)", FactBase(), {"p": (0, 0, 0), "q": Obj(x=1, y=2, z=2)}) == 3.0


@pytest.mark.parametrize(
    ("text", "fragment", "column"),
    [
        ("x > 1 / (y - y)", "division by zero", 5),
        ("x % 0 > 1", "division by zero", 1),
        ("a + 1 > 0", "cannot apply '+'", 1),
        ("a < 1", "cannot compare", 1),
        ("-a > 0", "cannot negate", 1),
        ("1 and true", "expected a truth value, got 1", 1),
        ("x and true", "expected a truth value", 1),
        ("sqrt(-1) > 0", "sqrt failed", 1),
        ("true and sqrt(1, 2) > 0", "sqrt takes 1 argument, got 2", 10),
        ("(-8) ^ 0.5 > 0", "not a real number", 1),
        ("10.0 ^ 1000 > 0", "arithmetic error", 1),
    ],
)
def test_evaluation_errors_name_expression_and_column(text: str, fragment: str, column: int) -> None:
    with pytest.raises(EvaluationError) as info:
        holds(text, FactBase(), {"x": 1, "y": 2})
    assert fragment in str(info.value)
    assert info.value.column == column  # type: ignore[attr-defined]
    assert f"at column {column}" in str(info.value)


def test_huge_integer_powers_fail_fast() -> None:
    with pytest.raises(EvaluationError):
        evaluate("9 ^ 9 ^ 9", FactBase())


def test_holds_requires_a_truth_value() -> None:
    with pytest.raises(EvaluationError, match="expected a truth value"):
        holds("1 + 2", FactBase())
    with pytest.raises(EvaluationError, match="expected a truth value"):
        holds("Pos(f1)", frontier({"f1": (0, 0)}))


def test_syntax_errors_propagate_from_text() -> None:
    with pytest.raises(FormulaError):
        holds("a and", FactBase())


def test_registered_callables_win_over_facts() -> None:
    registry = Registry()
    registry.register("On", lambda x, y: x == "z", 2)
    fb = FactBase(facts=[("On", "a", "g")])
    assert not holds("On(a, g)", fb, registry=registry)
    assert holds("On(z, g)", fb, registry=registry)
    assert holds("On(a, g)", fb)


def test_belief_callables_receive_the_belief_base() -> None:
    registry = Registry()
    seen: list[object] = []

    @registry.predicate("Seen", arity=1, needs_belief=True)
    def seen_pred(belief: object, x: object) -> bool:
        seen.append(belief)
        return x == "a"

    fb = FactBase()
    assert holds("Seen(a)", fb, registry=registry)
    assert seen == [fb]


def test_registry_changes_invalidate_compiled_formulas() -> None:
    registry = Registry()
    registry.register("flag", lambda: True, 0)
    assert holds("flag", FactBase(), registry=registry)
    registry.register("flag", lambda: False, 0, replace=True)
    assert not holds("flag", FactBase(), registry=registry)


def test_non_bool_predicate_result_is_an_error() -> None:
    registry = Registry()
    registry.register("weird", lambda: 3, 0)
    with pytest.raises(EvaluationError, match="expected a truth value, got 3"):
        holds("weird", FactBase(), registry=registry)


def test_compile_formula() -> None:
    run = compile_formula("On(a, g) and n > 1")
    fb = FactBase(facts=[("On", "a", "g")])
    assert run(fb, {"n": 2})
    assert not run(fb, {"n": 1})
    value = compile_formula("n * 2", boolean=False)
    assert value(fb, {"n": 4}) == 8


def test_evaluate_accepts_nodes() -> None:
    node = parse("x + 1")
    assert evaluate(node, FactBase(), {"x": 1}) == 2
    assert evaluate(node, FactBase(), {"x": 2}) == 3


def test_having_lists_the_objects_whose_fluent_has_a_value() -> None:
    # a world model's object sets only grow: a retracted frontier keeps its object but loses its gain
    fb = FactBase(
        objects={"Frontier": ["f_2", "f_1", "f_3"]},
        values={("gain", "f_1"): 4.0, ("gain", "f_3"): 0.0},
    )
    assert evaluate("having(Frontier, gain)", fb) == ["f_1", "f_3"]
    assert evaluate("count(Frontier, gain)", fb) == 2
    assert evaluate("count(Frontier)", fb) == 3
    assert holds("count(Sample, gain) = 0", fb)
