"""The quality gates of ``make test``: ruff (lint and format), mypy, import-linter.

The repository keeps one folder per layer (``alica/``, ``prophet/``,
``skills/``, ``worldsim/``, ``plans/``) while they install under the one
import name ``alica`` (``alica.prophet``, ...; see ``[tool.setuptools]`` in
``pyproject.toml``). mypy and import-linter read packages from folders, so
this script first lays out the installed tree as links under
``build/typecheck/`` and points both tools at it; their messages name the
checkout's own files again.

Usage: ``python tools/quality.py`` (exit 0 when every gate passes).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STAGE = ROOT / "build" / "typecheck"
BIN = Path(sys.executable).parent


def _package_dirs() -> dict[str, str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    dirs: dict[str, str] = config.get("package-dir", {})
    return {"alica": "alica", **{k: v for k, v in dirs.items() if k != "alica.plans"}}


def stage() -> dict[str, str]:
    """Link every source file into ``build/typecheck`` by its installed name; the staged -> checkout folder map."""
    shutil.rmtree(STAGE, ignore_errors=True)
    mapping: dict[str, str] = {}
    for name, source in _package_dirs().items():
        target = STAGE.joinpath(*name.split("."))
        mapping[target.relative_to(STAGE).as_posix() + "/"] = source + "/"
        for path in (ROOT / source).rglob("*"):
            if "__pycache__" in path.parts or path.is_dir() or path.suffix not in {".py", ".pyi", ".typed"}:
                continue
            link = target / path.relative_to(ROOT / source)
            link.parent.mkdir(parents=True, exist_ok=True)
            os.symlink(path, link)
    # the longest prefix first: alica/skills/ before alica/
    return dict(sorted(mapping.items(), key=lambda item: -len(item[0])))


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
    mapping = stage()
    config = str(ROOT / "pyproject.toml")
    ok &= _run("mypy", [str(BIN / "mypy"), "--config-file", config, "-p", "alica"], STAGE, mapping)
    ok &= _run("import-linter", [str(BIN / "lint-imports"), config], STAGE, mapping)
    print("quality gates: " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
