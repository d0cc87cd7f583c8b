"""``alica center``: serve the control center's page for a trace replay or a plan file."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import Any

from alica.app.team_keys import add_team_keys_option
from alica.errors import AlicaError


def _cmd_center(args: argparse.Namespace) -> int:
    import secrets

    from alica.app.center.server import plan_app, replay_app, serve
    from alica.app.skill_options import skill_registry

    token = args.token or secrets.token_urlsafe(24)
    if args.no_trace_skills and args.plan is not None:
        raise AlicaError("--no-trace-skills goes with --trace or --team (it skips the modules a run recorded)")
    registry = skill_registry(args)  # the --skills modules must load, whatever the mode (a clear error if not)
    if args.team is not None:
        from alica.app.center.team_feed import JOIN_WAIT, serve_team
        from alica.app.team_keys import team_settings
        from alica.comm.credentials import CENTER

        wait = JOIN_WAIT if args.wait is None else args.wait
        if not wait > 0:
            raise AlicaError(f"--wait must be a positive number of seconds, got {args.wait}")
        prefix = args.key_prefix or "alica"
        team_settings(args, "alica center", CENTER, None, args.team, prefix)  # the keys load, the endpoints fit
        serve_team(args.team, prefix, args.host, args.port, token, wait=wait, skills=args.skills, keys=args.keys)
        return 0
    misplaced = [
        option
        for option, given in (
            ("--key-prefix", args.key_prefix is not None),
            ("--wait", args.wait is not None),
            ("--team-keys", args.team_keys is not None),
            ("--insecure", args.insecure),
        )
        if given
    ]
    if misplaced:
        raise AlicaError(f"{' and '.join(misplaced)} go(es) with --team (a running team of processes)")
    if args.trace is not None:
        from alica.app.center.trace_file import TraceFormatError, load_trace

        try:
            trace = load_trace(args.trace)
        except TraceFormatError as exc:  # already FILE:LINE: error: ..., as a compiler says it
            print(exc, file=sys.stderr)
            return 1
        replay, trees = trace_replay(trace, args.skills, header_skills=not args.no_trace_skills)
        for note in trees["notes"]:
            print(f"alica center: {note}", file=sys.stderr)
        app = replay_app(replay, token, trees)
    else:
        app = plan_app(args.plan, *plan_views(args.plan, registry), token)
    serve(app, args.host, args.port, token)
    return 0


def trace_replay(trace: Any, skills: Sequence[str] = (), *, header_skills: bool = True) -> tuple[Any, dict[str, Any]]:
    """The replay of a loaded trace and its agents' plan trees.

    The header's plan files are loaded with the skill modules and plan folders the header
    records (:func:`~alica.app.trace_sources.viewer_sources`) plus ``skills``; what cannot be
    loaded is in the trees' ``notes``.

    Raises:
        SkillPluginError: a module of ``skills`` cannot be loaded.
    """
    from pathlib import Path

    from alica.app.center.plan_view import entry_states, trace_plans, trace_trees
    from alica.app.center.replay import Replay
    from alica.app.trace_sources import viewer_sources

    sources = viewer_sources(trace.meta, skills, base=Path(trace.path).parent, header_skills=header_skills)
    loaded = trace_plans(trace.meta, trace.path, sources.loader)
    trees = trace_trees(trace.meta, trace.path, loaded=loaded)
    trees["notes"] = [*sources.notes, *trees["notes"]]
    return Replay(trace, entries=entry_states(loaded[0])), trees


def plan_views(path: str, registry: Any = None) -> tuple[dict[str, dict[str, Any]], dict[str, str]]:
    """The plan trees (data and SVG) of a plan file's top-level plans.

    Args:
        registry: the skills the plans are checked against (:func:`~alica.app.skill_options.skill_registry`);
            by default the installed plug-ins.

    Raises:
        PlanFormatError: the plan file does not load.
        AlicaError: it defines nothing to draw.
    """
    from alica.app.center.plan_view import plan_svg, plan_tree
    from alica.app.plan_entry import load_entry, root_plans
    from alica.io import Loader

    library, entry = load_entry(path, Loader(skills=registry) if registry is not None else None)
    roots = root_plans(library, entry, None)
    if not roots:
        raise AlicaError(f"{path} defines no plan, planning problem or behaviour to draw")
    return {r: plan_tree(library, r) for r in roots}, {r: plan_svg(library, r) for r in roots}


def port_number(text: str) -> int:
    """A TCP port from the command line (0 to 65535; 0 picks a free one)."""
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"'{text}' is not a port (0 to 65535; 0 picks a free one)")
    return port


def add_live_options(parser: Any, review: bool = False) -> None:
    """The options that serve a run's control center live: ``--center`` and its address, token and speed."""
    group = parser.add_argument_group("control center (a live view of the run in a web page)")
    group.add_argument(
        "--center",
        action="store_true",
        help="serve the control center for this run: prints http://HOST:PORT/?token=TOKEN to open; the run goes "
        "at --speed times the wall clock; after the run the page stays up until Ctrl-C",
    )
    group.add_argument("--center-host", default="127.0.0.1", metavar="HOST", help="address to bind (default 127.0.0.1)")
    group.add_argument(
        "--center-port", type=port_number, default=8765, metavar="P", help="port (default 8765; 0 picks a free one)"
    )
    group.add_argument("--center-token", metavar="T", help="the access token (default: a new random one)")
    group.add_argument(
        "--speed",
        type=float,
        default=1.0,
        metavar="X",
        help="with --center or --watch: simulated seconds per wall second (default 1; inf: as fast as possible)",
    )
    if review:
        group.add_argument(
            "--review",
            action="store_true",
            help="with --center: the leader shows each generated plan to the operator, who accepts, declines or "
            "changes it before the team runs it",
        )


def live_session(args: argparse.Namespace) -> Any:
    """The run's :class:`~alica.app.center.live.LiveSession` with ``--center``, else ``None``.

    Raises:
        AlicaError: ``--speed`` (but with ``--processes --world``: the world server's speed) or ``--review``
            without ``--center``, or a speed that is not positive.
    """
    if not args.center:
        served = getattr(args, "processes", False) and getattr(args, "world", None) is not None
        watched = getattr(args, "watch", False) and not getattr(args, "processes", False)
        if (args.speed != 1.0 and not (served or watched)) or getattr(args, "review", False):
            raise AlicaError("--speed and --review need --center (or --speed --watch): they are settings of a live run")
        return None
    from alica.app.center.live import LiveSession

    out = sys.stderr if getattr(args, "json", False) else sys.stdout  # --json keeps standard output for the JSON
    return LiveSession(args.speed, args.center_host, args.center_port, args.center_token, out=out)


def add_parser(sub: Any) -> None:
    """Register ``alica center``."""
    from alica.app.skill_options import add_skills_option

    p = sub.add_parser(
        "center",
        help="serve the control center: a running team of processes, a trace replay or a plan file in a web page",
        description="Serve the control center's web page on HOST:PORT and print the one line to open, "
        "http://HOST:PORT/?token=TOKEN. Every request needs the token. --trace replays a recorded trace "
        "(time slider, play at 1x-10x, next fault or replan, agents, event log, map of poses, team map and objects, "
        "blocks table, each agent's plan tree with its current states); --plan draws "
        "the plan tree of a plan file; --team serves the live page of a running team of processes (alica agent, alica run "
        "--processes) reached at one agent's zenoh listen endpoint: every agent's events since its start, then as they "
        "happen, and the operator's actions (goal, facts, decisions under --review). Without any agent of the team "
        "answering within --wait seconds it says so on one line and exits 1. Plans that use your own skills load with "
        "--skills MODULE; a trace's header records the skill modules and plan folders of its run, and the replay loads "
        "them by itself (--no-trace-skills: not the modules). Stop it with Ctrl-C.",
    )
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--trace", metavar="FILE", help="a trace (JSON Lines) to replay")
    what.add_argument("--plan", metavar="FILE", help="a plan file (YAML or XML) to draw")
    what.add_argument(
        "--team",
        action="append",
        metavar="ENDPOINT",
        help="a zenoh listen endpoint of an agent of a running team, e.g. tcp/127.0.0.1:7447 (repeatable: the "
        "first reached is used, and the team is reached through it)",
    )
    p.add_argument(
        "--key-prefix",
        metavar="PREFIX",
        help="with --team: the team's zenoh key prefix, as its agents' --key-prefix (default alica)",
    )
    p.add_argument(
        "--wait",
        type=float,
        metavar="S",
        help="with --team: seconds to wait for a first agent to answer (default 10)",
    )
    add_team_keys_option(p.add_argument_group("with --team"))
    add_skills_option(p)
    p.add_argument(
        "--no-trace-skills",
        action="store_true",
        help="with --trace or --team: do not import the skill modules the run's trace header records "
        "(only the installed plug-ins and --skills); plans that use their skills then draw no tree",
    )
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1, this machine only)")
    p.add_argument("--port", type=port_number, default=8765, help="port (default 8765; 0 picks a free one)")
    p.add_argument("--token", help="the access token (default: a new random one)")
    p.set_defaults(run=_cmd_center)
