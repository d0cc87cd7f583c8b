"""The example in docs/motion.md runs and prints what the page says."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[2] / "docs" / "motion.md"


def test_motion_page_example(capsys: pytest.CaptureFixture[str]) -> None:
    [example] = re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.DOTALL)
    exec(compile(example, str(PAGE.name), "exec"), {})
    assert capsys.readouterr().out.splitlines() == ["exact True", "True True"]


def test_package_docstring_example() -> None:
    import doctest

    import alica.skills.motion
    import alica.worldsim.grid

    for module in (alica.skills.motion, alica.worldsim.grid):
        assert doctest.testmod(module).failed == 0
