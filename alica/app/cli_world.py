"""``alica world serve``: one simulated world, its robots served to agents in other processes.

``alica world serve --world lunar|blocks --listen tcp/127.0.0.1:7447`` builds
the world as ``alica run --world`` does (robots named after ``--agents``) and
serves it over zenoh until interrupted (or for ``--duration`` wall seconds):
see :mod:`alica.app.world_server`. Agents open it with
:class:`~alica.app.world_server.RemoteWorld`. Exit 0 after a clean stop, 2 on
wrong usage.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from types import FrameType
from typing import TYPE_CHECKING

from alica.app.plan_entry import EXIT_OK, EXIT_USAGE
from alica.app.ros2_options import add_ros2_options, ros2_output

if TYPE_CHECKING:
    from alica.app.world_server import WorldServer

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
SWITCH_INTERVAL = 0.0005
"""Seconds between the interpreter's thread switches while serving."""


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``world`` subcommand (with ``world serve``) to the ``alica`` parser."""
    from alica.app.options import add_field_options
    from alica.app.team_keys import add_team_keys_option

    world = sub.add_parser(
        "world",
        help="a simulated world for agents in other processes: alica world serve",
        description="Serve a simulated world to agents in other processes.",
    )
    actions = world.add_subparsers(dest="world_command", metavar="ACTION")
    actions.required = True
    p = actions.add_parser(
        "serve",
        help="run a pybullet world and serve each robot over zenoh (calls, state, liveliness)",
        description="Run the lunar or blocks world in this process and serve each robot to its agent over zenoh: "
        "queries for drive, sensors and arm calls (a robot answers only its own agent), the state published "
        "after every step, and a liveliness token. An agent whose process ends is its robot's crash; when it "
        "comes back, the robot recovers. Lock-step (--lockstep) steps only when every connected agent finished "
        "its tick, so a seed repeats exactly; otherwise the world runs on the wall clock at --speed. "
        "Exit 0 after a clean stop (Ctrl-C, SIGTERM, --duration), 2 on wrong usage.",
    )
    p.add_argument("--world", required=True, choices=("lunar", "blocks"), help="the world to serve")
    p.add_argument("--seed", type=int, default=0, help="the world's seed (default 0)")
    add_field_options(p)
    p.add_argument("--stacks", default="a,b;c", help="blocks world stacks, bottom first (default 'a,b;c')")
    p.add_argument(
        "--agents",
        metavar="NAME[:ROLE],...",
        help="the team: each agent's robot is named after it (lunar: scout, stummel, amparo; blocks: default "
        "r1,r2); in lock-step the first step waits for them all",
    )
    p.add_argument(
        "--listen",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help=f"listen here, repeatable (default {DEFAULT_ENDPOINT}; tls/... with --team-keys)",
    )
    p.add_argument("--connect", action="append", default=[], metavar="ENDPOINT", help="connect here (repeatable)")
    p.add_argument("--mode", choices=("peer", "client"), default="peer", help="zenoh mode (default peer)")
    p.add_argument(
        "--key-prefix", default="alica", metavar="PREFIX", help="the team's zenoh key prefix (default alica)"
    )
    p.add_argument(
        "--lockstep",
        action="store_true",
        help="advance time one period only when every connected agent finished its tick (repeatable runs)",
    )
    p.add_argument(
        "--speed",
        type=float,
        default=1.0,
        metavar="X",
        help="free-running: simulated seconds per wall second (default 1; lock-step runs as fast as the agents tick)",
    )
    p.add_argument(
        "--frequency", type=float, default=30.0, metavar="HZ", help="world steps per simulated second (default 30)"
    )
    p.add_argument("--duration", type=float, metavar="S", help="stop after S wall seconds (default: run until stopped)")
    add_team_keys_option(p)
    p.add_argument("--json", action="store_true", help="print the start and end lines as JSON")
    add_ros2_options(p, record=False)
    p.set_defaults(run=cmd_world_serve)


def cmd_world_serve(args: argparse.Namespace) -> int:
    """Run ``alica world serve``."""
    from alica.app.options import parse_roster
    from alica.app.run_skills import run_world
    from alica.app.team_keys import team_settings
    from alica.app.world_server import WorldServer
    from alica.app.world_server.access import WORLD, world_settings
    from alica.errors import AlicaError

    who = "alica world serve"
    try:
        if args.agents:
            agents = list(parse_roster(args.agents))
        else:
            agents = ["r1", "r2"] if args.world == "blocks" else []
        default = DEFAULT_ENDPOINT.replace("tcp/", "tls/") if args.team_keys else DEFAULT_ENDPOINT
        if args.ros2 and default == args.ros2_router:  # rmw_zenohd listens there: the world takes the next port
            default = default.replace(":7447", ":7448")
        listen = list(args.listen) or ([] if args.connect else [default])
        team_settings(args, who, WORLD, agents, [*listen, *args.connect], args.key_prefix)  # (checks, sets args.keys)
        settings = {} if args.keys is None else world_settings(args.keys, args.key_prefix)
        if not (args.speed > 0 and args.frequency > 0):
            raise AlicaError(f"{who}: --speed and --frequency must be > 0")
        if args.duration is not None and not args.duration > 0:
            raise AlicaError(f"{who}: --duration must be > 0 seconds")
        with run_world(args, agents) as (world, _perception):
            if world is None:
                raise AlicaError(f"{who}: --world lunar or --world blocks is required")
            server = WorldServer(
                world,
                listen=listen,
                connect=args.connect,
                prefix=args.key_prefix,
                lockstep=args.lockstep,
                speed=args.speed,
                frequency=args.frequency,
                agents=agents,
                mode=args.mode,
                settings=settings,
            )
            try:
                return _serve(args, server, [*listen, *args.connect])
            finally:
                server.close()
    except (AlicaError, ValueError) as exc:  # (CredentialsError is an AlicaError)
        print(f"{who}: error: {str(exc).removeprefix(f'{who}: ')}", file=sys.stderr)
        return EXIT_USAGE


def _serve(args: argparse.Namespace, server: WorldServer, endpoints: list[str]) -> int:
    world = server.world
    start = {
        "event": "serving",
        "world": args.world,
        "seed": args.seed,
        "robots": sorted(world.robots),
        "endpoints": endpoints,
        "key_prefix": args.key_prefix,
        "lockstep": args.lockstep,
        "speed": args.speed,
        "frequency": args.frequency,
    }
    if args.json:
        print(json.dumps(start), flush=True)
    else:
        timing = "lock-step" if args.lockstep else f"free-running at {args.speed:g}x"
        print(
            f"alica world serve: {args.world} world (seed {args.seed}) with robots {', '.join(sorted(world.robots))} "
            f"on {', '.join(endpoints)}, key prefix '{args.key_prefix}', {timing}, {args.frequency:g} Hz",
            flush=True,
        )

    def _stop(signum: int, frame: FrameType | None) -> None:
        server.stop()

    previous = {s: signal.signal(s, _stop) for s in (signal.SIGINT, signal.SIGTERM)}
    # Calls served on zenoh's threads wait for the world's thread to let go of the interpreter: every 0.5 ms
    # rather than the default 5 ms keeps a drive command's answer within a few milliseconds.
    sys.setswitchinterval(SWITCH_INTERVAL)
    try:
        with ros2_output(args) as ros2:  # --ros2: /clock and each robot's true pose, node alica_world
            server.serve(duration=args.duration, until=ros2.attach_world(world) if ros2 is not None else None)
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    stats = server.stats
    end = {
        "event": "stopped",
        "time": world.now(),
        "steps": stats.steps,
        "calls": stats.calls,
        "refused": stats.refused,
        "rejected": sum(stats.rejected.values()),
        "crashes": stats.crashes,
        "recoveries": stats.recoveries,
    }
    if args.json:
        print(json.dumps(end), flush=True)
    else:
        print(
            f"alica world serve: stopped at {world.now():.2f} s simulated after {stats.steps} steps, "
            f"{stats.calls} calls ({stats.refused} refused, {sum(stats.rejected.values())} malformed), "
            f"{stats.crashes} crashes, {stats.recoveries} recoveries",
            flush=True,
        )
    return EXIT_OK
