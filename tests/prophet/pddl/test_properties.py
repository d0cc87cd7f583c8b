"""Property-based tests: generated domains and problems round-trip; garbage raises only PddlError."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from alica.prophet.pddl import (
    Action,
    And,
    Atom,
    Domain,
    Equals,
    Not,
    Or,
    PddlError,
    Predicate,
    Problem,
    either,
    parse_domain,
    parse_problem,
    write_domain,
    write_problem,
)
from alica.prophet.planner import Feature

NAMES = st.sampled_from(["a", "b", "c", "d-1", "e_2"])
TYPES = {"thing": ("object",), "box": ("thing",), "cup": ("thing",), "mug": ("box", "cup")}
KINDS = ["object", *TYPES, either(["box", "cup"]), either(["mug", "thing"])]
"""Parameter types: plain, one with two parents (mug) and (either ...) types."""


@st.composite
def domains(draw: st.DrawFn) -> Domain:
    """A small random domain with all features declared."""
    arities = draw(st.lists(st.integers(0, 2), min_size=1, max_size=4))
    predicates = tuple(
        Predicate(f"p{i}", tuple((f"?x{j}", draw(st.sampled_from(KINDS))) for j in range(n)))
        for i, n in enumerate(arities)
    )
    actions = []
    for k in range(draw(st.integers(0, 3))):
        params = tuple((f"?v{j}", draw(st.sampled_from(KINDS))) for j in range(draw(st.integers(0, 2))))
        terms = [p for p, _ in params] + ["k"]

        def atom() -> Atom:
            pred = draw(st.sampled_from(predicates))
            return Atom(pred.name, tuple(draw(st.sampled_from(terms)) for _ in range(pred.arity)))

        pre_parts = [atom() if draw(st.booleans()) else Not(atom()) for _ in range(draw(st.integers(0, 3)))]
        if len(params) == 2 and draw(st.booleans()):
            pre_parts.append(Not(Equals(params[0][0], params[1][0])))
        if pre_parts and draw(st.booleans()):
            pre_parts = [Or(tuple(pre_parts))]
        effects = [atom() if draw(st.booleans()) else Not(atom()) for _ in range(draw(st.integers(0, 3)))]
        precondition = pre_parts[0] if len(pre_parts) == 1 and draw(st.booleans()) else And(tuple(pre_parts))
        actions.append(Action(f"act{k}", params, precondition, And(tuple(effects))))
    return Domain(
        draw(NAMES),
        frozenset(Feature),
        dict(TYPES),
        (("k", "box"),),
        predicates,
        (),
        tuple(actions),
        frozenset({"disjunctive-preconditions"}),
    )


@given(domains())
def test_generated_domains_round_trip(domain: Domain) -> None:
    assert parse_domain(write_domain(domain)) == domain


@given(domains(), st.data())
def test_generated_problems_round_trip(domain: Domain, data: st.DataObject) -> None:
    objects = tuple(
        (f"o{i}", data.draw(st.sampled_from(["object", *TYPES]))) for i in range(data.draw(st.integers(0, 3)))
    )
    names = [o for o, _ in objects] + ["k"]
    facts = tuple(
        Atom(p.name, tuple(data.draw(st.sampled_from(names)) for _ in range(p.arity)))
        for p in data.draw(st.lists(st.sampled_from(domain.predicates), max_size=4))
    )
    goal = And(tuple(facts[:2]))
    problem = Problem("prob", domain.name, objects, facts, goal)
    assert parse_problem(write_problem(problem), domain=domain) == problem


TOKENS = st.sampled_from(
    [
        "(",
        ")",
        "(",
        ")",
        "define",
        "domain",
        "problem",
        ":action",
        ":predicates",
        ":parameters",
        ":precondition",
        ":effect",
        ":types",
        ":requirements",
        ":strips",
        ":typing",
        "and",
        "not",
        "or",
        "forall",
        "when",
        "=",
        "-",
        "?x",
        "?y",
        "p",
        "q",
        "1",
        "1.5x",
        ";c\n",
        "\n",
        "increase",
        "(total-cost)",
        ":init",
        ":goal",
        ":objects",
    ]
)


@given(st.lists(TOKENS, max_size=40))
def test_garbage_raises_only_pddl_error(tokens: list[str]) -> None:
    text = " ".join(tokens)
    for parse in (parse_domain, parse_problem):
        try:
            parse(text, "g.pddl")
        except PddlError as error:
            assert str(error).startswith(("g.pddl:", "error:"))


@given(st.text(max_size=60))
def test_random_text_raises_only_pddl_error(text: str) -> None:
    try:
        parse_domain("(define (domain d) " + text, "g.pddl")
    except PddlError:
        pass
