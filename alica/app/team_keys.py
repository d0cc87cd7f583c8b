"""``--team-keys DIR`` and ``--insecure``: how a process of a team (agent, process team, center) joins it.

With the team's credentials (made by ``alica team keys``), the process's
zenoh session uses TLS with mutual authentication and zenoh's access control
(:meth:`alica.comm.credentials.TeamKeys.zenoh_settings`), and its endpoints
must be ``tls/``. Without them it is unauthenticated and unencrypted, so it
talks only over loopback unless ``--insecure`` says otherwise, and it says so
on standard error when it starts.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable
from typing import TYPE_CHECKING

from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.comm.credentials import TeamKeys


def add_team_keys_option(parser: argparse.ArgumentParser | argparse._ArgumentGroup, *, insecure: bool = True) -> None:
    """Add ``--team-keys`` (and ``--insecure``, for processes given endpoints) to ``parser``."""
    parser.add_argument(
        "--team-keys",
        metavar="DIR",
        help="the team's credentials (made by alica team keys): TLS with mutual authentication and access "
        "control; only holders of the team's keys connect, and each speaks only for itself (endpoints are tls/...)",
    )
    if not insecure:
        return
    parser.add_argument(
        "--insecure",
        action="store_true",
        help="without --team-keys, allow endpoints beyond loopback: anyone who reaches them can read and steer "
        "the team",
    )


def check_members(keys: TeamKeys, members: Iterable[str], who: str) -> None:
    """Refuse ``members`` that hold no keys of ``keys``'s team (``who``: the process, for the message).

    Raises:
        AlicaError: some do not, with the command that adds them.
    """
    outside = sorted(set(members) - keys.members)
    if outside:
        raise AlicaError(
            f"{who}: {', '.join(outside)} hold(s) no keys of the team in {keys.folder}; add them with "
            f"'alica team keys --out {keys.folder} --add {' '.join(outside)}'"
        )


def team_settings(
    args: argparse.Namespace,
    who: str,
    name: str,
    members: Iterable[str] | None,
    endpoints: Iterable[str],
    prefix: str,
) -> dict[str, object]:
    """The zenoh settings of ``args.team_keys`` for ``name``; sets ``args.keys`` (``None`` without credentials).

    Args:
        args: the parsed command line (``team_keys``, ``insecure``).
        who: the process, for messages (``"alica agent b"``).
        name: the process's identity in the team (an agent's name, or ``center``).
        members: the agents the process takes as its team (each must hold keys of the team).
        endpoints: the zenoh endpoints the process listens on and connects to.
        prefix: the team's zenoh key prefix.

    Raises:
        AlicaError: credentials that do not load, a member without keys, an endpoint that is not TLS
            with credentials or beyond loopback without them (and without ``--insecure``).
    """
    from alica.comm.zenoh_transport import off_loopback

    endpoints = list(endpoints)
    if args.team_keys is None:
        args.keys = None
        beyond = off_loopback(endpoints)
        if beyond and not args.insecure:
            raise AlicaError(
                f"{who}: {', '.join(beyond)} reaches beyond this machine, and without team credentials anyone "
                "who reaches it can read and steer the team; make credentials with 'alica team keys --out DIR NAME...' "
                "and give --team-keys DIR (with tls/ endpoints), or say --insecure"
            )
        where = "on the network (--insecure)" if beyond else "on loopback only"
        print(f"{who}: no team credentials (--team-keys): unauthenticated and unencrypted, {where}", file=sys.stderr)
        return {}
    from alica.comm.credentials import TeamKeys, tls_endpoint

    keys: TeamKeys = TeamKeys.load(args.team_keys, name)
    check_members(keys, members or (), who)
    for endpoint in endpoints:
        if not endpoint.startswith("tls/"):
            try:
                hint = f"write {tls_endpoint(endpoint)} instead"
            except ValueError:
                hint = "use a tls/HOST:PORT endpoint"
            raise AlicaError(f"{who}: with --team-keys the team's links are TLS: {endpoint} is not; {hint}")
    args.keys = keys
    return keys.zenoh_settings(prefix)
