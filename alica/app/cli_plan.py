"""``alica plan``: solve a PDDL problem with a planner back-end, validate the plan, print it.

Given a plan file instead of a PDDL domain, it plans one of the file's
planning problems offline (its ``world``, or ``--world``), prints the tasks
pRoPhEt MAS makes of the plan and, with ``--emit-plan FILE``, writes the
generated ALICA plan as a YAML plan file.

Exit codes: 0 solved (the plan is valid), 1 input error or a failed planner
(also: a back-end returned an invalid plan), 2 wrong usage, 3 proven
unsolvable, 4 time or memory limit reached without a plan.

``--time-limit`` covers reading, grounding and search; ``--memory-limit``
bounds the process's resident memory while it reads, grounds and searches
(measured, and checked against the estimated size of what a stage is about
to build); with ``--parallel`` it bounds each agent's search. A limit reached prints one line on standard error naming the stage
(``alica: time limit 10 s reached while grounding (...)``) and exits 4.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.errors import AlicaError, PlannerError
from alica.prophet.planner import DEFAULT_MEMORY_MB, LimitReached, Limits, Plan, PlanResult, PlanStatus

if TYPE_CHECKING:
    from alica.prophet.ground import GroundTask
    from alica.prophet.pddl import Domain, Problem
    from alica.prophet.planner import Planner

EXIT_OK, EXIT_ERROR, EXIT_UNSOLVABLE, EXIT_TIMEOUT = 0, 1, 3, 4
PLAN_FILE_SUFFIXES = (".yaml", ".yml", ".xml")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``plan`` subcommand to the ``alica`` parser."""
    from alica.prophet.planners import PLANNERS

    p = sub.add_parser(
        "plan",
        help="solve a PDDL planning problem and print a validated plan",
        description="Solve a PDDL problem with a planner back-end, check the plan with alica.prophet.validate and print it "
        "(one action a line, then ';' lines with cost, times and expansions: the output is itself a plan file). "
        "Exit 0 solved, 1 input error or planner failure, 3 proven unsolvable, 4 time limit reached without a plan.",
    )
    p.add_argument("domain", metavar="DOMAIN", help="a PDDL domain file, or a plan file with a planning problem")
    p.add_argument("problem", metavar="PROBLEM", nargs="?", help="a PDDL problem file (not with a plan file)")
    p.add_argument(
        "--problem",
        dest="problem_name",
        metavar="NAME",
        help="with a plan file: the planning problem (default: its only one)",
    )
    p.add_argument(
        "--world",
        metavar="FACTS",
        help='with a plan file: the world as facts, e.g. "ontable(a) and clear(a) and handempty(r)"',
    )
    p.add_argument("--goal", metavar="FORMULA", help="with a plan file: the goal instead of the problem's")
    p.add_argument(
        "--emit-plan", metavar="FILE", help="with a plan file: write the generated ALICA plan and its tasks as YAML"
    )
    p.add_argument(
        "--planner",
        default=None,
        choices=sorted(PLANNERS),
        help="the back-end (default: a plan file's problem's own planner, else builtin; fd needs: "
        "pip install 'alica-teams[fd]')",
    )
    p.add_argument(
        "--time-limit",
        type=_positive,
        default=60.0,
        metavar="S",
        help="wall seconds for reading, grounding and search (default 60)",
    )
    p.add_argument(
        "--memory-limit",
        type=_megabytes,
        default=float(DEFAULT_MEMORY_MB),
        metavar="MB",
        help=f"the resident memory this planning process may use, in MB (default {DEFAULT_MEMORY_MB})",
    )
    p.add_argument(
        "--anytime", action="store_true", help="keep improving the plan until the time limit or a proven optimum"
    )
    p.add_argument(
        "--json",
        action="store_true",
        help='print {"solved", "cost", "plan", "time_first_s", "time_s", "expansions"} as JSON '
        '(with --parallel also "agents" and "messages")',
    )
    p.add_argument(
        "--parallel",
        type=_agents,
        metavar="N",
        help="MAGiC: split the search over N agent processes on loopback (zenoh), the first valid plan wins",
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


def _agents(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of agents") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"--parallel needs at least 1 agent, not {text}")
    return value


def _megabytes(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number of MB") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"the memory limit must be a positive number of MB, not {text}")
    return value


def cmd_plan(args: argparse.Namespace) -> int:
    """Run ``alica plan``; returns the exit code."""
    from alica.prophet.pddl import PddlError

    start = time.monotonic()
    limits = Limits(args.time_limit, args.memory_limit, whole_process=True)
    if args.planner is None and Path(args.domain).suffix.lower() not in PLAN_FILE_SUFFIXES:
        args.planner = "builtin"
    try:
        return _plan(args, limits)
    except LimitReached as exc:  # while reading or before the planner ran: reported as the planner's own limits are
        planner = args.planner or "builtin"
        result = PlanResult(exc.status, None, planner, None, time.monotonic() - start, 0, str(exc))
        return _report(args, planner, result, lambda plan: plan.cost)
    except PddlError as exc:  # found while grounding: FILE:LINE:COL: error: ... when it has a place
        return _refuse(args, exc)
    except AlicaError as exc:
        if not args.json:
            raise
        return _refuse(args, exc)


def _refuse(args: argparse.Namespace, exc: Exception) -> int:
    """An input the planner refuses: the message on standard error; with --json also ``{"solved": false, "error"}``."""
    from alica.prophet.pddl import PddlError

    text = str(exc)
    if args.json:
        print(json.dumps({"solved": False, "error": text}))
    print(text if isinstance(exc, PddlError) else f"alica: error: {text}", file=sys.stderr)
    return EXIT_ERROR


def _plan(args: argparse.Namespace, limits: Limits) -> int:
    from alica.prophet.pddl import PddlError, read_domain, read_problem
    from alica.prophet.planners import get_planner

    if Path(args.domain).suffix.lower() in PLAN_FILE_SUFFIXES:
        return _plan_file(args, limits)
    if args.problem is None:
        raise AlicaError(
            f"{args.domain}: a PDDL domain needs a PROBLEM file (or give a plan file with a planning problem)"
        )
    if args.emit_plan or args.problem_name or args.world or args.goal:
        raise AlicaError("--problem, --world, --goal and --emit-plan go with a plan file, not with PDDL files")
    if args.parallel is not None:
        return _plan_parallel(args, limits)
    try:
        domain = read_domain(args.domain, limits)
        problem = read_problem(args.problem, domain, limits)
    except PddlError as exc:
        return _refuse(args, exc)
    if domain.durative_actions and args.planner == "builtin":  # durative actions: the builtin search, scheduled
        args.planner = "temporal"
    planner = get_planner(args.planner)
    if planner.name == "temporal":
        return _plan_temporal(args, planner, domain, problem, limits)
    if planner.reads_files:
        _check_features(planner, domain, problem)
        result = planner.solve(args.domain, args.problem, anytime=args.anytime, limits=limits)
    else:
        result = planner.solve(domain, problem, anytime=args.anytime, limits=limits)
    return _report(
        args,
        planner.name,
        result,
        lambda plan: _validated_cost(planner.name, _checked_on(planner, domain, problem), plan),
    )


def _plan_temporal(args: argparse.Namespace, planner: Planner, domain: Domain, problem: Problem, limits: Limits) -> int:
    """A temporal task: the schedule printed as ``START: (action args) [DURATION]`` lines, checked happening by
    happening; the cost is the makespan."""
    from alica.prophet.planners.temporal import TemporalPlanner
    from alica.prophet.validate_temporal import validate_temporal_plan

    try:
        result = planner.solve(domain, problem, anytime=args.anytime, limits=limits)
    except PlannerError as exc:
        return _refuse(args, exc)
    schedules: dict[int, Any] = {}

    def timed(plan: Plan) -> Any:
        if id(plan) not in schedules:
            schedules[id(plan)] = TemporalPlanner.schedule_of(domain, problem, plan)
        return schedules[id(plan)]

    def makespan(plan: Plan) -> float:
        checked = validate_temporal_plan(domain, problem, timed(plan).plan)
        if not checked.valid:
            raise AlicaError(f"planner '{planner.name}' returned an invalid schedule: {checked.reason}")
        return checked.cost

    def extra() -> dict[str, Any]:
        assert result.plan is not None
        return {"sequential_makespan": _number(timed(result.plan).sequential_makespan)}

    return _report(
        args,
        planner.name,
        result,
        makespan,
        extra,
        lines_of=lambda plan: [str(t) for t in timed(plan).plan.steps],
        checker="alica.prophet.validate_temporal",
    )


def _checked_on(planner: Planner, domain: Domain, problem: Problem) -> GroundTask | tuple[Domain, Problem]:
    """What a plan is validated on: the planner's own ground task when it grounded the task (each step's
    ground operator applied with the grounding's reference semantics, derived facts recomputed by their
    own fixpoint, not the search's), else the lifted domain and problem (as ``alica validate-plan`` does)."""
    grounded = planner.last_ground_task
    return (domain, problem) if grounded is None else grounded


def _plan_parallel(args: argparse.Namespace, limits: Limits) -> int:
    """``--parallel N``: MAGiC over N agent processes (the builtin planner's first plan, not anytime)."""
    from alica.app.magic_processes import run_processes
    from alica.prophet.pddl import PddlError

    if args.planner != "builtin" or args.anytime:
        raise AlicaError("--parallel runs MAGiC with the builtin planner's first plan: drop --planner and --anytime")
    try:
        texts = Path(args.domain).read_text(encoding="utf-8"), Path(args.problem).read_text(encoding="utf-8")
    except OSError as exc:
        raise AlicaError(f"cannot read {exc.filename}: {exc.strerror}") from None
    remaining = limits.remaining()
    try:
        run = run_processes(
            *texts,
            args.parallel,
            timeout=args.time_limit if remaining is None else remaining,
            memory_mb=args.memory_limit,
        )
    except PddlError as exc:
        return _refuse(args, exc)
    message = "" if run.outcome is None else run.outcome.message
    if run.outcome is None:
        message = f"time limit {args.time_limit:g} s reached before the round ended"
    result = PlanResult(run.status, run.plan, "magic", run.first_plan_s, run.wall_s, run.expansions, message)
    return _report(
        args,
        "magic",
        result,
        lambda plan: plan.cost,  # validated by the leader
        lambda: {"agents": run.agents, "messages": run.messages},
        always=True,
    )


def _report(
    args: argparse.Namespace,
    name: str,
    result: PlanResult,
    cost_of: Callable[[Plan], float],
    extra: Callable[[], dict[str, Any]] | None = None,
    *,
    always: bool = False,
    lines_of: Callable[[Plan], list[str]] | None = None,
    checker: str = "alica.prophet.validate",
) -> int:
    """Print the result; ``cost_of`` validates the plan (raising when it is not valid); ``extra`` adds fields (and lines).

    ``extra`` is asked only with a plan, unless ``always``. ``lines_of`` shows a plan otherwise than
    its steps (a temporal plan's timed steps); ``checker`` names what validated it.
    """
    if result.status is PlanStatus.ERROR and result.plan is None:
        raise AlicaError(f"planner '{name}' failed: {result.message or 'no reason given'}")
    cost = None
    more: dict[str, Any] = {}
    if result.plan is not None:
        cost = cost_of(result.plan)
    if extra is not None and (always or result.plan is not None):
        more = extra()
    lines = None if result.plan is None else (lines_of or _step_lines)(result.plan)
    if args.json:
        print(json.dumps({**_summary(result, cost, lines), **more}))
    else:
        _print_text(result, cost, lines, checker)
        for key, value in more.items():
            print(f"; {key}: {value}")
    if result.plan is not None:
        return EXIT_OK
    if result.status is PlanStatus.UNSOLVABLE:
        return EXIT_UNSOLVABLE
    print(f"alica: {result.message or 'time limit reached'}", file=sys.stderr)
    return EXIT_TIMEOUT


def _plan_file(args: argparse.Namespace, limits: Limits) -> int:
    """Plan a planning problem of a plan file offline; print the plan and its tasks, maybe emit the generated plan."""
    from dataclasses import replace

    from alica.io import import_reference, load_library
    from alica.model import Condition, ConditionKind
    from alica.prophet.pipeline import plan_problem
    from alica.prophet.tasks import create_tasks, emit_yaml
    from alica.prophet.world import read_world

    if args.problem is not None:
        raise AlicaError(f"{args.domain} is a plan file: name its planning problem with --problem, not a PROBLEM file")
    library = load_library(args.domain)
    problems = library.problems
    if args.problem_name is None:
        if len(problems) != 1:
            raise AlicaError(
                f"{args.domain}: choose a planning problem with --problem ({', '.join(sorted(problems)) or 'it has none'})"
            )
        name = next(iter(problems))
    elif args.problem_name not in problems:
        raise AlicaError(
            f"{args.domain}: no planning problem named '{args.problem_name}'; problems: {', '.join(sorted(problems)) or 'none'}"
        )
    else:
        name = args.problem_name
    problem = problems[name]
    if args.world is not None:
        problem = replace(problem, world=Condition(ConditionKind.PRE, args.world))
    if args.goal is not None:
        problem = replace(problem, goal=Condition(ConditionKind.POST, args.goal))
    if problem.world is None:
        raise AlicaError(
            f"planning problem '{name}' has no 'world' (it is read from the world model at run time): give one with --world"
        )
    world = read_world(problem, library, (), ())
    planning = plan_problem(problem, library, world, planner=args.planner)
    args.planner = planning.planner.name
    result = planning.solve(anytime=args.anytime, limits=limits)  # PlannerError: an invalid plan

    def tasks() -> dict[str, Any]:
        assert result.plan is not None
        steps = result.plan.steps
        if not steps:
            return {"tasks": []}
        roleset = next(iter(sorted(library.rolesets.items())))[1] if library.rolesets else None
        if roleset is None:
            raise AlicaError(f"{args.domain}: the generated plan needs a role set for its task priorities; import one")
        created = create_tasks(
            f"{name}Plan",
            steps,
            library,
            world.facts,
            world.robots or ("self",),
            roleset,
            "Default",
            standby=problem.wait_plan,
            per_robot=planning.planner.stepwise,
        )
        if args.emit_plan:
            out = Path(args.emit_plan)
            imports = sorted({import_reference(d.path, out.parent) for d in library.documents if d.path})
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(emit_yaml(created, imports), encoding="utf-8")
        return {
            "tasks": [[s.label for s in task] for task in created.tasks],
            **({"emitted": str(args.emit_plan)} if args.emit_plan else {}),
        }

    def cost_of(_: Plan) -> float:
        assert result.plan is not None  # validated by the pipeline
        return result.plan.cost

    return _report(args, planning.planner.name, result.run, cost_of, tasks)


def _check_features(planner: Planner, domain: Domain, problem: Problem) -> None:
    lacking = planner.missing(domain.requirements | problem.requirements)
    if lacking:
        names = ", ".join(sorted(f.value for f in lacking))
        raise AlicaError(
            f"planner '{planner.name}' does not support :{names}; use another planner (alica plan --planner ...)"
        )


def _validated_cost(name: str, task: GroundTask | tuple[Domain, Problem], plan: Plan) -> float:
    """The plan's cost as :func:`alica.prophet.validate.validate_plan` computes it.

    Raises:
        AlicaError: the plan is not valid (the message gives the reason).
    """
    from alica.prophet.validate import validate_plan

    check = validate_plan(task, plan)
    if not check.valid:
        raise AlicaError(f"planner '{name}' returned an invalid plan: {check.reason}")
    return check.cost


def _number(value: float) -> int | float:
    return int(value) if float(value).is_integer() else value


def _step_lines(plan: Plan) -> list[str]:
    return [str(step) for step in plan.steps]


def _summary(result: PlanResult, cost: float | None, lines: list[str] | None = None) -> dict[str, Any]:
    if lines is None and result.plan is not None:
        lines = _step_lines(result.plan)
    return {
        "solved": result.plan is not None,
        "cost": None if cost is None else _number(cost),
        "plan": lines,
        "time_first_s": None if result.time_first_s is None else round(result.time_first_s, 6),
        "time_s": round(result.time_s, 6),
        "expansions": result.expansions,
    }


def _print_text(
    result: PlanResult, cost: float | None, lines: list[str] | None = None, checker: str = "alica.prophet.validate"
) -> None:
    if result.plan is None or cost is None:
        why = {PlanStatus.UNSOLVABLE: "proven unsolvable", PlanStatus.MEMORY: "memory limit reached"}.get(
            result.status, "time limit reached"
        )
        print(f"; no plan: {why} after {result.time_s:.3f} s ({result.planner}, {result.expansions} expansions)")
        if result.message:
            print(f"; {result.message}")
        return
    for line in lines if lines is not None else _step_lines(result.plan):
        print(line)
    first = f"{result.time_first_s:.3f} s" if result.time_first_s is not None else "-"
    print(f"; cost = {_number(cost)} ({len(result.plan)} steps, valid: checked with {checker})")
    print(f"; time to first plan: {first}")
    print(f"; final cost: {_number(cost)} after {result.time_s:.3f} s ({result.status.value})")
    print(f"; expansions: {result.expansions}")
    print(f"; planner: {result.planner}")
    from alica.prophet.planners import planner_class

    if planner_class(result.planner).stepwise:
        print("; the next step only: this planner plans one step at a time (a team plans the next when it is over)")
