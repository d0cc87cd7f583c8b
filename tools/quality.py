"""The quality gates of ``make test``: ruff (lint and format), mypy, import-linter.

mypy and import-linter read packages from folders, so this script first lays
out the installed tree as links under ``build/typecheck/`` (:mod:`layout`) and
points both tools at it; their messages name the checkout's own files again.

Usage: ``python tools/quality.py`` (exit 0 when every gate passes).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from layout import ROOT, stage

STAGE = ROOT / "build" / "typecheck"
BIN = Path(sys.executable).parent


def _run(title: str, argv: list[str], cwd: Path, mapping: dict[str, str] | None = None) -> bool:
    print(f"== {title}", flush=True)
    done = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, check=False)
    output = done.stdout + done.stderr
    if mapping:
        pattern = re.compile(r"(?<![\w/.])(" + "|".join(re.escape(k) for k in mapping) + ")")
        output = pattern.sub(lambda m: mapping[m.group(1)], output)
    sys.stdout.write(output)
    return done.returncode == 0


def main() -> int:
    ok = _run("ruff check", [str(BIN / "ruff"), "check", "."], ROOT)
    ok &= _run("ruff format --check", [str(BIN / "ruff"), "format", "--check", "."], ROOT)
    mapping = stage(STAGE)
    config = str(ROOT / "pyproject.toml")
    ok &= _run("mypy", [str(BIN / "mypy"), "--config-file", config, "-p", "alica"], STAGE, mapping)
    ok &= _run("import-linter", [str(BIN / "lint-imports"), config], STAGE, mapping)
    print("quality gates: " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
