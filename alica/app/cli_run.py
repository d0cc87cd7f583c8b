"""``alica run``: a team runs a plan in simulation, with faults, a trace and a summary.

Every skill with an implementation runs for real; ``--world blocks|lunar``
gives the team a pybullet world with one robot named after each agent.
Scripted stand-ins (:func:`alica.testing.default_fallback`) run only with
``--stand-ins``, for the skills that have no implementation or that act on a
robot when the run has no world.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
from typing import TYPE_CHECKING, Any

from alica.app.center.cli import add_live_options, live_session
from alica.app.engine_options import add_engine_options, engine_arguments, engine_settings
from alica.app.options import add_time_limit, check_output, parse_roster, time_limit
from alica.app.plan_watch import add_watch_option
from alica.app.robot_plugin import add_robot_options
from alica.app.ros2_options import add_ros2_options, check_ros2, ros2_arguments, ros2_output
from alica.app.skill_options import add_lunar_options, add_skills_option
from alica.app.team_keys import add_team_keys_option
from alica.app.timed import add_fault_options, add_network_options, partition
from alica.app.timed import timed as _timed
from alica.errors import AlicaError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    import uvicorn

    from alica.allocation import AgentSpec
    from alica.app.center.live import LiveHub, LiveSession
    from alica.app.center.team_feed import CommandLoop
    from alica.app.plan_watch import PlanWatch
    from alica.app.processes import Fault, ProcessTeam
    from alica.app.robot_plugin import PluggedRobots, RobotPlugin
    from alica.app.run_skills import SkillWiring
    from alica.comm.credentials import TeamKeys
    from alica.engine import AgentEngine, SimulatedTeam
    from alica.engine.agent import Observer
    from alica.lang.skills import SkillRegistry
    from alica.model import PlanLibrary
    from alica.worldsim.world import World


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``run`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "run",
        help="run a team on a plan in simulated time",
        description="Run a team of agents on a plan in simulated time over a simulated network. "
        "Every skill with an implementation runs for real; --world gives the team a pybullet world. "
        "With --stand-ins, skills without an implementation (or, without --world, those that act on a robot) "
        "are scripted stand-ins: they run for their duration parameter (Idle until its state is left when it is 0), "
        "others succeed after a while and write their post-condition. "
        "Exit 0 when the root plan succeeded (for every agent that has not crashed); 1 when it failed, when it did not "
        "finish within the limit (--ticks N or --time-limit S: both are limits), or on wrong input. "
        "The summary gives each agent's last failure or allocation problem when the run does not succeed.",
    )
    p.add_argument("plan", metavar="PLAN", help="a plan file")
    p.add_argument(
        "--agents",
        required=True,
        metavar="NAME[:ROLE],...",
        help="the team (required), e.g. scout:Scout,stummel:Stummel; NAME alone takes the role of that name; "
        "NAME:+cap1+cap2 derives the role from capabilities",
    )
    p.add_argument("--name", help="the root plan (default: the file's top-level plan)")
    p.add_argument("--roleset", help="the role set (default: the one holding the agents' roles)")
    p.add_argument("--seed", type=int, default=0, help="seed of the network and the agents (default 0)")
    length = p.add_mutually_exclusive_group()
    length.add_argument(
        "--ticks", type=int, metavar="N", help="run N engine ticks at most (unfinished after N ticks exits 1)"
    )
    length.add_argument(
        "--until-done",
        action="store_true",
        help="run until every agent's root plan ended, up to --time-limit (the default)",
    )
    add_time_limit(
        p,
        300.0,
        "give up after S simulated seconds with --until-done (default 300; wall seconds with --processes)",
        old=("--max-time",),
    )
    p.add_argument("--frequency", type=float, default=30.0, metavar="HZ", help="engine ticks per second (default 30)")
    add_network_options(p)
    p.add_argument(
        "--jitter", type=float, default=0.0, metavar="MS", help="random extra delay up to this many milliseconds"
    )
    add_fault_options(
        p,
        crash="crash agent NAME at simulated second T (repeatable)",
        recover="restart agent NAME at second T (repeatable)",
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
    p.add_argument(
        "--pose-rate",
        type=float,
        default=2.0,
        metavar="HZ",
        help="with --world and --trace: robot poses per simulated second in the trace (default 2)",
    )
    add_live_options(p, review=True)
    p.add_argument("--show-tree", action="store_true", help="print each agent's running plan tree whenever it changes")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument(
        "--world",
        choices=("blocks", "lunar"),
        help="run the skills in a pybullet world: blocks (one manipulator per agent, named after it) "
        "or lunar (the robots scout, stummel and amparo; name the agents after them)",
    )
    p.add_argument("--stacks", default="a,b;c", help="blocks world stacks, bottom first (default 'a,b;c')")
    add_lunar_options(p)
    add_robot_options(p)
    p.add_argument(
        "--stand-ins",
        action="store_true",
        help="run scripted stand-ins for skills that have no implementation (and, without --world, for skills "
        "that act on a robot) instead of stopping with an error",
    )
    add_skills_option(p)
    add_engine_options(p)
    p.add_argument(
        "--parallel-planning",
        action="store_true",
        help="MAGiC: the leader of a planning problem splits its search over the agents in the problem's state",
    )
    p.add_argument(
        "--processes",
        action="store_true",
        help="run every agent in its own process (alica agent) over zenoh on loopback, on the wall clock; "
        "--crash is then a kill -9, --recover a restart, --partition cuts the links between groups; "
        "times are wall seconds; with --center this process serves the team's live page",
    )
    add_watch_option(
        p,
        "the team adopts a valid one at one tick and goes on where it is (hot reload), an invalid one is reported "
        "and the team goes on unchanged; a simulated run then goes at --speed times the wall clock (default 1)",
    )
    add_team_keys_option(p, insecure=False)
    add_ros2_options(p)
    p.set_defaults(run=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    """Run the ``run`` subcommand; returns the exit code."""
    from alica.app.plan_entry import agent_roles, load_entry, root_plans
    from alica.app.robot_plugin import robot_plugin
    from alica.app.run_skills import plan_skills, run_world, skill_wiring
    from alica.app.skill_options import skill_registry
    from alica.io import Loader

    if not 0 <= args.loss < 1:
        raise AlicaError(f"--loss must lie in [0, 1), got {args.loss}")
    if args.delay < 0 or args.jitter < 0 or args.frequency <= 0:
        raise AlicaError("--delay and --jitter must be >= 0 and --frequency > 0")
    if args.ticks is not None and args.ticks < 0:
        raise AlicaError(f"--ticks must be >= 0, got {args.ticks}")
    time_limit(args)
    if args.watch and not (args.speed > 0 and not math.isnan(args.speed)):
        raise AlicaError(f"--speed must be a positive number of simulated seconds per wall second, got {args.speed}")
    if args.trace:
        check_output(args.trace, "--trace", make_folders=True)  # before any agent starts, not after the run
    check_ros2(args)
    session = live_session(args)
    if args.center and args.show_tree:
        raise AlicaError("--center shows the team in a web page; it does not go with --show-tree")
    registry = skill_registry(args)
    library, entry = load_entry(args.plan, Loader(skills=registry))
    if args.name is None:
        roots = [r for r in root_plans(library, entry, None) if r in library.plans]
        if not roots:
            raise AlicaError(f"{args.plan} defines no plan to run; give one with --name")
        plan = roots[0]
    else:
        plan = args.name
    agents = parse_roster(args.agents)
    roles = agent_roles(library, agents, args.roleset)
    skills = plan_skills(library, plan)
    plugin = robot_plugin(args, agents)
    if plugin is not None and args.world is not None:
        raise AlicaError("--robot and --world both give the team its robots: choose one")
    has_robots = args.world is not None or plugin is not None
    try:
        wiring = skill_wiring(registry, skills, world=has_robots, stand_ins=args.stand_ins, plan=plan)
    except AlicaError as exc:
        raise AlicaError(f"{exc}{_declared_in_files(registry, skills)}") from None
    if args.team_keys is not None and not args.processes:
        raise AlicaError("--team-keys goes with --processes (a simulated team has no network to secure)")
    if args.processes:
        header = _trace_header(args, library, plan, roles, None) if args.trace or args.center else None
        return _run_processes(args, plan, list(agents), wiring, header, library, session)
    args.load_plans = lambda: load_entry(args.plan, Loader(skills=registry))[0]  # --watch, the center's reload
    with ros2_output(args) as args.ros2_output:  # --ros2, --record: the team's topics after every tick
        if plugin is not None:
            return _run_plugged(args, library, plan, roles, wiring, plugin, session)
        with run_world(args, sorted(agents)) as (world, perception):
            return _run_team(args, library, plan, roles, wiring, world, perception, session)


def _run_plugged(
    args: argparse.Namespace,
    library: PlanLibrary,
    plan: str,
    roles: dict[str, str | AgentSpec],
    wiring: SkillWiring,
    plugin: RobotPlugin,
    session: LiveSession | None,
) -> int:
    """``alica run --robot``: every agent's skills act on its own robot of the plug-in, stepped in simulated time."""
    from alica.allocation import AgentSpec
    from alica.app.robot_plugin import PluggedRobots

    role_names = {name: (r.role if isinstance(r, AgentSpec) else r) or "" for name, r in roles.items()}
    robots = PluggedRobots(plugin, role_names)
    try:
        return _run_team(args, library, plan, roles, wiring, None, None, session, robots)
    finally:
        robots.close()


def _declared_in_files(registry: SkillRegistry, skills: list[str]) -> str:
    """A note on the skills a plan file declared (``skills:``): how to bind an implementation to them."""
    declared = [registry.get(name) for name in skills if name in registry]
    declared = [s for s in declared if s.declared_at is not None and s.implementation is None]
    if not declared:
        return ""
    where = ", ".join(f"{s.name} in {s.declared_at}" for s in declared)
    return (
        f"; a plan file declares {where}: a --skills MODULE whose register(registry) declares "
        "the same name with an implementation binds one"
    )


def _trace_header(
    args: argparse.Namespace,
    library: PlanLibrary,
    plan: str,
    roles: dict[str, str | AgentSpec],
    world: World | None,
) -> dict[str, Any]:
    """The header of the run's trace: the plan file, the root plan, every agent's role, the seed, the world."""
    from alica.allocation import AgentSpec, assign_roles
    from alica.app.trace_sources import plan_path_names
    from alica.app.trace_world import MAP_EVERY, world_header
    from alica.engine import pick_roleset, trace_header

    specs = {n: r if isinstance(r, AgentSpec) else AgentSpec(role=r) for n, r in roles.items()}
    return trace_header(
        plans=[args.plan],
        root=plan,
        agents=assign_roles(specs, pick_roleset(library, (s.role for s in specs.values()), args.roleset)),
        seed=args.seed,
        frequency=args.frequency,
        processes=bool(args.processes),
        skills=args.skills,
        plan_path=plan_path_names(),
        **world_header(
            world, args.world, pose_hz=args.pose_rate, map_every=MAP_EVERY if args.world == "lunar" else None
        ),
    )


def _run_team(
    args: argparse.Namespace,
    library: PlanLibrary,
    plan: str,
    roles: dict[str, str | AgentSpec],
    wiring: SkillWiring,
    world: World | None,
    perception: Callable[[SimulatedTeam], None] | None,
    session: LiveSession | None = None,
    robots: PluggedRobots | None = None,
) -> int:
    from alica.app.trace_world import WorldTrace, team_grid, tee
    from alica.engine import JsonlTrace, SimulatedTeam, running_tree
    from alica.lang import literals
    from alica.prophet import engine_config
    from alica.testing import default_fallback

    if not (args.pose_rate > 0 and args.pose_rate < float("inf")):
        raise AlicaError(f"--pose-rate must be a positive number of poses per second, got {args.pose_rate}")
    reasons = _Reasons()
    observers: list[Observer] = [reasons]
    header = _trace_header(args, library, plan, roles, world) if args.trace or args.center else None
    # a live run's trace (--watch, --center) is written through line by line, for whoever follows it
    trace = (
        JsonlTrace(args.trace, header=header, line_buffered=args.watch or session is not None) if args.trace else None
    )
    if trace is not None:
        observers.append(trace)
    hub = session.start(header, library) if session is not None and header is not None else None
    if hub is not None:
        observers.append(hub)
    changed: set[str] = set()
    if args.show_tree:
        observers.append(
            lambda e: changed.add(e["agent"]) if e["event"] in ("transition", "allocation", "repair") else None
        )
    if args.watch or session is not None:
        from alica.app.plan_watch import print_reloads

        observers.append(print_reloads)
    team = SimulatedTeam(
        library,
        plan,
        roles,
        seed=args.seed,
        config=engine_config(  # planning problems run with pRoPhEt MAS
            frequency=args.frequency,
            parallel_planning=args.parallel_planning,
            review=args.review,
            **engine_settings(args),
        ),
        roleset=args.roleset,
        loss=args.loss,
        delay=args.delay / 1000.0,
        jitter=args.jitter / 1000.0,
        skill_registry=wiring.registry,
        fallback=default_fallback(args.seed, registry=wiring.registry) if args.stand_ins else None,
        observers=observers,
        trace_messages=args.trace_messages,
        world=world if robots is None else robots,
        perception=perception,
        agent_worlds=None if robots is None else robots.worlds,
    )
    if world is not None or robots is not None:
        from alica.app.run_skills import share_poses

        team.after_tick(share_poses(team))
    sinks = [s for s in (trace, hub) if s is not None]
    if sinks and world is not None:
        sample = WorldTrace(
            tee(sinks),
            world,
            alive=lambda name: name not in team.crashed,
            team_map=(lambda: team_grid(team)) if args.world == "lunar" else None,
            pose_hz=args.pose_rate,
        )
        sample(team.now())
        team.after_tick(sample)
    if args.ros2_output is not None:
        args.ros2_output.attach_team(team, library)
    for text in args.crash:
        who, at, _ = _timed("--crash", text)
        team.crash(who, at=at)
    for text in args.recover:
        who, at, _ = _timed("--recover", text)
        team.recover(who, at=at)
    for text in args.partition:
        groups, start, end = partition(text)
        team.partition(groups, start=start, end=end)
    for text in args.fact:
        what, at, _ = _timed("--fact", text)
        team.set_facts(literals(what), at=at)
    if args.watch or session is not None:  # --watch, and the control center's reload action
        from alica.app.plan_watch import PlanWatch, TeamReloads

        reloads = TeamReloads(PlanWatch(args.plan, library, args.load_plans), team, observers)
        if args.watch:
            team.after_tick(reloads.look)
        if session is not None:
            session.reloads = reloads
            if session.hub is not None:  # the page's plan trees follow the library the team adopts
                reloads.offers.append(session.hub.offer)
    if session is not None:  # the operator's actions run and the wall clock catches up between two ticks
        session.pace(team)
        team.after_tick(lambda now: session.pace(team))
    elif args.watch:  # an edit lands while the run goes on
        from alica.app.pacing import WallPace

        team.after_tick(WallPace(args.speed))
    try:
        if args.show_tree:
            _run_showing(team, args, changed, running_tree)
        elif args.ticks is not None:
            team.run(ticks=args.ticks)
        else:
            team.run(until_done=True, max_time=args.time_limit)
    except KeyboardInterrupt:
        if session is None:
            raise
    finally:
        if trace is not None:
            trace.close()
    summary = team.summary()
    summary["skills"] = {"real": wiring.real, "stand_ins": wiring.stand_ins, "world": args.world}
    if robots is not None:
        summary["skills"]["robot"] = args.robot
    for name, agent in summary["agents"].items():
        agent["reason"] = reasons.of(team, name, agent["status"])
    if args.json:
        print(json.dumps(summary, indent=2, sort_keys=True))
    else:
        _print_summary(summary, args.trace)
    if session is not None:
        session.finish(summary)
    return 0 if summary["success"] else 1


def _run_processes(
    args: argparse.Namespace,
    plan: str,
    names: list[str],
    wiring: SkillWiring,
    header: dict[str, Any] | None = None,
    library: PlanLibrary | None = None,
    session: LiveSession | None = None,
) -> int:
    """``alica run --processes``: one ``alica agent`` per agent (:mod:`alica.app.processes`).

    With ``--center`` (``session``), this process serves the team's live page
    (:mod:`alica.app.center.team_feed`) from before the agents start until SIGTERM after they ended.
    """

    unsupported = [
        option
        for option, used in (
            ("--ticks", args.ticks is not None),
            ("--show-tree", args.show_tree),
            ("--loss", args.loss > 0),
            ("--delay", args.delay > 0),
            ("--jitter", args.jitter > 0),
            ("--trace-messages", args.trace_messages),
            ("--speed", args.speed != 1.0 and args.world is None),
        )
        if used
    ]
    if unsupported:
        raise AlicaError(
            f"--processes runs the agents on a real network and the wall clock: {', '.join(unsupported)} "
            "only work in the simulated run (leave out --processes)"
        )
    faults: list[Fault] = []
    for text in args.crash:
        who, at, _ = _timed("--crash", text)
        faults.append((at, "crash", who))
    for text in args.recover:
        who, at, _ = _timed("--recover", text)
        faults.append((at, "recover", who))
    for text in args.partition:
        groups, start, end = partition(text)
        faults.append((start, "partition", (groups, start, end)))
        if end is not None:
            faults.append((end, "heal", None))
    for _, kind, what in faults:
        if kind in ("crash", "recover") and what not in names:
            raise AlicaError(f"--{kind}: no agent named '{what}' in the team; agents: {', '.join(names)}")
    faults.sort(key=lambda fault: fault[0])
    options = ["--frequency", repr(args.frequency), "--seed", str(args.seed)]
    options += [arg for text in args.fact for arg in ("--fact", text)]
    options += [arg for module in args.skills for arg in ("--skills", module)]
    if args.robot:
        options += ["--robot", args.robot, *(arg for item in args.robot_option for arg in ("--robot-option", item))]
    if args.name:
        options += ["--root", args.name]
    if args.roleset:
        options += ["--roleset", args.roleset]
    if args.stand_ins:
        options.append("--stand-ins")
    if args.parallel_planning:
        options.append("--parallel-planning")
    if args.review:
        options.append("--review")
    options += engine_arguments(args)
    if args.watch:
        options.append("--watch")
    keys = _team_keys(args, names, session is not None)
    if keys is not None:
        options += ["--team-keys", args.team_keys]
    with contextlib.ExitStack() as stack:
        if args.world is not None:
            endpoint = stack.enter_context(_served_world(args, names))
            options += ["--world", endpoint]
            if args.world == "blocks":
                options += ["--perception", "blocks"]
        return _launch_processes(args, plan, names, wiring, header, library, session, options, keys, faults)


def _launch_processes(
    args: argparse.Namespace,
    plan: str,
    names: list[str],
    wiring: SkillWiring,
    header: dict[str, Any] | None,
    library: PlanLibrary | None,
    session: LiveSession | None,
    options: list[str],
    keys: TeamKeys | None,
    faults: list[Fault],
) -> int:
    import tempfile
    from pathlib import Path

    from alica.app.processes import ProcessTeam

    with tempfile.TemporaryDirectory(prefix="alica-run-") as tmp:
        team = ProcessTeam(
            args.plan,
            args.agents,
            names,
            options,
            Path(tmp),
            relays=bool(args.partition),
            deadline=args.time_limit,
            tls=keys is not None,
            per_incarnation=ros2.for_agent if (ros2 := ros2_arguments(args)) is not None else None,
        )
        live = _ProcessCenter(session, team, header, library, keys) if session is not None else None
        interrupted = False
        terminate = _TerminateAsInterrupt()
        try:
            if live is not None:
                live.serve()
            team.launch()
            team.run(faults, args.time_limit, on_started=live.started if live is not None else _announce)
        except KeyboardInterrupt:
            interrupted = True
        except BaseException:
            if live is not None:
                live.close()
            raise
        finally:
            terminate.restore()
            team.stop()
        summary = team.summary(plan, args.seed)
        if args.trace:
            team.trace(Path(args.trace), header)
    summary["skills"] = {"real": wiring.real, "stand_ins": wiring.stand_ins, "world": args.world}
    if args.robot:
        summary["skills"]["robot"] = args.robot
    for agent in summary["agents"].values():
        agent["reason"] = None if agent["status"] == "success" else _process_reason(agent)
    if args.json:
        print(json.dumps(summary, indent=2, sort_keys=True))
    else:
        _print_summary(summary, args.trace)
    if live is not None:
        live.finish(summary)
    if interrupted:
        return 130
    return 0 if summary["success"] else 1


class _TerminateAsInterrupt:
    """While the team runs, SIGTERM stops it as Ctrl-C does: agents stopped, summary and merged trace written."""

    def __init__(self) -> None:
        import signal
        import threading

        self._previous: Any = None
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGTERM, self._interrupt)

    @staticmethod
    def _interrupt(*_: object) -> None:
        raise KeyboardInterrupt

    def restore(self) -> None:
        import signal

        if self._previous is not None:
            signal.signal(signal.SIGTERM, self._previous)
            self._previous = None


@contextlib.contextmanager
def _served_world(args: argparse.Namespace, names: list[str]) -> Iterator[str]:
    """``alica run --processes --world``: the world in a server on loopback, serving from a thread; its endpoint.

    Lock-step (the agents' ticks pace simulated time) unless ``--speed X`` asks for a free-running world.
    With ``--team-keys`` the server is the member ``world`` of the team's credentials (TLS, and the world's
    access control: each agent reaches only its own robot).
    """
    import threading

    from alica.app.run_skills import run_world
    from alica.app.world_server import WorldServer
    from alica.comm.zenoh_transport import free_endpoints

    if not (args.speed > 0 and math.isfinite(args.speed)):
        raise AlicaError(f"--speed must be a positive number of simulated seconds per wall second, got {args.speed}")
    settings = None
    endpoint = free_endpoints(1)[0]
    if args.team_keys is not None:  # the server is the member "world" of the team's credentials
        from alica.app.world_server.access import WORLD, world_settings
        from alica.comm.credentials import TeamKeys, tls_endpoint

        settings = world_settings(TeamKeys.load(args.team_keys, WORLD), "alica")
        endpoint = tls_endpoint(endpoint)
    with run_world(args, sorted(names)) as (world, _perception):
        assert world is not None
        server = WorldServer(
            world,
            listen=[endpoint],
            prefix="alica",
            lockstep=args.speed == 1.0,
            speed=args.speed,
            frequency=args.frequency,
            agents=names,
            settings=settings,
        )
        serving = threading.Thread(target=server.serve, name="world-server", daemon=True)
        serving.start()
        try:
            yield endpoint
        finally:
            server.stop()
            serving.join(timeout=5.0)
            server.close()


def _team_keys(args: argparse.Namespace, names: list[str], center: bool) -> TeamKeys | None:
    """``--team-keys`` of ``alica run --processes``: every agent's (and the center's) keys load, before anything starts.

    Returns:
        The center's keys with ``--center`` (``None`` without credentials); otherwise the first agent's.
    """
    if args.team_keys is None:
        return None
    from alica.comm.credentials import CENTER, TeamKeys

    loaded = [TeamKeys.load(args.team_keys, name) for name in names]  # each refuses a name outside the roster
    return TeamKeys.load(args.team_keys, CENTER) if center else loaded[0]


class _ProcessCenter:
    """``alica run --processes --center``: the live page of the team of processes this run started."""

    hub: LiveHub
    """The page's hub, from :meth:`serve` on."""

    def __init__(
        self,
        session: LiveSession,
        team: ProcessTeam,
        header: dict[str, Any] | None,
        library: PlanLibrary | None,
        keys: TeamKeys | None = None,
    ) -> None:
        from alica.app.center.team_feed import TeamFeed

        assert header is not None
        self.session, self.team, self.header, self.library = session, team, header, library
        self.feed = TeamFeed([agent.listen for agent in team.agents.values()], "alica", keys=keys)
        team.on_fault = self.feed.put  # kill -9, restarts and partitions are this process's doing
        self.server: uvicorn.Server | None = None
        self.loop: CommandLoop | None = None

    def serve(self) -> None:
        """Serve the page now (the team's events come once its agents are up)."""
        from alica.app.center.team_feed import start_live

        s = self.session
        self.feed.start = self.team.start
        hub, self.server, self.loop = start_live(
            self.feed, self.header, self.library, s.host, s.port, s.token, s.out, plans=self._plans()
        )
        self.hub = hub

    def _plans(self) -> PlanWatch | None:
        """The team's plan files as this process reads them, for the page's reload action and plan trees.

        Loaded with the skill modules and plan folders the header records (as the page's trees are), so
        the library's digest is the one the agents compute from the same files.
        """
        from alica.app.plan_entry import load_entry
        from alica.app.plan_watch import PlanWatch
        from alica.app.trace_sources import viewer_sources

        if self.library is None:
            return None
        sources = viewer_sources(self.header)
        plan = self.team.plan
        return PlanWatch(plan, self.library, lambda: load_entry(plan, sources.loader())[0])

    def started(self, count: int, at: float) -> None:
        """Every agent process is up: connect to the team (the clock counts from the team's launch)."""
        self.feed.start = self.team.start
        _announce(count, at)
        try:
            self.feed.open()
        except AlicaError as exc:
            print(f"alica run: the control center sees no agent: {exc}", file=sys.stderr, flush=True)

    def finish(self, summary: dict[str, Any]) -> None:
        """The team ended: the page shows the summary until Ctrl-C or SIGTERM."""
        from alica.app.center.live import wait_for_stop

        self.hub.finish(summary)
        print("the run is over; the control center stays up until Ctrl-C", file=sys.stderr, flush=True)
        try:
            wait_for_stop()
        finally:
            self.close()

    def close(self) -> None:
        if self.loop is not None:
            self.loop.close()
        if self.server is not None:
            self.server.should_exit = True
        self.feed.close()


def _announce(count: int, at: float) -> None:
    print(f"alica run: {count} agent processes started after {at:.1f} s (Ctrl-C stops them all)", file=sys.stderr)
    sys.stderr.flush()


def _process_reason(agent: dict[str, Any]) -> str:
    status = agent["status"]
    if status == "crashed":
        return "killed (kill -9)"
    if status == "exited":
        last = agent.get("reason")
        return f"its process exited by itself{f': {last}' if last else ''}"
    return f"ended {status} at {agent.get('path') or 'no plan'}"


def _run_showing(
    team: SimulatedTeam, args: argparse.Namespace, changed: set[str], running_tree: Callable[[AgentEngine], str]
) -> None:
    ticks = 0
    while True:
        if args.ticks is not None and ticks >= args.ticks:
            break
        if args.ticks is None and (team.done() or team.now() >= args.time_limit):
            break
        team.tick()
        ticks += 1
        for name in sorted(changed):
            if name not in team.crashed:
                print(f"--- t={team.now():.2f} s")
                print(running_tree(team.engines[name]))
        changed.clear()


class _Reasons:
    """A trace observer that keeps, per agent, the last failure or allocation problem the engine reported."""

    def __init__(self) -> None:
        self.last: dict[str, str] = {}

    def __call__(self, event: dict[str, Any]) -> None:
        kind = event["event"]
        if kind == "allocation" and event.get("outcome") == "none":
            text = f"{event.get('why') or 'no valid assignment'} (in {event.get('key')})"
        elif kind == "failure":
            text = f"plan '{event.get('plan')}' failed: {event.get('reason') or 'no reason given'}"
        elif kind == "behaviour" and event.get("status") == "failure":
            text = f"behaviour '{event.get('behaviour')}' failed: {event.get('reason') or 'no reason given'}"
        elif kind == "fault" and event.get("fault") in ("crash", "recover"):
            text = f"{event['fault']}ed at {event['t']:g} s"
        else:
            return
        self.last[event["agent"]] = f"{text} at t={event['t']:.2f} s" if kind != "fault" else text

    def of(self, team: SimulatedTeam, name: str, status: str) -> str | None:
        """Why agent ``name`` has not succeeded: what it waits for, or the last problem reported; ``None`` on success."""
        if status == "success":
            return None
        last = self.last.get(name)
        if status != "running":
            return last
        engine = team.engines[name]
        says = "; ".join(f"{skill} says: {text}" for skill, text in _feedback(engine))
        waiting = _waiting(engine)
        parts = [p for p in (waiting, says, f"last problem: {last}" if waiting and last else last) if p]
        return "; ".join(parts) or "not started"


def _feedback(engine: AgentEngine) -> list[tuple[str, str]]:
    """Each running behaviour of the agent's plan tree with its own word on its progress (``feedback_message``)."""
    found: list[tuple[str, str]] = []
    nodes = [engine.root] if engine.root is not None else []
    while nodes:
        node = nodes.pop(0)
        for slot in node.slots:
            if slot.feedback:
                found.append((slot.name, slot.feedback))
            if slot.node is not None:
                nodes.append(slot.node)
    return found


def _waiting(engine: AgentEngine) -> str | None:
    """What a running agent waits for: a child's reason (e.g. no valid assignment), else its state's transitions."""
    node = engine.root
    if node is None:
        return None
    while True:
        stuck = [s for s in node.slots if s.reason and s.status.value != "success"]
        if stuck:
            return f"{stuck[0].name} in {node.plan.name}:{node.state}: {stuck[0].reason}"
        child = next((s.node for s in node.slots if s.node is not None), None)
        if child is None:
            break
        node = child
    if node.state is None:
        return f"{node.plan.name}: no state entered yet"
    where = f"in {node.plan.name}:{node.state}"
    children = [f"{s.name} {s.status.value}" for s in node.slots]
    if children:
        where += f" ({', '.join(children)})"
    conditions = [t.condition.text if t.condition else "always" for t in node.plan.out_transitions(node.state)]
    if not conditions:
        return f"{where}, a state with no transition out that is not terminal"
    return f"{where}, waiting for one of: {'; '.join(conditions)}"


#: What became of the copies a summary's ``messages`` counts, by key, in the words of the summary line.
DROPPED = {
    "dropped_loss": "dropped by loss",
    "dropped_partition": "dropped by partitions",
    "dropped_crash": "dropped at crashed receivers",
    "dropped_closed": "dropped at closed receivers",
    "dropped_lost": "lost for good (no longer in the sender's history)",
    "dropped_undecodable": "not decodable",
    "superseded": "replaced by a newer one before delivery",
}


def message_counts(messages: dict[str, int]) -> str:
    """The summary's line on messages: publish calls, then what became of the copies per receiver.

    Example: ``messages: 260 sent; copies to receivers: 256 delivered, 203 dropped by loss,
    60 dropped at crashed receivers``.
    """
    fates = [f"{messages[key]} {words}" for key, words in DROPPED.items() if messages.get(key)]
    return f"messages: {messages['sent']} sent; copies to receivers: {messages['delivered']} delivered, " + (
        ", ".join(fates) if fates else "none dropped"
    )


def _print_summary(summary: dict[str, Any], trace: str | None) -> None:
    failed = any(a["status"] == "failure" for a in summary["agents"].values())
    verdict = (
        "success"
        if summary["success"]
        else ("not finished" if not summary["done"] else "failed" if failed else "ended")
    )
    clock = "wall-clock, one process per agent" if summary.get("processes") else "simulated"
    print(
        f"{summary['plan']}: {verdict} after {summary['sim_time_s']:.2f} s {clock} ({summary['ticks']} ticks), seed {summary['seed']}"
    )
    header = f"{'agent':<12} {'role':<12} {'status':<8} {'transitions':>11} {'allocations':>11} {'sent':>6} {'recv':>6} {'repairs':>7}  where"
    print(header)
    for name, a in summary["agents"].items():
        print(
            f"{name:<12} {a['role']:<12} {a['status']:<8} {a['transitions']:>11} {a['allocations']:>11} {a['messages_out']:>6} {a['messages_in']:>6} {a['repairs']:>7}  {a['path']}"
        )
    skills = summary.get("skills") or {}
    if skills.get("real"):
        where = f" in the {skills['world']} world" if skills.get("world") else ""
        print(f"real skills{where}: {', '.join(skills['real'])}")
    if skills.get("stand_ins"):
        print(f"scripted stand-ins (--stand-ins): {', '.join(skills['stand_ins'])}")
    print(message_counts(summary["messages"]))
    if "world_models_agree" in summary:
        agree = "agree" if summary["world_models_agree"] else "DIFFER"
        print(f"world models of the running agents: {agree}")
    if not summary["success"]:
        for name, a in summary["agents"].items():
            if a["reason"]:
                print(f"why {name}: {a['reason']}")
    if summary["faults"]:
        print("faults: " + "; ".join(summary["faults"]))
    if trace:
        print(f"trace: {trace}")
    sys.stdout.flush()
