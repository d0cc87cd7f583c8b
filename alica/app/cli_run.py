"""``alica run``: a team runs a plan in simulation, with faults, a trace and a summary."""

from __future__ import annotations

import argparse
import json
import re
import sys
from typing import Any

from alica.errors import AlicaError

_AT = re.compile(r"^(?P<what>.+)@(?P<start>[0-9.]+)(?:-(?P<end>[0-9.]+))?$")


def add_parser(sub: Any) -> None:
    """Add the ``run`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "run",
        help="run a team on a plan in simulated time",
        description="Run a team of agents on a plan in simulated time over a simulated network. "
        "Team runs have no simulated world yet, so every skill is a scripted stand-in (Idle waits; others succeed "
        "after a while and write their post-condition). Exit 0 when the run ends well, 1 when the plan failed or the time ran out.",
    )
    p.add_argument("plan", metavar="PLAN", help="a plan file")
    p.add_argument(
        "--agents",
        required=True,
        metavar="NAME:ROLE,...",
        help="the team, e.g. scout:Scout,stummel:Stummel; NAME alone takes the role of that name; NAME:+cap1+cap2 derives the role from capabilities",
    )
    p.add_argument("--name", help="the root plan (default: the file's top-level plan)")
    p.add_argument("--roleset", help="the role set (default: the one holding the agents' roles)")
    p.add_argument("--seed", type=int, default=0, help="seed of the network and the agents (default 0)")
    length = p.add_mutually_exclusive_group()
    length.add_argument("--ticks", type=int, metavar="N", help="run N engine ticks")
    length.add_argument(
        "--until-done", action="store_true", help="run until every agent's root plan ended (the default)"
    )
    p.add_argument(
        "--max-time",
        type=float,
        default=300.0,
        metavar="S",
        help="simulated seconds at most with --until-done (default 300)",
    )
    p.add_argument("--frequency", type=float, default=30.0, metavar="HZ", help="engine ticks per second (default 30)")
    p.add_argument(
        "--loss",
        type=float,
        default=0.0,
        metavar="P",
        help="probability that a best-effort message is lost (default 0)",
    )
    p.add_argument("--delay", type=float, default=0.0, metavar="MS", help="message delay in milliseconds (default 0)")
    p.add_argument(
        "--jitter", type=float, default=0.0, metavar="MS", help="random extra delay up to this many milliseconds"
    )
    p.add_argument(
        "--crash",
        action="append",
        default=[],
        metavar="NAME@T",
        help="crash agent NAME at simulated second T (repeatable)",
    )
    p.add_argument(
        "--recover", action="append", default=[], metavar="NAME@T", help="restart agent NAME at second T (repeatable)"
    )
    p.add_argument(
        "--partition",
        action="append",
        default=[],
        metavar="A,B|C@T1-T2",
        help="cut the network between groups from T1 to T2, or for good without -T2 (repeatable)",
    )
    p.add_argument(
        "--fact",
        action="append",
        default=[],
        metavar="LITERALS@T",
        help="the operator sets facts at second T, e.g. 'found(a) and not stop@5' (repeatable)",
    )
    p.add_argument(
        "--trace",
        metavar="FILE",
        help="write a JSON Lines trace of allocations, transitions, repairs, messages and faults",
    )
    p.add_argument("--trace-messages", action="store_true", help="trace every message too (large)")
    p.add_argument("--show-tree", action="store_true", help="print each agent's running plan tree whenever it changes")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=cmd_run)


def _agents(text: str) -> dict[str, str | frozenset[str] | None]:
    agents: dict[str, str | frozenset[str] | None] = {}
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        name, _, role = part.partition(":")
        name, role = name.strip(), role.strip()
        if not name or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_\-]*", name):
            raise AlicaError(f"--agents: '{part}' is not NAME or NAME:ROLE (names are letters, digits, '_' and '-')")
        if name in agents:
            raise AlicaError(f"--agents: agent '{name}' is given twice")
        if role.startswith("+"):
            caps = frozenset(c.strip() for c in role.split("+") if c.strip())
            if not caps:
                raise AlicaError(f"--agents: '{part}' names no capabilities; write NAME:+cap1+cap2")
            agents[name] = caps
        else:
            agents[name] = role or None
    if not agents:
        raise AlicaError("--agents: give at least one agent, e.g. --agents scout:Scout")
    return agents


def _timed(option: str, text: str, span: bool = False) -> tuple[str, float, float | None]:
    match = _AT.match(text.strip())
    if match is None or (match.group("end") is not None and not span):
        form = "WHAT@T1-T2" if span else "WHAT@T"
        raise AlicaError(f"{option}: '{text}' is not of the form {form} (T in simulated seconds)")
    end = float(match.group("end")) if match.group("end") else None
    return match.group("what").strip(), float(match.group("start")), end


def _roles(library: Any, agents: dict[str, str | frozenset[str] | None], roleset: str | None) -> dict[str, Any]:
    from alica.allocation import AgentSpec
    from alica.engine import pick_roleset

    names = {r.name.lower(): r.name for rs in library.rolesets.values() for r in rs.roles}
    out: dict[str, Any] = {}
    for name, role in agents.items():
        if isinstance(role, frozenset):
            out[name] = AgentSpec(capabilities=role)
            continue
        if role is None:
            if name.lower() not in names:
                raise AlicaError(
                    f"--agents: agent '{name}' has no role and no role is called like it; write {name}:ROLE (roles: {', '.join(sorted(set(names.values())))})"
                )
            role = names[name.lower()]
        out[name] = role
    pick_roleset(library, [r for r in out.values() if isinstance(r, str)], roleset)
    return out


def cmd_run(args: argparse.Namespace) -> int:
    """Run the ``run`` subcommand; returns the exit code."""
    from alica.app.cli import _load, _roots
    from alica.engine import JsonlTrace, SimulatedTeam, running_tree
    from alica.lang import literals
    from alica.prophet import engine_config
    from alica.testing import default_fallback

    if not 0 <= args.loss < 1:
        raise AlicaError(f"--loss must lie in [0, 1), got {args.loss}")
    if args.delay < 0 or args.jitter < 0 or args.frequency <= 0:
        raise AlicaError("--delay and --jitter must be >= 0 and --frequency > 0")
    if args.ticks is not None and args.ticks < 0:
        raise AlicaError(f"--ticks must be >= 0, got {args.ticks}")
    library, entry = _load(args.plan)
    if args.name is None:
        roots = [r for r in _roots(library, entry, None) if r in library.plans]
        if not roots:
            raise AlicaError(f"{args.plan} defines no plan to run; give one with --name")
        plan = roots[0]
    else:
        plan = args.name
    roles = _roles(library, _agents(args.agents), args.roleset)
    observers: list[Any] = []
    trace = JsonlTrace(args.trace) if args.trace else None
    if trace is not None:
        observers.append(trace)
    changed: set[str] = set()
    if args.show_tree:
        observers.append(
            lambda e: changed.add(e["agent"]) if e["event"] in ("transition", "allocation", "repair") else None
        )
    team = SimulatedTeam(
        library,
        plan,
        roles,
        seed=args.seed,
        config=engine_config(frequency=args.frequency),  # planning problems run with pRoPhEt MAS
        roleset=args.roleset,
        loss=args.loss,
        delay=args.delay / 1000.0,
        jitter=args.jitter / 1000.0,
        fallback=default_fallback(args.seed),
        observers=observers,
        trace_messages=args.trace_messages,
    )
    for text in args.crash:
        who, at, _ = _timed("--crash", text)
        team.crash(who, at=at)
    for text in args.recover:
        who, at, _ = _timed("--recover", text)
        team.recover(who, at=at)
    for text in args.partition:
        what, start, end = _timed("--partition", text, span=True)
        team.partition([g.split(",") for g in what.split("|")], start=start, end=end)
    for text in args.fact:
        what, at, _ = _timed("--fact", text)
        team.set_facts(literals(what), at=at)
    try:
        if args.show_tree:
            _run_showing(team, args, changed, running_tree)
        elif args.ticks is not None:
            team.run(ticks=args.ticks)
        else:
            team.run(until_done=True, max_time=args.max_time)
    finally:
        if trace is not None:
            trace.close()
    summary = team.summary()
    if args.json:
        print(json.dumps(summary, indent=2, sort_keys=True))
    else:
        _print_summary(summary, args.trace)
    failed = any(a["status"] == "failure" for a in summary["agents"].values())
    if args.ticks is not None:
        return 1 if failed else 0
    return 0 if summary["success"] else 1


def _run_showing(team: Any, args: argparse.Namespace, changed: set[str], running_tree: Any) -> None:
    ticks = 0
    while True:
        if args.ticks is not None and ticks >= args.ticks:
            break
        if args.ticks is None and (team.done() or team.now() >= args.max_time):
            break
        team.tick()
        ticks += 1
        for name in sorted(changed):
            if name not in team.crashed:
                print(f"--- t={team.now():.2f} s")
                print(running_tree(team.engines[name]))
        changed.clear()


def _print_summary(summary: dict[str, Any], trace: str | None) -> None:
    verdict = "success" if summary["success"] else ("ended" if summary["done"] else "not finished")
    print(
        f"{summary['plan']}: {verdict} after {summary['sim_time_s']:.2f} s simulated ({summary['ticks']} ticks), seed {summary['seed']}"
    )
    header = f"{'agent':<12} {'role':<12} {'status':<8} {'transitions':>11} {'allocations':>11} {'sent':>6} {'recv':>6} {'repairs':>7}  where"
    print(header)
    for name, a in summary["agents"].items():
        print(
            f"{name:<12} {a['role']:<12} {a['status']:<8} {a['transitions']:>11} {a['allocations']:>11} {a['messages_out']:>6} {a['messages_in']:>6} {a['repairs']:>7}  {a['path']}"
        )
    m = summary["messages"]
    print(f"messages: {m['sent']} sent, {m['delivered']} delivered, {m['dropped']} dropped")
    if summary["faults"]:
        print("faults: " + "; ".join(summary["faults"]))
    if trace:
        print(f"trace: {trace}")
    sys.stdout.flush()
