"""Lay out the checkout's packages by their installed names, as links, for tools that read folders.

The repository keeps one folder per layer (``alica/``, ``prophet/``,
``skills/``, ``worldsim/``, ``plans/``) while they install under the one import
name ``alica`` (``alica.prophet``, ...; see ``[tool.setuptools]`` in
``pyproject.toml``). mypy, import-linter and mkdocstrings read packages from
folders, so :func:`stage` links every source file into a folder by its
installed name (``alica/skills/...`` for ``skills/...``).
"""

from __future__ import annotations

import os
import shutil
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SUFFIXES = {".py", ".pyi", ".typed"}


def package_dirs(root: Path = ROOT) -> dict[str, str]:
    """Installed package name -> checkout folder, for every package with Python code."""
    config = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    dirs: dict[str, str] = config.get("package-dir", {})
    return {"alica": "alica", **{name: src for name, src in dirs.items() if name != "alica.plans"}}


def stage(target: Path, root: Path = ROOT) -> dict[str, str]:
    """Link every source file under ``target`` by its installed name.

    Returns:
        The staged folder -> checkout folder map (``alica/skills/`` -> ``skills/``), longest first,
        to turn the tools' messages back into the checkout's paths.
    """
    shutil.rmtree(target, ignore_errors=True)
    mapping: dict[str, str] = {}
    for name, source in package_dirs(root).items():
        base = target.joinpath(*name.split("."))
        mapping[base.relative_to(target).as_posix() + "/"] = source + "/"
        for path in (root / source).rglob("*"):
            if "__pycache__" in path.parts or path.is_dir() or path.suffix not in SUFFIXES:
                continue
            link = base / path.relative_to(root / source)
            link.parent.mkdir(parents=True, exist_ok=True)
            os.symlink(path, link)
    return dict(sorted(mapping.items(), key=lambda item: -len(item[0])))
