"""Round trips: parse(write(tree)) == tree for the paper's files, every construct, and generated expressions."""

from __future__ import annotations

import string
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from alica.prophet.rddl import (
    KEYWORDS,
    PVARIABLE_KINDS,
    Aggregate,
    Apply,
    Assignment,
    Binary,
    BoolConst,
    Constant,
    Cpf,
    Distribution,
    Domain,
    EnumValue,
    Expr,
    If,
    Instance,
    IntConst,
    Name,
    Neg,
    NonFluents,
    Not,
    ObjectsDecl,
    Param,
    PVariable,
    RddlError,
    RddlFile,
    RealConst,
    TypeDecl,
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
from alica.prophet.rddl.parser import parse_blocks
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


CONSTANTS: st.SearchStrategy[Constant] = st.one_of(
    st.builds(BoolConst, st.booleans()),
    st.builds(IntConst, st.integers(-1000, 1000)),
    st.builds(RealConst, st.floats(-1e6, 1e6, allow_nan=False)),
    WORDS.map(lambda w: EnumValue("@" + w)),
    WORDS.map(Apply),
)
NAMES = WORDS.map(Name)


@st.composite
def domains(draw: st.DrawFn) -> Domain:
    """A random domain; its expressions name anything (read back unchecked)."""
    types = tuple(
        draw(
            st.lists(
                st.one_of(
                    st.builds(TypeDecl, WORDS, NAMES),
                    st.builds(
                        TypeDecl, WORDS, st.none(), st.lists(WORDS.map(lambda w: "@" + w), min_size=1).map(tuple)
                    ),
                ),
                max_size=3,
            )
        )
    )
    pvariables = []
    for index in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(PVARIABLE_KINDS))
        level = draw(st.none() | st.integers(1, 3)) if kind == "interm-fluent" else None
        pvariables.append(
            PVariable(
                f"p{index}",
                tuple(draw(st.lists(NAMES, max_size=3))),
                kind,
                draw(st.sampled_from(["bool", "int", "real"]).map(Name) | NAMES),
                draw(st.none() | CONSTANTS),
                level,
            )
        )
    cpfs = tuple(
        Cpf(p.name, p.kind == "state-fluent", tuple(Param(f"?x{i}") for i in range(len(p.params))), draw(EXPRESSIONS))
        for p in pvariables
        if draw(st.booleans())
    )
    small = st.lists(EXPRESSIONS, max_size=2).map(tuple)
    return Domain(
        draw(WORDS),
        tuple(draw(st.lists(WORDS, max_size=3))),
        types,
        tuple(pvariables),
        cpfs,
        draw(st.none() | EXPRESSIONS),
        draw(small),
        draw(small),
        draw(small),
    )


ASSIGNMENTS = st.lists(
    st.builds(
        Assignment, WORDS, st.lists(NAMES | WORDS.map(lambda w: Name("@" + w)), max_size=3).map(tuple), CONSTANTS
    ),
    max_size=4,
).map(tuple)
OBJECTS = st.lists(st.builds(ObjectsDecl, NAMES, st.lists(NAMES, min_size=1, max_size=3).map(tuple)), max_size=3).map(
    tuple
)


@given(
    domains(),
    st.builds(NonFluents, WORDS, NAMES, OBJECTS, ASSIGNMENTS),
    st.builds(
        Instance,
        WORDS,
        NAMES,
        st.none() | NAMES,
        OBJECTS,
        ASSIGNMENTS,
        st.none() | st.integers(1, 50),
        st.none() | st.integers(1, 500),
        st.none() | st.floats(0, 1),
    ),
)
def test_generated_blocks_round_trip(domain: Domain, non_fluents: NonFluents, instance: Instance) -> None:
    blocks = RddlFile(domain, non_fluents, instance)
    text = write_rddl(blocks)
    assert parse_blocks(text) == blocks, text


PAPER_DOMAIN = (DATA / "multi_ros_robot_mdp.rddl").read_text(encoding="utf-8")


@given(st.integers(0, len(PAPER_DOMAIN)), st.integers(0, 12), st.text("(){}[];,:=~-^|<>?@_' xr1\n", max_size=4))
def test_damaged_paper_domain_raises_only_rddl_error(position: int, cut: int, junk: str) -> None:
    damaged = PAPER_DOMAIN[:position] + junk + PAPER_DOMAIN[position + cut :]
    try:
        parse_rddl(damaged, "paper.rddl")
    except RddlError as error:
        assert str(error).startswith("paper.rddl:")
