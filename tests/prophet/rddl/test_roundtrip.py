"""Round trips: parse(write(tree)) == tree for the paper's files, every construct, and generated expressions."""

from __future__ import annotations

import string
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from alica.prophet.rddl import (
    KEYWORDS,
    Aggregate,
    Apply,
    Binary,
    BoolConst,
    Distribution,
    EnumValue,
    Expr,
    If,
    IntConst,
    Name,
    Neg,
    Not,
    Param,
    RddlError,
    RealConst,
    TypedParam,
    parse_expr,
    parse_rddl,
    read_rddl,
    write_domain,
    write_expr,
    write_instance,
    write_non_fluents,
    write_rddl,
)
from tests.prophet.rddl.test_parse import FULL

DATA = Path(__file__).parent / "data"


def test_paper_files_round_trip() -> None:
    domain = read_rddl(DATA / "multi_ros_robot_mdp.rddl")
    assert domain.domain is not None
    assert parse_rddl(write_rddl(domain)) == domain
    assert parse_rddl(write_domain(domain.domain)) == domain
    blocks = read_rddl(DATA / "multi_ros_robot_inst_mdp__1.rddl", domain=domain.domain)
    assert blocks.non_fluents is not None and blocks.instance is not None
    assert parse_rddl(write_rddl(blocks), domain=domain.domain) == blocks
    assert parse_rddl(write_non_fluents(blocks.non_fluents), domain=domain.domain).non_fluents == blocks.non_fluents
    assert parse_rddl(write_instance(blocks.instance)).instance == blocks.instance


def test_every_construct_round_trips_and_prints_one_declaration_per_line() -> None:
    blocks = parse_rddl(FULL)
    text = write_rddl(blocks)
    assert parse_rddl(text) == blocks
    assert write_rddl(parse_rddl(text)) == text
    lines = text.splitlines()
    assert "        mode : {state-fluent, grade, default = @low};" in lines
    assert "        heat(room) : {interm-fluent, real, level = 1};" in lines
    assert "        ~ADJ(c2, c1);" in lines
    assert "    max-nondef-actions = pos-inf;" in lines
    assert "    state-action-constraints {" in lines  # the older name 'constraints' is written as the newer one


def test_written_paper_domain_layout() -> None:
    text = write_rddl(read_rddl(DATA / "multi_ros_robot_mdp.rddl"))
    assert "        robotAt'(?r, ?x, ?y) = if (goto(?r, ?x, ?y))" in text
    assert "            then KronDelta(false)" in text
    assert "        forall_{?r : robot} [(sum_{?a : action} [do(?r, ?a)]) <= 1];" in text
    assert "\n        - (sum_{?r : robot, ?a : action} [do(?r, ?a) * DO_COST(?r, ?a)])\n" in text


_FIRST = string.ascii_letters
_REST = string.ascii_letters + string.digits + "_"
WORDS = st.builds(
    lambda first, rest, tail: first + rest + (f"-{tail}" if tail else ""),
    st.sampled_from(_FIRST),
    st.text(_REST, max_size=5),
    st.one_of(st.just(""), st.text(string.ascii_lowercase, min_size=1, max_size=3)),
).filter(lambda w: w not in KEYWORDS and not w.endswith("_") and w.split("-")[0] not in KEYWORDS)
PARAMS = WORDS.map(lambda w: Param("?" + w))
LEAVES: st.SearchStrategy[Expr] = st.one_of(
    st.builds(BoolConst, st.booleans()),
    st.builds(IntConst, st.integers(-(10**12), 10**12)),
    st.builds(RealConst, st.floats(allow_nan=False, allow_infinity=False, width=64)),
    WORDS.map(lambda w: EnumValue("@" + w)),
    PARAMS,
    WORDS.map(Apply),
)
OPS = ["+", "-", "*", "/", "==", "~=", "<", "<=", ">", ">=", "^", "&", "|", "=>", "<=>"]


def _extend(inner: st.SearchStrategy[Expr]) -> st.SearchStrategy[Expr]:
    typed = st.builds(TypedParam, PARAMS.map(lambda x: x.name), WORDS.map(Name))
    return st.one_of(
        st.builds(Apply, WORDS, st.lists(inner, min_size=1, max_size=3).map(tuple)),
        st.builds(Neg, inner),
        st.builds(Not, inner),
        st.builds(Binary, st.sampled_from(OPS), inner, inner),
        st.builds(If, inner, inner, inner),
        st.builds(
            Aggregate,
            st.sampled_from(["sum", "prod", "forall", "exists"]),
            st.lists(typed, min_size=1, max_size=2).map(tuple),
            inner,
        ),
        st.builds(
            Distribution,
            st.sampled_from(["Bernoulli", "KronDelta", "DiracDelta", "Normal"]),
            st.lists(inner, min_size=1, max_size=2).map(tuple),
        ),
    )


EXPRESSIONS = st.recursive(LEAVES, _extend, max_leaves=12)


@given(EXPRESSIONS)
def test_generated_expressions_round_trip(expr: Expr) -> None:
    text = write_expr(expr)
    assert parse_expr(text) == expr, text


@given(EXPRESSIONS, st.integers(0, 200), st.integers(0, 3), st.text("(){}[];,=~-<>?@_' x1", max_size=3))
def test_damaged_text_raises_only_rddl_error(expr: Expr, position: int, cut: int, junk: str) -> None:
    text = f"domain d {{ reward = {write_expr(expr)}; }}"
    position = min(position, len(text))
    damaged = text[:position] + junk + text[position + cut :]
    try:
        parse_rddl(damaged)
    except RddlError as error:
        assert str(error).startswith("<string>:")
