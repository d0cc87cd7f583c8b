"""mkdocs hook: lay out the packages by their installed names for the API reference.

The repository keeps one folder per layer (``alica/``, ``prophet/``,
``skills/``, ``worldsim/``) while they install under the one import name
``alica`` (see ``[tool.setuptools]`` in ``pyproject.toml``). mkdocstrings reads
packages from folders, so before each build this hook links every source file
into ``build/docs-api/`` by its installed name (``alica/skills/...`` for
``skills/...``); ``mkdocs.yml`` points the python handler's ``paths`` there.

The folder is the hook's own, so a build never races ``make check``, which lays
out ``build/typecheck/`` the same way.
"""

from __future__ import annotations

import os
import re
import shutil
import tomllib
from pathlib import Path
from typing import Any

import griffe
from mkdocs.plugins import event_priority

ROOT = Path(__file__).resolve().parents[1]
STAGE = ROOT / "build" / "docs-api"
SUFFIXES = {".py", ".pyi", ".typed"}


def package_dirs(root: Path = ROOT) -> dict[str, str]:
    """Installed package name -> checkout folder, for every package with Python code."""
    config = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    dirs: dict[str, str] = config.get("package-dir", {})
    return {"alica": "alica", **{name: src for name, src in dirs.items() if name != "alica.plans"}}


def stage(root: Path = ROOT, target: Path = STAGE) -> Path:
    """Link every source file under ``target`` by its installed name; return ``target``."""
    shutil.rmtree(target, ignore_errors=True)
    for name, source in package_dirs(root).items():
        base = target.joinpath(*name.split("."))
        for path in (root / source).rglob("*"):
            if "__pycache__" in path.parts or path.is_dir() or path.suffix not in SUFFIXES:
                continue
            link = base / path.relative_to(root / source)
            link.parent.mkdir(parents=True, exist_ok=True)
            os.symlink(path, link)
    return target


@event_priority(100)  # before mkdocstrings sets up its handler
def on_config(config: Any) -> Any:
    """mkdocs event: stage the sources before any plugin reads them."""
    stage()
    return config


ROLE = re.compile(r":(?:class|func|meth|attr|mod|data|exc|obj):`~?([^`]+)`")


class SphinxRoles(griffe.Extension):
    """griffe extension: show Sphinx roles of docstrings (``:class:`~a.B```) as code (`` `B` ``).

    The docstrings are written for Python's ``help()`` and for Sphinx-style
    readers; Markdown would print the role markup literally.
    """

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(_code, obj.docstring.value)


def _code(match: re.Match[str]) -> str:
    target = match.group(1)
    shown = target.rsplit(".", 1)[-1] if match.group(0).split("`", 1)[1].startswith("~") else target
    return f"`{shown}`"
