"""``alica agent``: one agent of a team in its own process, on the wall clock, over eclipse-zenoh.

This is how a team runs on robots: every robot starts ``alica agent`` with
the same plan file and the same roster (``--agents``), names itself with
``--name`` and says where its teammates are (``--connect``/``--listen``
zenoh endpoints). The engine ticks at ``--frequency`` in real time
(:class:`alica.engine.realtime.RealTimeLoop`); the team is whoever is alive
on the network (zenoh liveliness). ``alica run --processes`` starts one
``alica agent`` per agent on loopback (:mod:`alica.app.processes`).

Skills: any skill that needs no robot; with ``--robot PLUGIN`` (a robot
driver, :mod:`alica.app.robot_plugin`) the skills that act on a robot too; with
``--stand-ins`` scripted stand-ins for the others. A simulated driver (one
whose world has ``step(seconds)``) is moved on by the wall time between two
ticks; a hardware driver runs on its own. With ``--world ENDPOINT`` the robot
is a remote one of a world server (``alica world serve``,
:mod:`alica.app.world_server`): the agent then runs on the server's simulated
time (``--time-limit`` and the times of ``--fact`` are simulated seconds
since the world's start), in lock-step when the server is.

With ``--json`` it prints one JSON object per line on standard output: a
``status`` line whenever its root plan's status changes, and a ``summary``
line when it stops (the agent's part of ``alica run``'s summary plus its
transport's counters and its world model's digest).

Unless ``--no-center-feed``, the agent publishes its trace events for a
control center (``alica center --team ENDPOINT``) on zenoh, answers a late
center's question for its history, and applies the operator's commands (a
goal, facts, a decision on a plan proposed under ``--review``) between two
ticks (:mod:`alica.comm.center_feed`).

With ``--parent-pipe FD`` the agent stops, as on SIGTERM, when that file
descriptor reaches end of file: the process that started it holds the
pipe's other end, so the agent does not outlive it, even after a
``kill -9``. ``alica run --processes`` passes each agent's standard input
and the run's deadline (``--time-limit``).

``--trace FILE`` is checked before the agent starts; its folder must exist.

Exit codes: 0 the root plan succeeded, 1 it failed or is still running when
the agent stops (time limit, Ctrl-C, SIGTERM), 2 wrong usage.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from alica.app.engine_options import add_engine_options, engine_settings
from alica.app.options import add_time_limit, check_output, time_limit
from alica.app.plan_watch import PlanWatch, TeamReloads, add_watch_option
from alica.app.robot_plugin import add_robot_options
from alica.app.ros2_options import add_ros2_options, check_ros2, ros2_output
from alica.app.skill_options import add_skills_option
from alica.app.team_keys import add_team_keys_option, team_settings
from alica.app.timed import timed
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.allocation import AgentSpec
    from alica.app.run_skills import SkillWiring
    from alica.clock import Clock
    from alica.comm.zenoh_transport import ZenohTransport
    from alica.engine import AgentEngine
    from alica.engine.agent import Observer
    from alica.model import PlanLibrary
    from alica.worldmodel import WorldModel
    from alica.worldsim.interface import RobotWorld


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``agent`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "agent",
        help="run one agent of a team in this process, on the wall clock, over zenoh",
        description="Run one agent of a team as one would on a robot: its own engine, ticking in real time, talking "
        "to its teammates over eclipse-zenoh. Start one per robot with the same plan and --agents roster. "
        "Exit 0 when the root plan succeeded, 1 when it failed or had not ended when the agent stopped.",
    )
    p.add_argument("plan", metavar="PLAN", help="a plan file")
    p.add_argument("--name", required=True, help="this agent's name (its id in the team)")
    p.add_argument("--role", help="this agent's role (default: from --agents, or the role called like the agent)")
    p.add_argument(
        "--agents",
        metavar="NAME[:ROLE],...",
        help="the whole team, this agent included, as for alica run (default: this agent alone)",
    )
    p.add_argument("--root", metavar="PLAN", help="the root plan (default: the file's top-level plan)")
    p.add_argument("--roleset", help="the role set (default: the one holding the agents' roles)")
    p.add_argument(
        "--connect",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="a zenoh endpoint to connect to, e.g. tcp/192.168.1.10:7447 (repeatable)",
    )
    p.add_argument(
        "--listen",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="a zenoh endpoint to listen on, e.g. tcp/0.0.0.0:7447 (repeatable)",
    )
    p.add_argument(
        "--mode", choices=("peer", "client"), default="peer", help="zenoh mode (default peer; client: through a router)"
    )
    p.add_argument(
        "--key-prefix",
        default="alica",
        metavar="PREFIX",
        help="the team's zenoh key prefix; teams with different prefixes do not hear each other (default alica)",
    )
    p.add_argument(
        "--zenoh",
        action="append",
        default=[],
        metavar="KEY=JSON",
        help="more zenoh configuration, e.g. scouting/multicast/enabled=true (repeatable)",
    )
    add_team_keys_option(p)
    p.add_argument("--frequency", type=float, default=30.0, metavar="HZ", help="engine ticks per second (default 30)")
    add_watch_option(
        p,
        "the agent proposes a valid one to its team and adopts it at the tick the team agrees on (hot reload: "
        "the team switches only when every live agent has the same plans), an invalid one is reported",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the agent's random choices (default 0)")
    add_ros2_options(p)
    p.add_argument(
        "--start-at",
        type=float,
        metavar="EPOCH",
        help="the team's start, in seconds since the epoch, for the times of --fact and --time-limit (default: now)",
    )
    p.add_argument(
        "--fact",
        action="append",
        default=[],
        metavar="LITERALS@T",
        help="the operator sets facts in this agent's world model T seconds after the start (repeatable)",
    )
    p.add_argument(
        "--goal",
        action="append",
        default=[],
        metavar="PROBLEM=FORMULA",
        help="the operator's goal of a planning problem from the start, e.g. 'GetObjects=at(a, g)' (repeatable)",
    )
    p.add_argument(
        "--object",
        action="append",
        default=[],
        metavar="NAME:TYPE",
        help="the mission's data: an object this agent knows from the start, e.g. g:location (repeatable)",
    )
    p.add_argument(
        "--value",
        action="append",
        default=[],
        metavar="FUNCTION(ARGS)=VALUE",
        help="the mission's data: a value this agent knows from the start, VALUE read as YAML, e.g. "
        "'pos(g)=[0, 0]' (repeatable)",
    )
    add_time_limit(
        p,
        None,
        "stop S wall seconds after the start (default: no limit, run until stopped)",
        old=("--max-time",),
    )
    p.add_argument("--until-done", action="store_true", help="stop one second after the root plan succeeded or failed")
    p.add_argument(
        "--stand-ins",
        action="store_true",
        help="run scripted stand-ins for skills without an implementation and for skills that act on a robot",
    )
    p.add_argument(
        "--parallel-planning",
        action="store_true",
        help="MAGiC: as the leader of a planning problem, split the search over the agents in its state",
    )
    p.add_argument(
        "--review",
        action="store_true",
        help="the operator reviews every plan this agent generates as a planning problem's leader, from a control "
        "center (alica center --team), before the team runs it",
    )
    p.add_argument(
        "--no-center-feed",
        dest="center_feed",
        action="store_false",
        help="do not publish this agent's events for control centers nor take the operator's commands from them "
        "(by default it does: with no center listening it only keeps its last events in memory)",
    )
    add_skills_option(p)
    add_robot_options(p)
    p.add_argument(
        "--world",
        metavar="ENDPOINT",
        help="drive this agent's robot in a world served by alica world serve at this zenoh endpoint, e.g. "
        "tcp/127.0.0.1:7448; the agent then runs on the world's simulated time (in lock-step with the other "
        "agents when the server was started with --lockstep)",
    )
    p.add_argument(
        "--perception",
        choices=("blocks",),
        help="with --world or --robot: blocks writes the blocks-world facts (on, ontable, clear, holding, handempty) "
        "and the blocks' places into this agent's world model every 0.2 s from the world's state; a stand-in for "
        "an overhead camera, as in alica run --world blocks",
    )
    add_engine_options(p)
    p.add_argument("--trace", metavar="FILE", help="write this agent's JSON Lines trace (in an existing folder)")
    p.add_argument(
        "--parent-pipe",
        type=int,
        metavar="FD",
        help="stop when this file descriptor reaches end of file: the read end of a pipe whose other end the "
        "process that started this agent holds, so the agent ends with it (alica run --processes gives 0, "
        "standard input)",
    )
    p.add_argument("--json", action="store_true", help="print status and summary lines as JSON")
    p.set_defaults(run=cmd_agent)


WORLD_TRACE_GAP = 0.1
"""Seconds between two ``world`` trace events (the world model's digest) at most."""


def _zenoh_settings(items: list[str]) -> dict[str, object]:
    settings: dict[str, object] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise AlicaError(f"--zenoh: '{item}' is not KEY=JSON, e.g. scouting/multicast/enabled=true")
        try:
            settings[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            settings[key.strip()] = value  # a bare word: a string
    return settings


def cmd_agent(args: argparse.Namespace) -> int:
    """Run ``alica agent``; returns the exit code."""
    from alica.allocation import AgentSpec
    from alica.app.options import parse_roster
    from alica.app.plan_entry import agent_roles, load_entry, root_plans
    from alica.app.robot_plugin import close_world, robot_plugin
    from alica.app.run_skills import plan_skills, skill_wiring
    from alica.app.skill_options import skill_registry
    from alica.io import Loader

    if args.frequency <= 0:
        raise AlicaError(f"--frequency must be > 0, got {args.frequency}")
    time_limit(args)
    if args.parent_pipe is not None:
        try:
            os.fstat(args.parent_pipe)
        except (OSError, OverflowError):
            raise AlicaError(
                f"--parent-pipe {args.parent_pipe}: no such open file descriptor; give the read end of a pipe the "
                "parent holds open (0: standard input)"
            ) from None
    if args.trace:
        check_output(args.trace, "--trace", make_folders=False)
    check_ros2(args)
    registry = skill_registry(args)
    library, entry = load_entry(args.plan, Loader(skills=registry))
    args.load_plans = lambda: load_entry(args.plan, Loader(skills=registry))[0]  # --watch, the center's reload
    plan = args.root
    if plan is None:
        roots = [r for r in root_plans(library, entry, None) if r in library.plans]
        if not roots:
            raise AlicaError(f"{args.plan} defines no plan to run; give one with --root")
        plan = roots[0]
    agents = parse_roster(args.agents) if args.agents else {args.name: args.role}
    if args.name not in agents:
        raise AlicaError(f"--name {args.name} is not in --agents ({', '.join(agents)}); the roster names every agent")
    if args.role is not None:
        agents[args.name] = args.role
    roles = agent_roles(library, agents, args.roleset, {args.name: "--role"} if args.role is not None else None)
    facts = [timed("--fact", text) for text in args.fact]
    args.knowledge = mission_knowledge(args.object, args.value)
    args.goals = []
    for item in args.goal:
        problem, sep, goal = (part.strip() for part in item.partition("="))
        if not sep or not problem or not goal:
            raise AlicaError(f"--goal: '{item}' is not PROBLEM=FORMULA, e.g. 'GetObjects=at(a, g)'")
        if problem not in library.problems:
            known = ", ".join(sorted(library.problems)) or "none"
            raise AlicaError(f"--goal: no planning problem named '{problem}' in {args.plan}; problems: {known}")
        args.goals.append((problem, goal))
    plugin = robot_plugin(args, agents)
    if plugin is not None and args.world is not None:
        raise AlicaError("--robot and --world both give the agent its robot: choose one")
    if args.perception is not None and plugin is None and args.world is None:
        raise AlicaError(f"--perception {args.perception} reads the robot's world: give --world or --robot too")
    wiring = skill_wiring(
        registry,
        plan_skills(library, plan),
        world=plugin is not None or args.world is not None,
        stand_ins=args.stand_ins,
        plan=plan,
        robots="pass --world ENDPOINT (a world server: alica world serve) or --robot PLUGIN (a robot driver)",
    )
    members = agents if args.agents else None
    endpoints = [*args.connect, *args.listen]
    settings = {
        **team_settings(args, f"alica agent {args.name}", args.name, members, endpoints, args.key_prefix),
        **_zenoh_settings(args.zenoh),
    }
    if args.world is not None:
        return _run_in_served_world(args, library, plan, roles, wiring, facts, settings)
    if plugin is None:
        return _run(args, library, plan, roles, wiring, facts, settings)
    mine = roles[args.name]
    world = plugin.make(args.name, (mine.role if isinstance(mine, AgentSpec) else mine) or "")
    try:
        return _run(args, library, plan, roles, wiring, facts, settings, world)
    finally:
        close_world(world)


def _run_in_served_world(
    args: argparse.Namespace,
    library: PlanLibrary,
    plan: str,
    roles: dict[str, str | AgentSpec],
    wiring: SkillWiring,
    facts: list[tuple[str, float, float | None]],
    settings: dict[str, object],
) -> int:
    """``alica agent --world EP``: the agent's robot is a remote one of a world server; the agent runs on its time."""
    from alica.app.world_server import RemoteWorld
    from alica.worldsim.errors import WorldError

    world_zenoh = None
    if args.keys is not None:  # the world's own access control: this agent reaches only its robot
        from alica.app.world_server.access import world_settings

        world_zenoh = world_settings(args.keys, args.key_prefix)
    try:
        world = RemoteWorld([args.world], args.name, prefix=args.key_prefix, settings=world_zenoh)
    except (WorldError, ValueError) as exc:
        raise AlicaError(f"alica agent {args.name} --world {args.world}: {exc}") from None
    try:
        return _run(args, library, plan, roles, wiring, facts, settings, world)
    finally:
        world.close()


def _run(
    args: argparse.Namespace,
    library: PlanLibrary,
    plan: str,
    roles: dict[str, str | AgentSpec],
    wiring: SkillWiring,
    facts: list[tuple[str, float, float | None]],
    settings: dict[str, object],
    robot_world: RobotWorld | None = None,
) -> int:
    from alica.allocation import AgentSpec, assign_roles
    from alica.app.robot_plugin import is_simulated, wall_seconds
    from alica.app.trace_sources import plan_path_names
    from alica.clock import SystemClock
    from alica.comm.zenoh_transport import ZenohTransport
    from alica.engine import AgentEngine, JsonlTrace, SkillBinder, pick_roleset, trace_header
    from alica.engine.realtime import RealTimeLoop
    from alica.engine.runner import describe_agent, root_status
    from alica.lang import literals
    from alica.prophet import engine_config
    from alica.testing import default_fallback
    from alica.worldmodel import WorldModel

    # a served world's robot lives in the server's simulated time: the agent runs on it (from its time 0)
    served: Any = robot_world if callable(getattr(robot_world, "tick_done", None)) else None
    clock: Clock = _LastKnownTime(served.clock) if served is not None else SystemClock()
    if served is not None:
        start = 0.0
    else:
        start = args.start_at if args.start_at is not None else clock.now()
    specs = {n: r if isinstance(r, AgentSpec) else AgentSpec(role=r) for n, r in sorted(roles.items())}
    roleset = pick_roleset(library, (s.role for s in specs.values()), args.roleset)
    roster = assign_roles(specs, roleset)
    config = engine_config(
        frequency=args.frequency,
        planner_seconds=0.3 / args.frequency,
        parallel_planning=args.parallel_planning,
        review=args.review,
        **engine_settings(args),
    )
    header = trace_header(
        plans=[args.plan],
        root=plan,
        agents=roster,
        seed=args.seed,
        frequency=args.frequency,
        recorder=args.name,  # this trace holds one agent's events
        clock="wall",
        skills=args.skills,
        plan_path=plan_path_names(),
    )
    trace = JsonlTrace(args.trace, header=header, line_buffered=True) if args.trace else None  # kept up to a kill -9
    sinks: list[Observer] = [trace] if trace is not None else []

    def observe(event: dict[str, Any]) -> None:
        record = _since_start(event, start)
        for sink in sinks:
            sink(record)

    stop = threading.Event()
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGTERM, signal.SIGINT)}
    orphaned = threading.Event()
    if args.parent_pipe is not None:
        _watch_parent(args.parent_pipe, stop, orphaned)
    pending = sorted(((at, literals(what)) for what, at, _ in facts), key=lambda item: item[0])
    try:
        transport = ZenohTransport(
            args.name,
            connect=args.connect,
            listen=args.listen,
            team=args.key_prefix,
            mode=args.mode,
            clock=clock,
            config=settings,
            roster=list(roster) if args.agents else None,
            on_name_taken=lambda _why: stop.set(),  # the reason stays in transport.name_taken
        )
    except ValueError as exc:
        raise AlicaError(f"alica agent {args.name}: {exc}") from None
    feed = None
    if args.center_feed:
        from alica.comm.center_feed import CenterFeed

        try:
            feed = CenterFeed(transport, header, start, keys=args.keys)
        except BaseException:
            transport.close()
            raise
        sinks.append(feed)
    fallback = default_fallback(args.seed, registry=wiring.registry) if args.stand_ins else None
    closing = contextlib.ExitStack()
    try:
        # --ros2, --record: stamped with the clock's time (the wall clock's epoch seconds; a served world's seconds)
        ros2 = closing.enter_context(ros2_output(args))
        world_model = WorldModel(args.name, clock=clock, relay=False)
        engine = AgentEngine(
            args.name,
            roster,
            library,
            plan,
            roleset,
            transport,
            world_model,
            clock,
            config=config,
            skills=SkillBinder(None, wiring.registry, fallback),
            seed=args.seed,
            observers=(observe,) if sinks else (),
            world=robot_world,
            listen_first=2 * config.broadcast_interval,
        )
        stepped: Any = getattr(robot_world, "step") if robot_world is not None and is_simulated(robot_world) else None  # noqa: B009
        last_step = [time.monotonic()]
        status = ["running"]

        perceive = _perception(args.perception, engine, robot_world)
        reloads = TeamReloads(
            PlanWatch(args.plan, library, args.load_plans),
            engine,
            [lambda event: engine.emit("reload", status="invalid", errors=event["errors"])],
        )
        engine.observers.append(_reload_output(args.json, start))

        def operator(now: float) -> None:
            if perceive is not None:
                perceive()
            if args.watch:
                reloads.look()
            while pending and now >= start + pending[0][0]:
                _, literals_now = pending.pop(0)
                for positive, pred, fact_args in literals_now:
                    (engine.world_model.assert_fact if positive else engine.world_model.retract_fact)(pred, *fact_args)
            if feed is not None:
                for command in feed.commands():
                    apply_command(engine, command, reloads.reload)

        for problem, goal in args.goals:
            engine.set_problem(problem, goal=goal)
        objects, values = args.knowledge
        for obj, type_name in objects:
            engine.world_model.add_object(obj, type_name)
        for function, function_args, value in values:
            engine.world_model.set(function, *function_args, value=value)
        world = _WorldTrace()
        engine.world_model.on_change(world.touch)

        lockstep = served is not None and bool(served.lockstep)
        world_down = [False]

        share = _pose_sharing(engine, robot_world, args.name)
        own_robot = robot_world.robots.get(args.name) if robot_world is not None else None
        publish = ros2.attach_agent(engine, own_robot, library) if ros2 is not None else None

        def report(now: float) -> None:
            if share is not None:
                share()
            if publish is not None:
                publish(now)
            if lockstep:
                _lockstep_tick(served, args.name, world_down, stop)
            if stepped is not None:
                stepped(wall_seconds(last_step))  # a simulated robot moves on as the wall clock did
            if trace is not None and world.changed and now - world.at >= WORLD_TRACE_GAP:
                # the world model's fingerprint in the trace: when two agents' agree, their states are equal
                world.changed, world.at = False, now
                digest = _digest(world_model)
                if digest != world.digest:
                    world.digest = digest
                    engine.emit("world", digest=digest, facts=len(engine.world_model.facts()))
            current = root_status(engine)
            if current != status[0]:
                status[0] = current
                if args.json:
                    _line({"event": "status", "agent": args.name, "status": current, "t": round(now - start, 3)})

        if args.json:
            _line({"event": "started", "agent": args.name, "t": round(clock.now() - start, 3)})
        # in lock-step the server's step is the wait: no sleeping between ticks
        loop = RealTimeLoop(engine, stop, sleep=_no_sleep) if lockstep else RealTimeLoop(engine, stop)
        began, began_cpu = time.monotonic(), sum(os.times()[:2])
        why = loop.run(
            until_done=args.until_done,
            end_at=None if args.time_limit is None else start + args.time_limit,
            before_tick=operator,
            after_tick=report,
        )
        if orphaned.is_set():
            why = "parent gone"
            print(f"alica agent {args.name}: the process that started it is gone; stopping", file=sys.stderr)
        if transport.name_taken is not None:
            why = "name taken"
            print(f"alica agent {args.name}: {transport.name_taken}; stopping", file=sys.stderr)
        summary = describe_agent(engine, root_status(engine))
        summary.update(
            name=args.name,
            ended=why,
            overruns=loop.overruns,
            time_s=round(clock.now() - start, 3),
            cpu_s=round(sum(os.times()[:2]), 3),  # this process's user and system time (zenoh's threads too)
            # of one core, while ticking (start-up left out)
            cpu_percent=round(100 * (sum(os.times()[:2]) - began_cpu) / max(1e-9, time.monotonic() - began), 2),
            transport=_counters(transport),
            world_digest=_digest(world_model),
            world_facts=[str(fact) for fact in engine.world_model.facts()],
        )
    finally:
        closing.close()
        if feed is not None:
            feed.close()
        transport.close()
        for what, count in sorted(transport.errors.items()):
            print(f"alica agent {args.name}: {count} message(s) could not be decoded, from {what}", file=sys.stderr)
        if trace is not None:
            trace.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if args.json:
        _line({"event": "summary", **summary})
    else:
        print(
            f"{args.name} ({summary['role']}): {summary['status']} after {summary['time_s']:.2f} s ({why}); "
            f"{summary['ticks']} ticks, {summary['messages_out']} sent, {summary['messages_in']} received; "
            f"at {summary['path'] or '-'}"
        )
    if transport.name_taken is not None:
        return 2
    return 0 if summary["status"] == "success" else 1


_CALL = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)\s*=(.*)$", re.DOTALL)
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")


def mission_knowledge(
    objects: list[str], values: list[str]
) -> tuple[list[tuple[str, str]], list[tuple[str, tuple[str, ...], object]]]:
    """``--object NAME:TYPE`` and ``--value FUNCTION(ARGS)=VALUE`` as ``(objects, values)``.

    Raises:
        AlicaError: an item of the wrong form (the message shows the right one).
    """
    import yaml  # lazy: every alica command builds this parser

    known: list[tuple[str, str]] = []
    for item in objects:
        name, sep, type_name = item.partition(":")
        if not sep or not _NAME.match(name.strip()) or not _NAME.match(type_name.strip()):
            raise AlicaError(f"--object: '{item}' is not NAME:TYPE, e.g. g:location")
        known.append((name.strip(), type_name.strip()))
    set_values: list[tuple[str, tuple[str, ...], object]] = []
    for item in values:
        match = _CALL.match(item)
        names = [a.strip() for a in match.group(2).split(",")] if match and match.group(2).strip() else []
        if match is None or not all(_NAME.match(a) for a in names):
            raise AlicaError(f"--value: '{item}' is not FUNCTION(ARGS)=VALUE, e.g. 'pos(g)=[0, 0]'")
        try:
            value = yaml.safe_load(match.group(3))
        except yaml.YAMLError:
            raise AlicaError(f"--value: '{item}': '{match.group(3).strip()}' is not a YAML value") from None
        if value is None or isinstance(value, dict):
            raise AlicaError(f"--value: '{item}' gives no value; write a number, a name or a list, e.g. [0, 0]")
        set_values.append((match.group(1), tuple(names), tuple(value) if isinstance(value, list) else value))
    return known, set_values


def _pose_sharing(engine: AgentEngine, world: RobotWorld | None, name: str) -> Callable[[], None] | None:
    """After each tick the agent shares its robot's pose estimate with the team (throttled), as robots do."""
    if world is None or name not in world.robots:
        return None
    from alica.skills.team_poses import share_pose
    from alica.worldsim.errors import WorldError

    robot = world.robots[name]

    def share() -> None:
        try:
            share_pose(engine.world_model, world, robot)
        except WorldError:
            pass  # a served robot that does not answer: nothing to share now

    return share


def _perception(kind: str | None, engine: AgentEngine, world: RobotWorld | None) -> Callable[[], None] | None:
    """``--perception``: a hook writing what the world shows into this agent's world model before each tick."""
    if kind is None or world is None:
        return None
    from alica.worldsim.scenarios import blocks_perception

    hook = blocks_perception()

    class _Alone:  # the one agent of this process, as the perception hook reads a team
        def __init__(self) -> None:
            self.world = world

        def now(self) -> float:
            return engine.now()

        def running(self) -> list[AgentEngine]:
            return [engine]

    alone: Any = _Alone()  # (typed for the simulator's World; it reads only the robot interface of it)
    return lambda: hook(alone)


class _LastKnownTime:
    """A served world's time that never raises and never goes back.

    While the server does not answer it is the time the server last had: time stands still for the agent
    (its skills fail, each with the reason) until a server steps again. A new server starts from its own
    time 0; the agent's time goes on from where it stood.
    """

    def __init__(self, clock: Clock) -> None:
        self._clock = clock
        self._last = 0.0
        self._offset = 0.0

    def now(self) -> float:
        from alica.worldsim.errors import WorldError

        try:
            value = self._clock.now() + self._offset
        except WorldError:
            return self._last  # the server is gone: its time stands still for this agent
        if value < self._last:  # a new server started again from its time 0: time goes on from here
            self._offset += self._last - value
            value = self._last
        self._last = value
        return value


def _no_sleep(_seconds: float) -> None:
    """The lock-step loop's wait: none (the world server's step paced the tick)."""


def _lockstep_tick(world: Any, name: str, down: list[bool], stop: threading.Event) -> None:
    """Tell the lock-step world server this tick is done and wait for its step.

    A server that does not answer is reported once (``down``); the agent then ticks on at most once a
    second, asking again each time, until the server steps again (or the agent is stopped).
    """
    from alica.worldsim.errors import WorldError

    try:
        world.tick_done(timeout=1.0 if down[0] else None)
    except WorldError as exc:
        if not down[0]:
            print(f"alica agent {name}: {exc}; waiting for the world server", file=sys.stderr)
        down[0] = True
        stop.wait(0.2)
    else:
        if down[0]:
            print(f"alica agent {name}: the world server steps again", file=sys.stderr)
        down[0] = False


def apply_command(
    engine: AgentEngine, command: dict[str, Any], reload: Callable[[], dict[str, Any]] | None = None
) -> None:
    """Apply one operator's command from a control center (:class:`alica.comm.center_feed.CenterFeed`) to ``engine``.

    The same checks as in a simulated team (:class:`alica.engine.runner.SimulatedTeam`): a goal or a
    decision for a planning problem the plan file does not have, or a malformed command, changes
    nothing; the agent says why in a ``note`` event. A command applied goes into the agent's trace as an
    ``operator`` event with ``applied: true`` (so a process team's merged trace holds the operator's actions).

    Commands: ``{"what": "goal", "problem", "goal"}``; ``{"what": "facts", "facts": [[positive, predicate,
    [args]], ...]}``; ``{"what": "decision", "problem", "generation", "action", "order", "pins"}``;
    ``{"what": "reload"}`` (the agent loads its plan files again with ``reload`` and proposes them to its team).
    """
    from alica.engine import PlanDecision
    from alica.lang import literal_text

    what = command.get("what")
    try:
        if what == "goal":
            problem, goal = command.get("problem"), command.get("goal")
            if not isinstance(problem, str) or not isinstance(goal, str):
                raise ValueError("a goal names its problem and its goal as text")
            engine.set_problem(problem, goal=goal)
            engine.emit("operator", what="goal", problem=problem, goal=goal, applied=True)
        elif what == "facts":
            facts = command.get("facts")
            if not isinstance(facts, list):
                raise ValueError("facts come as a list of [positive, predicate, [args]]")
            checked = []
            for fact in facts:
                if (
                    not isinstance(fact, list)
                    or len(fact) != 3
                    or not isinstance(fact[1], str)
                    or not isinstance(fact[2], list)
                ):
                    raise ValueError(f"a fact is [positive, predicate, [args]], not {fact!r}")
                checked.append((bool(fact[0]), fact[1], tuple(fact[2])))
            for positive, pred, fact_args in checked:
                (engine.world_model.assert_fact if positive else engine.world_model.retract_fact)(pred, *fact_args)
            texts = [literal_text(p, n, a) for p, n, a in checked]
            engine.emit("operator", what="facts", facts=texts, applied=True)
        elif what == "decision":
            problem, generation = command.get("problem"), command.get("generation")
            if not isinstance(problem, str) or not isinstance(generation, int) or isinstance(generation, bool):
                raise ValueError("a decision names its problem and the generation it answers")
            order = command.get("order")
            decision = PlanDecision(
                command.get("action"),  # type: ignore[arg-type]  # checked by PlanDecision
                tuple(order) if isinstance(order, list) else None,
                command.get("pins") or {},
            )
            engine.decide_plan(problem, generation, decision)
            described = decision.describe()
            what_done = described.pop("action")
            engine.emit("operator", what=what_done, problem=problem, generation=generation, applied=True, **described)
        elif what == "reload":
            if reload is None:
                raise ValueError("this agent cannot load its plan files again")
            outcome = reload()
            engine.emit("operator", what="reload", applied=bool(outcome.get("ok")), **outcome)
        else:
            raise ValueError(f"no such operator's command: {what!r}")
    except (AlicaError, ValueError, TypeError) as exc:
        engine.emit("note", message=f"the operator's command {what!r} is refused: {exc}")


def _watch_parent(fd: int, stop: threading.Event, orphaned: threading.Event) -> None:
    """Set ``orphaned`` and ``stop`` once ``fd`` reaches end of file (the parent is gone), from a daemon thread.

    The thread blocks in ``os.read`` (no lock, no polling), so the ticks do not pay for it.
    """

    def watch() -> None:
        try:
            while os.read(fd, 4096):
                pass  # the parent writes nothing; anything it does write is ignored
        except OSError:
            pass  # a closed or broken descriptor: the parent is gone as well
        orphaned.set()
        stop.set()

    threading.Thread(target=watch, name="parent-pipe", daemon=True).start()


class _WorldTrace:
    """When the world model changed and its last digest in the trace."""

    def __init__(self) -> None:
        self.changed = True
        self.at = float("-inf")
        self.digest = ""

    def touch(self, _keys: object) -> None:
        self.changed = True


def _counters(transport: ZenohTransport) -> dict[str, int]:
    stats = transport.stats
    return {name: getattr(stats, name) for name in stats.__slots__}


def _digest(world_model: WorldModel) -> str:
    """A short fingerprint of the world model's state: equal on two agents when their states are equal."""
    import hashlib

    return hashlib.blake2b(world_model.dumps().encode("utf-8"), digest_size=8).hexdigest()


def _since_start(event: dict[str, Any], start: float) -> dict[str, Any]:
    """A trace event with its times in seconds since the start (``t``, and a reload's ``at``)."""
    record = {**event, "t": round(event["t"] - start, 6)}
    if isinstance(event.get("at"), float) and event.get("event") == "reload":
        record["at"] = round(event["at"] - start, 6)
    return record


def _reload_output(as_json: bool, start: float) -> Callable[[dict[str, Any]], None]:
    """An observer that shows the agent's reload events: JSON lines with ``--json``, else lines on standard error."""
    from alica.app.plan_watch import reload_line

    def show(event: dict[str, Any]) -> None:
        if event.get("event") != "reload":
            return
        record = _since_start(event, start)
        if as_json:
            _line(record)
            return
        line = reload_line(record)
        if line is not None:
            print(f"{record['t']:8.2f} s  {line}", file=sys.stderr, flush=True)

    return show


def _line(record: dict[str, Any]) -> None:
    sys.stdout.write(json.dumps(record, sort_keys=True, default=str) + "\n")
    sys.stdout.flush()
