"""The example in docs/comm.md runs and prints what the page says."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[2] / "docs" / "comm.md"


def test_comm_page_example(capsys: pytest.CaptureFixture[str]) -> None:
    [example] = re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.DOTALL)
    exec(compile(example, str(PAGE.name), "exec"), {})
    assert capsys.readouterr().out.splitlines() == ["a 1 ('Mission', 'Explore')", "frozenset({'a'})"]
