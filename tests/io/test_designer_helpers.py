"""Helpers shared by the designer import tests (no tests here): where the C++ engine's designer files are."""

from __future__ import annotations

import json
from pathlib import Path

import yaml

#: The ALICA Plan Designer files of the C++ engine's test suite (read in place, never copied).
DESIGNER = Path(__file__).resolve().parents[2] / ".." / "shared" / "reference" / "alica_designer"


def designer_folder() -> Path:
    """The shared designer folder, read in place (CI has ../shared beside the checkout)."""
    assert (DESIGNER / "plans").is_dir(), (
        f"the ALICA designer test files are not at {DESIGNER}: put ../shared beside the checkout"
    )
    return DESIGNER.resolve()


def data(path: Path) -> dict[str, object]:
    """An output file's YAML as plain data."""
    loaded = yaml.safe_load(path.read_text(encoding="utf-8"))
    assert isinstance(loaded, dict)
    return loaded


def write_json(folder: Path, rel: str, value: object) -> Path:
    """Write ``value`` as JSON at ``folder/rel``."""
    path = folder / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value, indent=2), encoding="utf-8")
    return path
