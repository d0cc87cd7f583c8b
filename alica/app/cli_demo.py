"""``alica demo blocksworld``: the blocks-world mission end to end (see :mod:`alica.app.demos.blocksworld`).

Exit 0 when the goal holds, 1 when the time limit passed first or the input is bad.
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TextIO

from alica.app.center.cli import add_live_options, live_session
from alica.app.options import (
    add_deprecated,
    add_field_options,
    add_time_limit,
    count,
    did_you_mean,
    parse_roster,
    time_limit,
)
from alica.app.ros2_options import add_ros2_options, check_ros2, ros2_arguments, ros2_output
from alica.app.timed import add_fault_options, add_network_options, partition, timed
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.app.demos.blocksworld import DemoResult
    from alica.app.demos.lunar import LunarConfig


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``demo`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "demo", help="run a demo mission in the simulator", description="Run a demo mission in the pybullet simulator."
    )
    demos = p.add_subparsers(dest="demo", metavar="DEMO", required=True)
    b = demos.add_parser(
        "blocksworld",
        help="a team plans at run time and stacks blocks (IMPERA Section 8.2)",
        description="A team of mobile manipulators reaches a goal configuration of block stacks. pRoPhEt MAS plans at run "
        "time from the simulated state, and opponent robots disturb the stacks. Exit 0 when the goal holds, 1 when the time "
        "limit passes first.",
    )
    b.add_argument("--robots", type=count(1), default=2, metavar="N", help="team robots r1..rN (default 2)")
    add_deprecated(b, "--agents", "--robots", dest="robots", type=_old_robot_count, metavar="N")
    b.add_argument("--opponents", type=count(0), default=0, metavar="K", help="opponent robots o1..oK (default 0)")
    b.add_argument(
        "--blocks", type=count(1), default=4, metavar="B", help="blocks of the random configurations (default 4)"
    )
    b.add_argument(
        "--seed", type=int, default=0, metavar="S", help="seeds the configurations, the world and the team (default 0)"
    )
    b.add_argument(
        "--goal",
        metavar="FILE",
        help="a YAML file with 'goal' (and optionally 'start') stacks, bottom first: goal: [[a, b], [c]]",
    )
    b.add_argument(
        "--planner",
        choices=("builtin", "temporal"),
        default=None,
        help="plan for the team's time (temporal, the mission's and the default: the skills' durations, refined "
        "by what the team measures) or for the fewest steps (builtin)",
    )
    add_time_limit(b, 600.0, "give up after S simulated seconds (default 600)")
    add_fault_options(
        b,
        crash="crash team robot NAME (r1..rN) at simulated second T: it stops, drops what it holds and goes silent "
        "(repeatable)",
        recover="restart team robot NAME at second T, with an empty memory (repeatable)",
    )
    b.add_argument("--out", metavar="DIR", help="write trace.jsonl, initial.png, final.png and plan.yaml here")
    b.add_argument("--json", action="store_true", help="print the summary as JSON")
    b.add_argument("--gui", action="store_true", help="show the pybullet window")
    add_live_options(b)
    add_ros2_options(b)
    b.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress bar (there is none when standard error is not a terminal)",
    )
    b.add_argument(
        "--processes",
        action="store_true",
        help="one alica agent process per team robot over zenoh, driving its robot in a world server this process "
        "runs (lock-step: the same seed, the same outcome); --crash is then a kill -9 of the robot's agent, "
        "--recover a restart; no opponents",
    )
    b.set_defaults(run=cmd_blocksworld)
    _add_lunar(demos)


def _add_lunar(demos: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    lunar = demos.add_parser(
        "lunar",
        help="explore, find samples, plan and fetch them as a team (IMPERA Sections 6.4, 7, 8.1)",
        description="The IMPERA lunar mission in pybullet with the real skills: the robots map and explore an unknown "
        "field, detect drill samples, the operator chooses which to bring back, pRoPhEt MAS plans the transport at run "
        "time and the team carries the samples to the collection point g. Exit 0 when every chosen sample lies at g, "
        "1 when the mission failed or the time limit passed first.",
    )
    lunar.add_argument(
        "--agents",
        default="scout,stummel,amparo",
        metavar="NAME[:ROLE],...",
        help="the team, from scout (Scout), stummel (Stummel) and amparo (Amparo); a role, if given, is the "
        "robot's own (default scout,stummel,amparo)",
    )
    add_deprecated(lunar, "--robots", "--agents", dest="agents", metavar="NAMES")
    add_field_options(lunar)
    choice = lunar.add_mutually_exclusive_group()
    choice.add_argument(
        "--goal", metavar="FORMULA", help="what to bring back, by the samples' names: 'at(green_white_red, g) and ...'"
    )
    choice.add_argument(
        "--collect", metavar="KINDS", help="the kinds to bring back, e.g. green-white-red,red-black-red"
    )
    lunar.add_argument(
        "--pick",
        type=count(1),
        default=2,
        metavar="K",
        help="without --goal or --collect: bring back the first K samples found (default 2)",
    )
    lunar.add_argument(
        "--seed", type=int, default=0, metavar="S", help="seeds the world, the network and the team (default 0)"
    )
    lunar.add_argument(
        "--crash",
        action="append",
        default=[],
        metavar="NAME@T",
        help="crash robot NAME at simulated second T, or NAME@grasp when it first lifts a sample it grasped (repeatable)",
    )
    add_network_options(lunar)
    add_time_limit(lunar, 900.0, "give up after S simulated seconds (default 900)")
    lunar.add_argument("--out", metavar="DIR", help="write trace.jsonl, map.png and plan.yaml here")
    lunar.add_argument("--json", action="store_true", help="print the summary as JSON")
    lunar.add_argument("--gui", action="store_true", help="show the pybullet window")
    add_live_options(lunar)
    add_ros2_options(lunar)
    lunar.add_argument(
        "--no-progress", action="store_true", help="no progress line (none when standard error is not a terminal)"
    )
    lunar.add_argument(
        "--processes",
        action="store_true",
        help="one alica agent process per robot over zenoh, driving its robot in a world server this process runs "
        "(lock-step: the same seed, the same outcome); --crash is then a kill -9 of the robot's agent",
    )
    lunar.set_defaults(run=cmd_lunar)


def lunar_config(args: argparse.Namespace) -> LunarConfig:
    """The lunar demo's configuration from the command line.

    Raises:
        AlicaError: a value that cannot run (the message names the option).
    """
    from alica.app.demos.lunar import LunarConfig, Partition, check_config, parse_crash

    if not 0.0 <= args.loss <= 1.0:
        raise AlicaError(f"--loss must be a probability in [0, 1], not {args.loss}")
    if args.delay < 0:
        raise AlicaError(f"--delay must be >= 0 milliseconds, not {args.delay}")
    partitions = []
    for text in args.partition:
        groups, start, end = partition(text)
        partitions.append(Partition(tuple(tuple(g) for g in groups), start, end))
    config = LunarConfig(
        robots=_lunar_team(args.agents),
        samples=args.samples,
        rocks=args.rocks,
        size=args.size,
        collect=tuple(k.strip() for k in args.collect.split(",") if k.strip()) if args.collect else (),
        goal=args.goal,
        pick=args.pick,
        seed=args.seed,
        time_limit=args.time_limit,
        loss=args.loss,
        delay=args.delay / 1000.0,
        crashes=tuple(parse_crash(c) for c in args.crash),
        partitions=tuple(partitions),
    )
    check_config(config)
    return config


class LunarProgress:
    """A one-line progress bar on a terminal: simulated time, coverage, samples found and delivered, replans."""

    def __init__(self, stream: TextIO, width: int = 24) -> None:
        self.stream = stream
        self.width = width

    def __call__(self, p: dict[str, Any]) -> None:
        done = int(self.width * min(1.0, p["time"] / p["limit"]))
        bar = "#" * done + "." * (self.width - done)
        chosen = f"{p['delivered']}/{p['chosen']}" if p["chosen"] else "-"
        self.stream.write(
            f"\r[{bar}] sim {p['time']:6.1f} s  coverage {p['coverage']:4.0%}  found {p['found']}  "
            f"delivered {chosen}  replans {p['replans']}  "
        )
        self.stream.flush()

    def close(self) -> None:
        """End the line."""
        self.stream.write("\n")
        self.stream.flush()


def cmd_lunar(args: argparse.Namespace) -> int:
    """Run ``alica demo lunar``; returns the exit code."""
    from alica.app.demos.lunar import run_lunar, summary_lines

    config = lunar_config(args)
    if args.processes and (args.gui or args.center):
        raise AlicaError(
            "--processes runs the world in a server without a window or a live page: leave out --gui and --center"
        )
    check_ros2(args)
    session = live_session(args)
    progress = LunarProgress(sys.stderr) if sys.stderr.isatty() and not args.no_progress else None
    out = Path(args.out) if args.out else None
    try:
        if args.processes:
            from alica.app.demos.lunar_processes import run_lunar_processes

            result = run_lunar_processes(config, on_second=progress, out=out, ros2=ros2_arguments(args))
        else:
            with ros2_output(args) as ros2:
                result = run_lunar(config, on_second=progress, out=out, gui=args.gui, live=session, ros2=ros2)
    finally:
        if progress is not None:
            progress.close()
    if args.json:
        print(json.dumps(result.as_json()))
    else:
        print("\n".join(summary_lines(result)))
    if session is not None:
        session.finish(result.as_json())
    return 0 if result.success else 1


def _lunar_team(text: str) -> tuple[str, ...]:
    """The robots of ``--agents`` for the lunar demo: a role, if given, must be the robot's own.

    Raises:
        AlicaError: not a roster, or a role that is not the robot's (with the closest role's name).
    """
    from alica.app.demos.lunar import ROLES

    roster = parse_roster(text, "--agents")
    for name, role in roster.items():
        own = ROLES.get(name)
        if role is None or own is None:  # an unknown robot: check_config names the robots there are
            continue
        if role != own:
            given = "+" + "+".join(sorted(role)) if isinstance(role, frozenset) else role
            roles = sorted(set(ROLES.values()))
            hint = "" if given in roles else did_you_mean(given, roles)
            raise AlicaError(
                f"--agents: '{name}:{given}': in the lunar demo {name} has the role {own}{hint}; "
                f"write {name} or {name}:{own}"
            )
    return tuple(roster)


def _old_robot_count(text: str) -> int:
    """``demo blocksworld --agents N``, the old spelling of ``--robots N``: a count, not a roster."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"'{text}' is not a count: the blocks demo names its robots r1..rN itself; give their number with --robots N"
        ) from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, not {value}")
    return value


def read_goal_file(path: str) -> tuple[list[list[str]] | None, list[list[str]]]:
    """The ``start`` (optional) and ``goal`` stacks of a goal file.

    Raises:
        AlicaError: the file is missing, not YAML, or holds no valid goal (the message names the file and line).
    """
    import yaml

    from alica.app.demos.blocksworld import check_stacks

    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise AlicaError(f"{path}: cannot read the goal file: {exc.strerror}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        marked = exc if isinstance(exc, yaml.MarkedYAMLError) else None
        mark = marked.problem_mark if marked is not None else None
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark is not None else path
        raise AlicaError(
            f"{where}: not valid YAML ({marked.problem if marked is not None else exc}); "
            "write e.g. 'goal: [[a, b], [c]]'"
        ) from None
    if not isinstance(data, dict) or "goal" not in data:
        raise AlicaError(
            f"{path}:1:1: the goal file needs a 'goal' key with the goal stacks, e.g. 'goal: [[a, b], [c]]'"
        )
    unknown = sorted(set(data) - {"goal", "start"})
    if unknown:
        raise AlicaError(
            f"{path}: unknown key(s) {', '.join(unknown)}; the goal file has 'goal' and optionally 'start'"
        )
    line = next((i + 1 for i, row in enumerate(text.splitlines()) if row.lstrip().startswith("goal")), 1)
    goal = check_stacks(data["goal"], f"{path}:{line}: 'goal'")
    start = check_stacks(data["start"], f"{path}: 'start'") if data.get("start") is not None else None
    return start, goal


class Progress:
    """A one-line progress bar on a terminal: simulated time, goal literals satisfied, replans."""

    def __init__(self, stream: TextIO, limit: float, width: int = 30) -> None:
        self.stream = stream
        self.limit = limit
        self.width = width

    def __call__(self, now: float, satisfied: int, total: int, replans: int) -> None:
        done = int(self.width * satisfied / total) if total else self.width
        bar = "#" * done + "." * (self.width - done)
        self.stream.write(
            f"\r[{bar}] goal {satisfied}/{total}  sim {now:7.1f} s / {self.limit:.0f} s  replans {replans}  "
        )
        self.stream.flush()

    def close(self) -> None:
        """End the line."""
        self.stream.write("\n")
        self.stream.flush()


def cmd_blocksworld(args: argparse.Namespace) -> int:
    """Run ``alica demo blocksworld``; returns the exit code."""
    from alica.app.demos.blocksworld import DemoConfig, run_demo

    start, goal = read_goal_file(args.goal) if args.goal else (None, None)
    time_limit(args)
    config = DemoConfig(
        agents=args.robots,
        opponents=args.opponents,
        blocks=args.blocks,
        seed=args.seed,
        start=start,
        goal=goal,
        time_limit=args.time_limit,
        planner=args.planner,
    )
    actions = fault_actions(args.crash, args.recover, args.robots)
    if args.processes and (args.gui or args.center):
        raise AlicaError(
            "--processes runs the world in a server without a window or a live page: leave out --gui and --center"
        )
    check_ros2(args)
    session = live_session(args)
    progress = Progress(sys.stderr, args.time_limit) if sys.stderr.isatty() and not args.no_progress else None
    out = Path(args.out) if args.out else None
    try:
        if args.processes:
            from alica.app.demos.blocks_processes import run_demo_processes

            result = run_demo_processes(config, on_second=progress, actions=actions, out=out, ros2=ros2_arguments(args))
        else:
            with ros2_output(args) as ros2:
                result = run_demo(
                    config, on_second=progress, actions=actions, out=out, gui=args.gui, live=session, ros2=ros2
                )
    finally:
        if progress is not None:
            progress.close()
    if args.json:
        print(json.dumps(result.as_json()))
    else:
        _print_summary(result)
    if session is not None:
        session.finish(result.as_json())
    return 0 if result.success else 1


class Faultable(Protocol):
    """A team whose robots can be crashed and recovered by name (a simulated team, a team of processes)."""

    def crash(self, name: str) -> None: ...

    def recover(self, name: str) -> None: ...


def fault_actions(
    crashes: Sequence[str], recoveries: Sequence[str], agents: int
) -> list[tuple[float, Callable[[Faultable], None]]]:
    """The demo's timed faults from ``--crash NAME@T`` and ``--recover NAME@T``, in the order given.

    Raises:
        AlicaError: a value is not NAME@T, or NAME is not a team robot.
    """
    team = [f"r{i + 1}" for i in range(agents)]
    actions: list[tuple[float, Callable[[Faultable], None]]] = []
    for option, texts, fault in (("--crash", crashes, _crash), ("--recover", recoveries, _recover)):
        for text in texts:
            who, at, _ = timed(option, text)
            if who not in team:
                raise AlicaError(f"{option}: '{who}' is not a team robot; the team is {', '.join(team)}")
            actions.append((at, functools.partial(fault, who)))
    return actions


def _crash(who: str, team: Faultable) -> None:
    team.crash(who)


def _recover(who: str, team: Faultable) -> None:
    team.recover(who)


def _print_summary(result: DemoResult) -> None:
    state = "success" if result.success else "time limit reached"
    print(
        f"blocksworld: {state} after {result.sim_time_s:.2f} s simulated, {result.wall_time_s:.2f} s wall ({result.real_time_factor:.1f}x real time)"
    )
    print(f"start {result.start}  goal {result.goal}  goal literals {result.satisfied}/{result.goal_literals}")
    print(
        f"steps executed {result.steps_executed}, plans made {result.plans} (the last: {result.plan_length} step(s)), "
        f"replans {result.replans}, messages sent {result.messages}"
    )
    print(
        "carried out: "
        + ", ".join(
            f"{agent} {result.steps.get(agent, 0)} step(s) in {count} task(s)" for agent, count in result.tasks.items()
        )
    )
