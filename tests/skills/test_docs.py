"""The examples of docs/skills.md run and print what the page says."""

from __future__ import annotations

import re

from tests.conftest import ROOT

PAGE = (ROOT / "docs" / "skills.md").read_text(encoding="utf-8")


def test_the_python_example_runs(capfd):
    block = re.findall(r"```python\n(.*?)```", PAGE, re.DOTALL)[0]
    exec(compile(block, "docs/skills.md", "exec"), {})
    lines = [line for line in capfd.readouterr().out.splitlines() if not line.startswith("argv")]
    assert lines == ["success done after 1 attempt(s)", "True"]


def test_the_pytest_example_passes(blocks_world, skill_run):
    block = re.findall(r"```python\n(.*?)```", PAGE, re.DOTALL)[1]
    scope: dict[str, object] = {}
    exec(compile(block, "docs/skills.md", "exec"), scope)
    scope["test_pickup_fails_after_the_retry_budget"](blocks_world, skill_run)
