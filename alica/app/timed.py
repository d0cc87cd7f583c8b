"""Command-line values that happen at a simulated time: ``WHAT@T`` and ``WHAT@T1-T2`` (``--crash r1@5``)."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from alica.errors import AlicaError

if TYPE_CHECKING:
    import argparse


def add_fault_options(parser: argparse._ActionsContainer, crash: str, recover: str) -> None:
    """Add the repeatable ``--crash NAME@T`` and ``--recover NAME@T`` options; ``crash``/``recover`` are their help."""
    for option, text in (("--crash", crash), ("--recover", recover)):
        parser.add_argument(option, action="append", default=[], metavar="NAME@T", help=text)


def add_network_options(parser: argparse._ActionsContainer) -> None:
    """Add ``--loss P``, ``--delay MS`` and the repeatable ``--partition A,B|C@T1-T2`` (the simulated network's faults)."""
    parser.add_argument(
        "--loss",
        type=float,
        default=0.0,
        metavar="P",
        help="probability that a best-effort message is lost (default 0)",
    )
    parser.add_argument(
        "--delay", type=float, default=0.0, metavar="MS", help="message delay in milliseconds (default 0)"
    )
    parser.add_argument(
        "--partition",
        action="append",
        default=[],
        metavar="A,B|C@T1-T2",
        help="cut the network between groups from T1 to T2, or for good without -T2 (repeatable)",
    )


def partition(text: str) -> tuple[list[list[str]], float, float | None]:
    """``A,B|C@T1-T2`` as ``([[A, B], [C]], T1, T2)`` (``T2`` None: for good).

    Raises:
        AlicaError: ``text`` is not of that form.
    """
    what, start, end = timed("--partition", text, span=True)
    return [group.split(",") for group in what.split("|")], start, end


_AT = re.compile(r"^(?P<what>.+)@(?P<start>[0-9.]+)(?:-(?P<end>[0-9.]+))?$")


def timed(option: str, text: str, span: bool = False) -> tuple[str, float, float | None]:
    """``WHAT@T`` as ``(WHAT, T, None)``; with ``span``, ``WHAT@T1-T2`` as ``(WHAT, T1, T2)`` too.

    Raises:
        AlicaError: ``text`` is not of that form (the message names ``option``).
    """
    match = _AT.match(text.strip())
    if match is None or (match.group("end") is not None and not span):
        form = "WHAT@T1-T2" if span else "WHAT@T"
        raise AlicaError(f"{option}: '{text}' is not of the form {form} (T in simulated seconds)")
    try:
        start = float(match.group("start"))
        end = float(match.group("end")) if match.group("end") else None
    except ValueError:
        form = "WHAT@T1-T2" if span else "WHAT@T"
        raise AlicaError(f"{option}: '{text}' is not of the form {form} (T in simulated seconds)") from None
    return match.group("what").strip(), start, end
