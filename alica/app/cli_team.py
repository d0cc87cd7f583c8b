"""``alica team keys``: a team's credentials (:mod:`alica.comm.credentials`).

``alica team keys --out DIR NAME...`` makes the team's CA, a certificate and
key for each agent and for the control center, and the roster;
``--add`` adds agents to the team in ``DIR`` with its CA. Exit 0 when the
files were made, 2 on wrong usage (a folder that is not empty, a bad name).
"""

from __future__ import annotations

import argparse
import sys

from alica.app.plan_entry import EXIT_OK, EXIT_USAGE


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``team`` subcommand (with ``team keys``) to the ``alica`` parser."""
    team = sub.add_parser(
        "team",
        help="a team's credentials: alica team keys",
        description="Manage a team's credentials.",
    )
    actions = team.add_subparsers(dest="team_command", metavar="ACTION")
    actions.required = True
    p = actions.add_parser(
        "keys",
        help="make a team's credentials (TLS certificates and keys, the roster), or add agents to them",
        description="Make a team's credentials in a new folder: the team's certificate authority (ca.pem, ca.key), "
        "a certificate and private key for each agent NAME and for the control center (NAME.pem, NAME.key, "
        "center.pem, center.key), and the roster (roster.json). Give the folder to --team-keys: the team's zenoh "
        "links then use TLS with mutual authentication and access control. Exit 0 when the files were made, "
        "2 on wrong usage.",
    )
    p.add_argument("names", nargs="+", metavar="NAME", help="the agents of the team (their --name)")
    p.add_argument("--out", required=True, metavar="DIR", help="the folder to make (new, or empty)")
    p.add_argument(
        "--add", action="store_true", help="add the agents to the team in DIR (made before; its ca.key must be there)"
    )
    p.add_argument(
        "--days", type=int, default=365, metavar="N", help="days the new certificates are valid (default 365)"
    )
    p.set_defaults(run=_cmd_keys)


def _cmd_keys(args: argparse.Namespace) -> int:
    from alica.comm.credentials import CA, CENTER, ROSTER, CredentialsError, make_keys

    try:
        written = make_keys(args.out, args.names, days=args.days, add=args.add)
    except CredentialsError as exc:
        print(f"alica team keys: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    out = args.out.rstrip("/") or "/"
    print(f"{'added to' if args.add else 'made'} the team's credentials in {out}/:")
    for path in written:
        print(f"  {path}")
    shared = f"{CA}.pem, {ROSTER}, {CENTER}.pem"
    if args.add:
        print(f"Copy the new {ROSTER} to every host of the team (the agents' and the center's).")
    print(
        f"Copy to each agent's host: {shared} and its own NAME.pem and NAME.key (only those); to the control "
        f"center's host: {shared} and {CENTER}.key.\n"
        f"Keep {out}/{CA}.key with whoever adds agents (alica team keys --out {out} --add NAME...): "
        "anyone holding it can make members.\n"
        "Then start each process with --team-keys pointing to its copy, and tls/HOST:PORT endpoints."
    )
    return EXIT_OK
