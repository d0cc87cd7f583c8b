"""One vocabulary of options for the commands that run a team, a demo or a skill.

The same name means the same thing, with the same default, in ``alica run``,
``alica agent``, ``alica demo lunar|blocksworld``, ``alica skill run`` and
``alica protap``:

* ``--agents NAME[:ROLE],...``: the team by name (a roster);
* ``--robots N``: a count of robots (where the command names them itself, e.g. r1..rN);
* ``--size M``, ``--rocks N``, ``--samples K``: the lunar field (:data:`FIELD_SIZE`,
  :data:`ROCKS`, :data:`SAMPLES`);
* ``--time-limit S``: when a run gives up (simulated seconds, or wall seconds on the wall clock).

An old spelling stays for one release as a hidden alias (:func:`add_deprecated`) that
works and prints one line on standard error.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from alica.errors import AlicaError

SAMPLES = 6
"""Drill samples on a lunar field, by default."""
ROCKS = 60
"""Rocks on a lunar field, by default."""
FIELD_SIZE = 40.0
"""Side of the square lunar field in metres, by default."""

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*")


def deprecation(old: str, new: str) -> str:
    """The one line an old spelling prints on standard error."""
    return f"alica: {old} is deprecated here; use {new} (the old spelling goes in the next release)"


class _Deprecated(argparse.Action):
    """Store the value under the new option's name, and say once per use that the spelling is old."""

    def __init__(self, option_strings: Sequence[str], dest: str, new: str = "", **kwargs: Any) -> None:
        self.new = new
        super().__init__(option_strings, dest, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print(deprecation(option_string or self.option_strings[0], self.new), file=sys.stderr)
        setattr(namespace, self.dest, values)


def add_deprecated(
    parser: argparse._ActionsContainer,
    old: str,
    new: str,
    *,
    dest: str,
    type: Callable[[str], object] = str,
    metavar: str | None = None,
) -> None:
    """Add ``old`` as a hidden alias of the option ``new`` (stored in ``dest``) for one release.

    Args:
        parser: the parser or argument group.
        old: the old spelling, e.g. ``--max-time``.
        new: the spelling to use, as the warning names it, e.g. ``--time-limit``.
        dest: the attribute the new option stores into.
        type: converts the value (as argparse's ``type``); ``str`` (the default) keeps the text.
        metavar: the value's name in error messages.
    """
    parser.add_argument(
        old,
        action=_Deprecated,
        new=new,
        dest=dest,
        type=type,
        metavar=metavar,
        default=argparse.SUPPRESS,  # the new option's default stands when the old one is not given
        help=argparse.SUPPRESS,
    )


def count(least: int) -> Callable[[str], int]:
    """An argparse type: a whole number of at least ``least``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"must be at least {least}, not {value}")
        return value

    return parse


def time_limit(args: argparse.Namespace) -> float | None:
    """``--time-limit`` of ``args`` (``None``: no limit).

    Raises:
        AlicaError: a limit that is not a positive number of seconds.
    """
    value: float | None = args.time_limit
    if value is not None and not 0 < value < float("inf"):
        raise AlicaError(f"--time-limit must be a positive number of seconds, not {value:g}")
    return value


def check_output(path: str | Path, option: str, *, make_folders: bool) -> None:
    """Check, before anything starts, that the file an option names can be written.

    Args:
        path: the file.
        option: the option that names it, for the message, e.g. ``--trace``.
        make_folders: whether the command creates the missing folders on the way to
            ``path`` (``alica run``); else its folder must exist (``alica agent``).

    Raises:
        AlicaError: the path is a folder, its folder is missing (unless ``make_folders``),
            something on the way is a file, or the place is not writable; the message
            names the file, what is wrong and what to do.
    """
    target = Path(path)
    where = f"{option} {target}"
    if target.is_dir():
        raise AlicaError(f"{where}: is a folder; give a file name, e.g. {target / 'trace.jsonl'}")
    folder = target.parent
    if not make_folders and not folder.is_dir():
        what = f"{folder} is not a folder" if folder.exists() else f"no such folder {folder}"
        raise AlicaError(f"{where}: {what}; create it first (mkdir -p {folder}) or give a file in an existing folder")
    existing = folder
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        raise AlicaError(f"{where}: {existing} is a file, not a folder; give a path whose folders are folders")
    if not os.access(existing, os.W_OK | os.X_OK) or (target.exists() and not os.access(target, os.W_OK)):
        blocked = target if target.exists() else existing
        raise AlicaError(f"{where}: {blocked} is not writable; give a file in a folder you can write to")


def add_field_options(parser: argparse._ActionsContainer) -> None:
    """Add ``--size M``, ``--rocks N`` and ``--samples K``: the lunar field, with the shared defaults.

    The command checks the values (each has its own least number of samples).
    """
    parser.add_argument(
        "--size",
        type=float,
        default=FIELD_SIZE,
        metavar="M",
        help=f"side of the square lunar field in metres (default {FIELD_SIZE:g})",
    )
    parser.add_argument(
        "--rocks", type=int, default=ROCKS, metavar="N", help=f"rocks on the lunar field (default {ROCKS})"
    )
    parser.add_argument(
        "--samples",
        type=int,
        default=SAMPLES,
        metavar="K",
        help=f"drill samples on the lunar field (default {SAMPLES})",
    )


def add_time_limit(
    parser: argparse._ActionsContainer, default: float | None, text: str, *, old: Sequence[str] = ()
) -> None:
    """Add ``--time-limit S`` (stored as ``time_limit``; :func:`time_limit` checks it), with ``old`` spellings
    as deprecated aliases.

    Args:
        parser: the parser or argument group.
        default: seconds; ``None``: no limit.
        text: the help text; it says the default.
        old: former spellings of the option in this command, e.g. ``("--max-time",)``.
    """
    parser.add_argument("--time-limit", type=float, default=default, metavar="S", help=text)
    for spelling in old:
        add_deprecated(parser, spelling, "--time-limit", dest="time_limit", type=float, metavar="S")


def parse_roster(text: str, option: str = "--agents") -> dict[str, str | frozenset[str] | None]:
    """The team of ``NAME[:ROLE],...``: name -> role, capabilities (``NAME:+cap1+cap2``) or ``None`` (no role given).

    Raises:
        AlicaError: a part that is not of that form, a name given twice, or no agent at all.
    """
    agents: dict[str, str | frozenset[str] | None] = {}
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        name, _, role = part.partition(":")
        name, role = name.strip(), role.strip()
        if not name or not _NAME.fullmatch(name):
            raise AlicaError(f"{option}: '{part}' is not NAME or NAME:ROLE (names are letters, digits, '_' and '-')")
        if name in agents:
            raise AlicaError(f"{option}: agent '{name}' is given twice")
        if role.startswith("+"):
            caps = frozenset(c.strip() for c in role.split("+") if c.strip())
            if not caps:
                raise AlicaError(f"{option}: '{part}' names no capabilities; write NAME:+cap1+cap2")
            agents[name] = caps
        else:
            agents[name] = role or None
    if not agents:
        raise AlicaError(f"{option}: give at least one agent, e.g. {option} scout:Scout")
    return agents


def did_you_mean(word: str, choices: Sequence[str]) -> str:
    """``" (did you mean 'x'?)"`` for the closest of ``choices``, or an empty string."""
    import difflib

    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    if not close:
        lowered = {c.lower(): c for c in choices}
        close = [lowered[word.lower()]] if word.lower() in lowered else []
    return f" (did you mean '{close[0]}'?)" if close else ""
