"""The Python examples of the ProTaP guide (docs/protap.md) run."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[3] / "docs" / "protap.md"
BLOCKS = re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.DOTALL)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_the_guide_examples_run(index: int, capsys: pytest.CaptureFixture[str]) -> None:
    exec(compile(BLOCKS[index], f"{PAGE.name}[{index}]", "exec"), {})
    assert len(BLOCKS) == 3
    if index in (1, 2):
        assert "Evaluation(" in capsys.readouterr().out
