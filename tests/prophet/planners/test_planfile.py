"""Plan files as Fast Downward and pyperplan write them."""

from __future__ import annotations

import pytest

from alica.errors import PlannerError
from alica.prophet.planner import Plan, PlanStep
from alica.prophet.planners.planfile import format_plan, parse_plan


def test_fast_downward_plan_with_cost_comment() -> None:
    plan = parse_plan("(pick-up b)\n(STACK b a)\n; cost = 7 (general cost)\n")
    assert plan == Plan((PlanStep("pick-up", ("b",)), PlanStep("stack", ("b", "a"))), 7.0)


def test_without_cost_comment_the_cost_is_the_length() -> None:
    assert parse_plan("; a comment\n\n(noop)\n(move a b)\n").cost == 2.0


def test_round_trip() -> None:
    plan = Plan((PlanStep("a", ("x", "y")), PlanStep("b")), 2.0)
    assert parse_plan(format_plan(plan)) == plan
    assert format_plan(plan).endswith("; cost = 2\n")


@pytest.mark.parametrize("text", ["move a b\n", "()\n"])
def test_bad_lines(text: str) -> None:
    with pytest.raises(PlannerError, match="sas_plan:1"):
        parse_plan(text, "sas_plan")
