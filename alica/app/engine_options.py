"""Engine settings shared by ``alica run`` and ``alica agent``: the option and its value for the engine."""

from __future__ import annotations

import argparse
from typing import Any

_SWITCH = {"on": True, "off": False}


def add_engine_options(parser: argparse.ArgumentParser) -> None:
    """``--auto-failure-handling on|off``: the C++ engine's ``AutoFailureHandling``."""
    parser.add_argument(
        "--auto-failure-handling",
        choices=tuple(_SWITCH),
        default="on",
        help="on (default): a failed plan that no transition of its parent state handles is retried, replaced "
        "by the next plan of its type, then fails its parent; off: it stays failed until a transition leaves "
        "the state (AutoFailureHandling: false of the C++ ALICA engine)",
    )


def engine_settings(args: argparse.Namespace) -> dict[str, Any]:
    """The :class:`~alica.engine.config.EngineConfig` settings the engine options give."""
    return {"auto_failure_handling": _SWITCH[args.auto_failure_handling]}


def engine_arguments(args: argparse.Namespace) -> list[str]:
    """The engine options again, as arguments for an agent process (``alica run --processes``)."""
    return ["--auto-failure-handling", args.auto_failure_handling]
