"""Command-line values that happen at a simulated time: ``WHAT@T`` and ``WHAT@T1-T2`` (``--crash r1@5``)."""

from __future__ import annotations

import re
from typing import Any

from alica.errors import AlicaError


def add_fault_options(parser: Any, crash: str, recover: str) -> None:
    """Add the repeatable ``--crash NAME@T`` and ``--recover NAME@T`` options; ``crash``/``recover`` are their help."""
    for option, text in (("--crash", crash), ("--recover", recover)):
        parser.add_argument(option, action="append", default=[], metavar="NAME@T", help=text)


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
