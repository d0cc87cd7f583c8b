"""The ``sum`` aggregate and the ``agents(E)`` binder domain of the formula language."""

from __future__ import annotations

from typing import ClassVar

import pytest

from alica.errors import EvaluationError, FormulaError
from alica.lang import parse
from alica.lang.ast import Call, Compare, Quantified, agents_of
from alica.lang.checker import check
from alica.lang.evaluator import evaluate, holds
from alica.lang.unparse import unparse


class Team:
    """Two explorers with a gain each; ``Frontier`` objects f1..f3."""

    gains: ClassVar[dict[str, float]] = {"r1": 1.5, "r2": 2.0}

    def lookup(self, name: str, args: tuple[object, ...]) -> object | None:
        if name == "gain" and len(args) == 1:
            return self.gains.get(str(args[0]))
        return None

    def objects(self, type_name: str) -> list[str]:
        return {"agents(Explore)": ["r1", "r2"], "Frontier": ["f1", "f2", "f3"]}.get(type_name, [])


@pytest.mark.parametrize(
    "text",
    [
        "sum a in agents(Explore): gain(a)",
        "(sum a in agents(Explore): gain(a)) > 3",
        "(sum a in agents(Explore): gain(a)) * 2 + 1",
        "sum a, b in agents(Explore): gain(a) * gain(b)",
        "forall a, b in agents(Explore): a == b or gain(a) != gain(b)",
        "exists f in Frontier, a in agents(Explore): f == a",
    ],
)
def test_aggregates_and_agent_domains_round_trip(text):
    node = parse(text)
    assert parse(unparse(node)) == node


def test_the_agents_domain_is_kept_as_its_type_name():
    node = parse("forall a in agents(Explore): gain(a) > 0")
    assert isinstance(node, Quantified)
    assert node.binders == (("a", "agents(Explore)"),)
    assert agents_of("agents(Explore)") == "Explore"
    assert agents_of("Frontier") is None


def test_a_sum_adds_its_term_over_the_domain():
    assert evaluate("sum a in agents(Explore): gain(a)", Team()) == 3.5
    assert evaluate("sum a in agents(Explore), f in Frontier: 1", Team()) == 6
    assert evaluate("sum a in Nothing: gain(a)", Team()) == 0
    assert holds("sum a in agents(Explore): gain(a) > 3", Team())  # the comparison takes the whole sum


def test_the_body_of_a_sum_ends_with_its_arithmetic_term():
    node = parse("sum a in agents(Explore): gain(a) + 1 > 3")
    assert isinstance(node, Compare) and isinstance(node.left, Quantified) and node.left.kind == "sum"


def test_sum_is_still_a_name_where_no_aggregate_starts():
    node = parse("sum(x, y) > 2")
    assert isinstance(node, Compare) and isinstance(node.left, Call) and node.left.name == "sum"
    assert parse("sum > 2").left.name == "sum"  # type: ignore[attr-defined]


def test_a_sum_is_no_truth_value():
    errors = check("sum a in agents(Explore): gain(a)", boolean=True)
    assert errors and "is a sum, a number, not a truth value" in str(errors[0])
    assert not check("(sum a in agents(Explore): gain(a)) + 1 > 2", boolean=True)
    with pytest.raises(EvaluationError, match="expected a truth value"):
        holds("sum a in agents(Explore): gain(a)", Team())


def test_a_sum_of_something_else_than_numbers_is_a_located_error():
    with pytest.raises(EvaluationError, match="a sum adds numbers"):
        evaluate("sum f in Frontier: f", Team())


def test_a_variable_per_agent_is_read_with_one_argument():
    # frontier(a): the plan's variable 'frontier' of agent a, accepted when 'frontier' is bound
    assert not check("forall a in agents(Explore): frontier(a) != 0", boolean=True, bound={"frontier"})


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("forall a in agents(: a", "expected an entry point, task or state"),
        ("forall a in agents(Explore: a", "expected ')'"),
        ("sum a in: 1", "expected a type name"),
    ],
)
def test_bad_domains_are_located(text, message):
    with pytest.raises(FormulaError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse(text)
