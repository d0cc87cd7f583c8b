"""The wheel's package list names every package of the repository, under the import name ``alica``."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]


def _installed_name(folder: Path) -> str:
    """The import name a package folder of the checkout installs as."""
    relative = folder.relative_to(ROOT).parts
    for name, source in CONFIG["package-dir"].items():
        if relative[: len(Path(source).parts)] == Path(source).parts:
            return ".".join((name, *relative[len(Path(source).parts) :]))
    return ".".join(relative)


def test_every_package_folder_is_listed() -> None:
    folders = {
        p.parent for top in ("alica", *CONFIG["package-dir"].values()) for p in (ROOT / top).rglob("__init__.py")
    }
    assert sorted(_installed_name(f) for f in folders) == sorted(CONFIG["packages"])


def test_every_installed_name_is_under_alica() -> None:
    assert all(name == "alica" or name.startswith("alica.") for name in CONFIG["packages"])


def test_every_code_package_ships_py_typed() -> None:
    for name, source in {"alica": "alica", **CONFIG["package-dir"]}.items():
        if name != "alica.plans":
            assert (ROOT / source / "py.typed").is_file(), source
            assert "py.typed" in CONFIG["package-data"][name]
