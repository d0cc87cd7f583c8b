"""``alica plan``: solve a PDDL problem with a planner back-end, validate the plan, print it.

Exit codes: 0 solved (the plan is valid), 1 input error or a failed planner
(also: a back-end returned an invalid plan), 2 wrong usage, 3 proven
unsolvable, 4 time limit reached without a plan.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from alica.errors import AlicaError
from prophet.planner import Plan, PlanResult, PlanStatus

EXIT_OK, EXIT_ERROR, EXIT_UNSOLVABLE, EXIT_TIMEOUT = 0, 1, 3, 4


def add_parser(sub: Any) -> None:
    """Add the ``plan`` subcommand to the ``alica`` parser."""
    from prophet.planners import PLANNERS

    p = sub.add_parser(
        "plan",
        help="solve a PDDL planning problem and print a validated plan",
        description="Solve a PDDL problem with a planner back-end, check the plan with prophet.validate and print it "
        "(one action a line, then ';' lines with cost, times and expansions: the output is itself a plan file). "
        "Exit 0 solved, 1 input error or planner failure, 3 proven unsolvable, 4 time limit reached without a plan.",
    )
    p.add_argument("domain", metavar="DOMAIN", help="a PDDL domain file")
    p.add_argument("problem", metavar="PROBLEM", help="a PDDL problem file")
    p.add_argument(
        "--planner",
        default="builtin",
        choices=sorted(PLANNERS),
        help="the back-end (default builtin; fd needs: pip install 'alica-teams[fd]')",
    )
    p.add_argument(
        "--time-limit", type=_positive, default=60.0, metavar="S", help="wall seconds for the search (default 60)"
    )
    p.add_argument(
        "--anytime", action="store_true", help="keep improving the plan until the time limit or a proven optimum"
    )
    p.add_argument(
        "--json",
        action="store_true",
        help='print {"solved", "cost", "plan", "time_first_s", "time_s", "expansions"} as JSON',
    )
    p.set_defaults(run=cmd_plan)


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of seconds") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"the time limit must be positive, not {text}")
    return value


def cmd_plan(args: argparse.Namespace) -> int:
    """Run ``alica plan``; returns the exit code."""
    from prophet.pddl import PddlError, read_domain, read_problem
    from prophet.planners import get_planner

    try:
        domain = read_domain(args.domain)
        problem = read_problem(args.problem, domain)
    except PddlError as exc:
        print(str(exc), file=sys.stderr)
        return EXIT_ERROR
    planner = get_planner(args.planner)
    if getattr(planner, "reads_files", False):
        _check_features(planner, domain, problem)
        result = planner.solve(args.domain, args.problem, time_limit=args.time_limit, anytime=args.anytime)
    else:
        result = planner.solve(domain, problem, time_limit=args.time_limit, anytime=args.anytime)
    if result.status is PlanStatus.ERROR and result.plan is None:
        raise AlicaError(f"planner '{planner.name}' failed: {result.message or 'no reason given'}")
    cost = None
    if result.plan is not None:
        cost = _validated_cost(planner.name, (domain, problem), result.plan)
    if args.json:
        print(json.dumps(_summary(result, cost)))
    else:
        _print_text(result, cost)
    if result.plan is not None:
        return EXIT_OK
    if result.status is PlanStatus.UNSOLVABLE:
        return EXIT_UNSOLVABLE
    return EXIT_TIMEOUT


def _check_features(planner: Any, domain: Any, problem: Any) -> None:
    lacking = planner.missing(domain.requirements | problem.requirements)
    if lacking:
        names = ", ".join(sorted(f.value for f in lacking))
        raise AlicaError(
            f"planner '{planner.name}' does not support :{names}; use another planner (alica plan --planner ...)"
        )


def _validated_cost(name: str, task: tuple[Any, Any], plan: Plan) -> float:
    """The plan's cost as :func:`prophet.validate.validate_plan` computes it.

    Raises:
        AlicaError: the plan is not valid (the message gives the reason).
    """
    from prophet.validate import validate_plan

    check = validate_plan(task, plan)
    if not check.valid:
        raise AlicaError(f"planner '{name}' returned an invalid plan: {check.reason}")
    return check.cost


def _number(value: float) -> int | float:
    return int(value) if float(value).is_integer() else value


def _summary(result: PlanResult, cost: float | None) -> dict[str, Any]:
    plan = [str(step) for step in result.plan.steps] if result.plan is not None else None
    return {
        "solved": result.plan is not None,
        "cost": None if cost is None else _number(cost),
        "plan": plan,
        "time_first_s": None if result.time_first_s is None else round(result.time_first_s, 6),
        "time_s": round(result.time_s, 6),
        "expansions": result.expansions,
    }


def _print_text(result: PlanResult, cost: float | None) -> None:
    if result.plan is None or cost is None:
        why = "proven unsolvable" if result.status is PlanStatus.UNSOLVABLE else "time limit reached"
        print(f"; no plan: {why} after {result.time_s:.3f} s ({result.planner}, {result.expansions} expansions)")
        if result.message:
            print(f"; {result.message}")
        return
    for step in result.plan.steps:
        print(step)
    first = f"{result.time_first_s:.3f} s" if result.time_first_s is not None else "-"
    print(f"; cost = {_number(cost)} ({len(result.plan)} steps, valid: checked with prophet.validate)")
    print(f"; time to first plan: {first}")
    print(f"; final cost: {_number(cost)} after {result.time_s:.3f} s ({result.status.value})")
    print(f"; expansions: {result.expansions}")
    print(f"; planner: {result.planner}")
