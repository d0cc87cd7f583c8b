"""Where the bench scripts read the standard benchmark sets (IPC PDDL): in place, never copied into the repository.

The folder holds ``pddl/`` (blocks, rovers) and ``ipc/`` (the 26 IPC domains). It is ``--benchmarks DIR`` when a
script is given it, else the environment variable ``ALICA_BENCHMARKS``, else ``../shared/benchmarks`` beside the
checkout (the tests follow the same rule, ``tests/conftest.py``).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VARIABLE = "ALICA_BENCHMARKS"


def default_benchmarks() -> Path:
    """``$ALICA_BENCHMARKS`` if set, else ``../shared/benchmarks`` beside the checkout."""
    value = os.environ.get(VARIABLE, "")
    return Path(value).expanduser() if value else ROOT / ".." / "shared" / "benchmarks"


def add_benchmarks_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--benchmarks DIR`` (a :class:`~pathlib.Path`; default :func:`default_benchmarks`) to ``parser``."""
    parser.add_argument(
        "--benchmarks",
        type=Path,
        default=default_benchmarks(),
        metavar="DIR",
        help=f"the folder holding the benchmark sets pddl/ and ipc/, read in place "
        f"(default: ${VARIABLE}, else ../shared/benchmarks beside the checkout)",
    )


def benchmark_set(folder: Path, name: str) -> Path:
    """``folder / name`` (``"pddl"`` or ``"ipc"``); exits with a message naming the folder when it is missing."""
    path = folder / name
    if not path.is_dir():
        raise SystemExit(
            f"error: the benchmark sets are read in place from {folder.resolve()} and {name}/ is not there: "
            f"put ../shared beside the checkout, set {VARIABLE} or pass --benchmarks DIR"
        )
    return path
