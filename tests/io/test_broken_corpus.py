"""A corpus of broken plan files, one per kind of error.

Each file says on its first lines what ``alica validate`` must print:
``# expect: LINE:COL message fragment`` (YAML) or ``<!-- expect: LINE:COL fragment -->``
(XML); ``FILE:LINE:COL`` names another file of the set. The test runs the
command on the file and checks exit code 1, the ``FILE:LINE:COL: error:``
line with that fragment, and that no traceback is printed.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from alica.app.cli import main

BROKEN = Path(__file__).parent / "broken"
EXPECT = re.compile(
    r"expect:\s*(?:(?P<file>[\w.]+):)?(?P<line>\d+):(?P<col>\d+)\s*(?P<fragment>.*?)\s*(?:-->)?$", re.MULTILINE
)
CASES = sorted(p for p in BROKEN.iterdir() if "expect-valid" not in p.read_text(encoding="utf-8")[:200])


def test_corpus_covers_every_error_kind() -> None:
    assert len(CASES) >= 25


@pytest.mark.parametrize("path", CASES, ids=lambda p: p.name)
def test_broken_file(path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(BROKEN)
    match = EXPECT.search(path.read_text(encoding="utf-8"))
    assert match, f"{path.name} has no expect line"
    code = main(["validate", path.name])
    out, err = capsys.readouterr()
    assert code == 1, err
    assert "Traceback" not in out + err
    where = f"{match['file'] or path.name}:{match['line']}:{match['col']}: error: "
    lines = [line for line in err.splitlines() if line.startswith(where)]
    assert lines, f"no line starting with {where!r} in:\n{err}"
    assert any(match["fragment"] in line for line in lines), f"{match['fragment']!r} not in {lines}"
    assert any("(fix: " in line for line in lines), "every error says what to do"


def test_imported_file_alone_is_valid(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", os.fspath(BROKEN / "shared_tasks.yaml")]) == 0
