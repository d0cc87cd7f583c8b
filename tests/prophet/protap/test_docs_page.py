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
    assert len(BLOCKS) == 4
    out = capsys.readouterr().out
    if index in (1, 2):
        assert "Evaluation(" in out
    if index == 3:  # the dispatch loop: the domain's episode, then every first goto failed and sent again
        assert out.splitlines() == [
            "2192.76 True 0",
            "[('goto(r1, x4, y2)', 'goto(r2, x1, y1)'), ('goto(r1, x4, y2)', 'goto(r2, x1, y1)')] 2 True",
        ]
