"""Parsing, precedence, unparsing and syntax errors of formulas."""

from __future__ import annotations

import pytest

from alica.errors import FormulaError
from alica.lang import (
    And,
    Attr,
    Binary,
    Bool,
    Call,
    Compare,
    Iff,
    Implies,
    Name,
    Not,
    Number,
    Or,
    Quantified,
    String,
    Unary,
    parse,
    unparse,
)
from alica.lang.parser import MAX_DEPTH

a, b, c = Name("a"), Name("b"), Name("c")

PAPER_EXAMPLES = [
    "On(a, g) and On(b, g)",
    "forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2",
    "forall f in Frontier, r in Agent: MinimalDist(f, r, eps)",
    "sqrt((p1.x - p2.x)^2 + (p1.y - p2.y)^2) > d",
    "not explored",
    "onground(?x) and handempty(?r)",
    "holding(?r, ?x) -> not handempty(?r)",
    "dist(pos(self), pos(target)) <= 0.3",
    "count(Sample) >= 2",
]


@pytest.mark.parametrize("text", PAPER_EXAMPLES)
def test_examples_parse_and_round_trip(text: str) -> None:
    node = parse(text)
    assert parse(unparse(node)) == node


def test_atoms() -> None:
    assert parse("42") == Number(42)
    assert parse("4.5") == Number(4.5)
    assert parse("1e-3") == Number(0.001)
    assert parse("2E+2") == Number(200.0)
    assert parse("'hi'") == String("hi")
    assert parse('"say \\"hi\\"\\n"') == String('say "hi"\n')
    assert parse("true") == Bool(True)
    assert parse("false") == Bool(False)
    assert parse("?r") == Name("?r")
    assert parse("On") == Name("On")
    assert parse("explored()") == Call("explored", ())
    assert parse("On(a, g)") == Call("On", (a, Name("g")))


def test_integer_and_float_types_are_kept() -> None:
    assert type(parse("3").value) is int  # type: ignore[union-attr]
    assert type(parse("3.0").value) is float  # type: ignore[union-attr]


def test_attribute_access_chains() -> None:
    assert parse("p.x") == Attr(Name("p"), "x")
    assert parse("pos(self).x") == Attr(Call("pos", (Name("self"),)), "x")
    assert parse("a.b.c") == Attr(Attr(a, "b"), "c")


def test_columns_are_recorded_but_not_compared() -> None:
    node = parse("  On(a,  g)")
    assert node.column == 3
    assert isinstance(node, Call)
    assert node.args[1].column == 10
    assert node == parse("On(a,g)")
    assert hash(node) == hash(parse("On(a,g)"))


def test_binary_node_column_includes_parentheses() -> None:
    node = parse("(a + b) * c")
    assert isinstance(node, Binary)
    assert node.column == 1
    assert node.left.column == 2


def test_and_binds_tighter_than_or() -> None:
    assert parse("a or b and c") == Or((a, And((b, c))))
    assert parse("a and b or c") == Or((And((a, b)), c))


def test_not_binds_tighter_than_and() -> None:
    assert parse("not a and b") == And((Not(a), b))
    assert parse("not a = b") == Not(Compare("==", a, b))
    assert parse("!a && b || c") == Or((And((Not(a), b)), c))


def test_chains_are_flat_but_parentheses_nest() -> None:
    assert parse("a and b and c") == And((a, b, c))
    assert parse("(a and b) and c") == And((And((a, b)), c))


def test_unary_minus_and_power() -> None:
    assert parse("-2^2") == Unary("-", Binary("^", Number(2), Number(2)))
    assert parse("2^3^2") == Binary("^", Number(2), Binary("^", Number(3), Number(2)))
    assert parse("2**-1") == Binary("^", Number(2), Unary("-", Number(1)))
    assert parse("(-2)^2") == Binary("^", Unary("-", Number(2)), Number(2))


def test_arithmetic_precedence_and_left_associativity() -> None:
    assert parse("a - b - c") == Binary("-", Binary("-", a, b), c)
    assert parse("a + b * c") == Binary("+", a, Binary("*", b, c))
    assert parse("a * b % c") == Binary("%", Binary("*", a, b), c)
    assert parse("-a * b") == Binary("*", Unary("-", a), b)


def test_implication_is_right_associative() -> None:
    assert parse("a -> b -> c") == Implies(a, Implies(b, c))
    assert parse("a implies b") == Implies(a, b)
    assert parse("a or b -> c") == Implies(Or((a, b)), c)


def test_equivalence() -> None:
    assert parse("a <-> b") == Iff(a, b)
    assert parse("a iff b -> c") == Iff(a, Implies(b, c))
    assert parse("a <-> b <-> c") == Iff(Iff(a, b), c)


def test_comparisons_and_equality_synonyms() -> None:
    for op in ("<", "<=", ">", ">=", "!="):
        assert parse(f"a {op} b") == Compare(op, a, b)
    assert parse("a = b") == parse("a == b") == Compare("==", a, b)
    assert parse("a + 1 < b * 2") == Compare("<", Binary("+", a, Number(1)), Binary("*", b, Number(2)))


def test_quantifier_binders() -> None:
    node = parse("forall f1, f2 in Frontier: p(f1, f2)")
    assert node == Quantified("forall", (("f1", "Frontier"), ("f2", "Frontier")), Call("p", (Name("f1"), Name("f2"))))
    node = parse("exists a in Agent, r in Robot: q(a, r)")
    assert isinstance(node, Quantified)
    assert node.kind == "exists"
    assert node.binders == (("a", "Agent"), ("r", "Robot"))


def test_quantifier_body_extends_right() -> None:
    node = parse("a and forall x in T: p(x) or q")
    assert node == And((a, Quantified("forall", (("x", "T"),), Or((Call("p", (Name("x"),)), Name("q"))))))
    node = parse("(forall x in T: p(x)) or q")
    assert isinstance(node, Or)


def test_quantifier_inside_call_arguments_stops_at_comma() -> None:
    node = parse("f(forall x in T: p, y)")
    assert isinstance(node, Call)
    assert node.args[1] == Name("y")


def test_keywords_are_case_sensitive() -> None:
    assert parse("And") == Name("And")
    assert parse("NOT(x)") == Call("NOT", (Name("x"),))


@pytest.mark.parametrize(
    ("text", "canonical"),
    [
        ("a  or(b and c)", "a or b and c"),
        ("(a or b) and c", "(a or b) and c"),
        ("a = b", "a == b"),
        ("x ** 2", "x ^ 2"),
        ("(a -> b) -> c", "(a -> b) -> c"),
        ("(forall x in T: p) and q", "(forall x in T: p) and q"),
        ("not (forall x in T: p) and q", "not (forall x in T: p) and q"),
        ("forall x, y in T, z in U: p", "forall x, y in T, z in U: p"),
        ("-(a * b)", "-(a * b)"),
        ("'it\\'s'", '"it\'s"'),
    ],
)
def test_unparse_is_canonical(text: str, canonical: str) -> None:
    assert unparse(parse(text)) == canonical
    assert str(parse(text)) == canonical


# -- errors -------------------------------------------------------------


def error_of(text: str) -> FormulaError:
    with pytest.raises(FormulaError) as info:
        parse(text)
    assert info.value.text == text
    return info.value


def test_unclosed_parenthesis() -> None:
    err = error_of("On(a, g")
    assert err.column == 8
    assert err.message == "expected ')' to close '(' opened at column 3"
    assert err.hint
    err = error_of("On((a, g)")
    assert err.column == 6
    assert err.message.startswith("expected ')' to close '(' opened at column 4")


def test_unclosed_parenthesis_with_unexpected_token() -> None:
    err = error_of("On(a g)")
    assert err.column == 6
    assert "expected ')' to close '(' opened at column 3" in err.message
    assert "','" in err.hint


def test_end_after_operator() -> None:
    err = error_of("On(a, g) and")
    assert err.message == "unexpected end of formula, expected a term after 'and'"
    assert err.column == 13


def test_unknown_character() -> None:
    err = error_of("a and $b")
    assert err.message == "unknown character '$'"
    assert err.column == 7


@pytest.mark.parametrize("text", ["", "   "])
def test_empty_formula(text: str) -> None:
    err = error_of(text)
    assert err.message == "empty formula"
    assert err.column == 1


@pytest.mark.parametrize(
    ("text", "column", "fragment"),
    [
        ("a < b < c", 7, "chained"),
        ("a b", 3, "after a complete formula"),
        ("a)", 2, "unmatched ')'"),
        ("forall x T: p", 10, "expected 'in'"),
        ("forall x in T p", 15, "expected ':'"),
        ("forall in T: p", 8, "variable name"),
        ("exists x in : p", 13, "type name"),
        ("a and or b", 7, "expected a term after 'and', found 'or'"),
        ("p.1", 3, "attribute name"),
        ("'abc", 1, "unterminated string"),
        ("'a\\qb'", 3, "unknown escape"),
        ("? x", 1, "unknown character '?'"),
        ("2abc", 1, "malformed number"),
        ("1 + not a", 5, "expected a term after '+', found 'not'"),
        ("f(a,)", 5, "expected a term after ','"),
        ("1e999 > 0", 1, "out of range"),
    ],
)
def test_error_columns(text: str, column: int, fragment: str) -> None:
    err = error_of(text)
    assert fragment in err.message
    assert err.column == column


def test_error_message_points_at_column() -> None:
    err = error_of("a and $b")
    assert str(err).splitlines()[-1] == "  " + " " * 6 + "^"


def test_deep_nesting_is_a_formula_error_at_the_opening_too_deep() -> None:
    err = error_of("x and " + "(" * 500 + "a" + ")" * 500)
    assert err.message == f"formula nested deeper than {MAX_DEPTH} levels; simplify it"
    assert err.column == 7 + MAX_DEPTH
    err = error_of("f(" * (MAX_DEPTH + 1) + "a" + ")" * (MAX_DEPTH + 1))
    assert "nested deeper than" in err.message
    assert err.column == 2 * MAX_DEPTH + 2  # the "(" of the call one level too deep
    quantifiers = "forall x in T: " * (MAX_DEPTH + 1) + "a"
    assert error_of(quantifiers).column == 15 * MAX_DEPTH + 1


def test_moderate_nesting_is_fine() -> None:
    assert parse("(" * MAX_DEPTH + "a" + ")" * MAX_DEPTH) == a


def test_parse_rejects_non_strings() -> None:
    with pytest.raises(TypeError):
        parse(42)  # type: ignore[arg-type]


def test_parse_is_cached() -> None:
    assert parse("On(a, g) and x > 1") is parse("On(a, g) and x > 1")
