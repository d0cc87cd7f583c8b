"""Property tests: unparse/parse round trips, parser robustness, evaluator robustness."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from alica.errors import EvaluationError, FormulaError
from alica.lang import (
    And,
    Attr,
    Binary,
    Bool,
    Call,
    Compare,
    FactBase,
    Iff,
    Implies,
    Name,
    Node,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
    check,
    evaluate,
    parse,
    unparse,
)
from alica.lang.ast import KEYWORDS

identifiers = st.from_regex(r"\??[A-Za-z_][A-Za-z0-9_]{0,6}", fullmatch=True).filter(lambda name: name not in KEYWORDS)
# Names that mean something to the evaluator, so random formulas reach real code.
known = st.sampled_from(
    [
        "a",
        "b",
        "x",
        "p",
        "T",
        "On",
        "Pos",
        "eps",
        "sqrt",
        "min",
        "max",
        "dist",
        "count",
        "MaximalDist",
        "round",
    ]
)
names = st.one_of(identifiers, known)
numbers = st.one_of(
    st.integers(min_value=0, max_value=10**12),
    st.floats(min_value=0, allow_nan=False, allow_infinity=False).map(abs),
)
leaves = st.one_of(
    names.map(Name),
    numbers.map(Number),
    st.text(max_size=6).map(String),
    st.booleans().map(Bool),
)


def _extend(children: st.SearchStrategy[Node]) -> st.SearchStrategy[Node]:
    several = st.lists(children, min_size=2, max_size=4).map(tuple)
    binders = st.lists(st.tuples(names, names), min_size=1, max_size=3).map(tuple)
    return st.one_of(
        st.builds(Call, names, st.lists(children, max_size=3).map(tuple)),
        st.builds(Attr, children, names),
        st.builds(Unary, st.just("-"), children),
        st.builds(Binary, st.sampled_from(["+", "-", "*", "/", "%", "^"]), children, children),
        st.builds(Compare, st.sampled_from(["<", "<=", ">", ">=", "==", "!="]), children, children),
        st.builds(Not, children),
        st.builds(And, several),
        st.builds(Or, several),
        st.builds(Implies, children, children),
        st.builds(Iff, children, children),
        st.builds(Quantified, st.sampled_from(["forall", "exists"]), binders, children),
    )


trees = st.recursive(leaves, _extend, max_leaves=12)

TOKENS = [
    *"abxp?()[],.:;<>=!-+*/%^&|'\"$ 0123456789",
    " and ",
    " or ",
    "not ",
    "forall ",
    "exists ",
    " in ",
    "->",
    "<->",
    "true",
    "false",
    "1e-3",
    "On(",
    "**",
    "==",
    "\\",
    "\n",
    "é",
    "1e999",
]
formula_like = st.lists(st.sampled_from(TOKENS), max_size=40).map("".join)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees)
def test_parse_unparse_round_trip(tree: Node) -> None:
    text = unparse(tree)
    assert parse(text) == tree, text


@settings(max_examples=300, deadline=None)
@given(st.one_of(st.text(), formula_like))
def test_parse_returns_a_node_or_raises_formula_error(text: str) -> None:
    try:
        node = parse(text)
    except FormulaError as err:
        assert 1 <= err.column <= len(text) + 1
        assert err.text == text
        return
    assert parse(unparse(node)) == node


def _belief() -> FactBase:
    fb = FactBase(
        facts=[("On", "a", "b"), ("On", 1, 2), "x"],
        values={("Pos", "a"): (0, 0), ("Pos", "b"): (3, 4), "eps": 1.5},
        objects={"T": ["a", "b"], "p": [1, 2.5]},
    )
    return fb


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees)
def test_evaluation_returns_or_raises_evaluation_error(tree: Node) -> None:
    env = {"p": (1, 2), "b": {"x": 1, "y": "s"}}
    check(tree)
    for boolean in (False, True):
        try:
            if boolean:
                from alica.lang import holds

                assert holds(tree, _belief(), env) in (True, False)
            else:
                evaluate(tree, _belief(), env)
        except EvaluationError as err:
            assert str(err)
