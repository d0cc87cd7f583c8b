"""The example at the top of docs/manipulation.md runs and prints what the page says."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "manipulation.md"


def test_docs_example(capsys: pytest.CaptureFixture[str]) -> None:
    code = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.DOTALL)[0]
    exec(compile(code, str(DOC), "exec"), {})
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("True")]
    assert lines[0] == "True ok [2, 4, 5]"
    assert lines[1] == "True [0.45, 0.2, 0.075]"
