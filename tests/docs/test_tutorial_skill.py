"""The tutorial docs/tutorial_skill.md: what its example is, and that its test can fail.

Its commands run, with their outputs compared, in ``test_pages_run.py`` (against the
installed library); here: the example stays within its line budget, the page runs each
command it explains, and the page's unit test passes, and fails when the skill turns
the wrong way.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
from pathlib import Path

from tests.docs.pages import blocks, example_files, steps, write_files

ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "tutorial_skill.md").read_text(encoding="utf-8")
BUDGET = 60
PYTEST_TIMEOUT = 300  # seconds of wall time for one pytest run of the page's test


def test_the_example_is_three_files_within_the_line_budget() -> None:
    files = example_files(PAGE)
    assert sorted(files) == ["my_skills.py", "plans/face.yaml", "test_face.py"]
    lines = sum(len(text.splitlines()) for text in files.values())
    assert lines <= BUDGET
    assert f"{lines} lines in all" in PAGE, "the page states the example's length"


def test_the_page_runs_every_command_it_explains() -> None:
    commands = [step.script.strip() for step in steps(PAGE) if step.script.startswith("alica ")]
    ran = [shlex.split(command)[1:3] for command in commands]
    for verb in (["validate"], ["list-skills"], ["skill", "run"], ["run"]):
        assert any(argv[: len(verb)] == verb for argv in ran), verb
    assert all("--skills" in command for command in commands if not command.startswith("alica validate"))


def pytest_run(folder: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_face.py"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=PYTEST_TIMEOUT,
        check=False,
    )


def test_the_unit_test_passes_and_catches_a_broken_skill(tmp_path: Path) -> None:
    folder = tmp_path
    write_files(PAGE, folder)
    assert "python -m pytest -q test_face.py" in [b.text.strip() for b in blocks(PAGE) if b.language == "sh"]
    done = pytest_run(folder)
    assert done.returncode == 0 and "1 passed" in done.stdout, done.stdout + done.stderr
    skill = folder / "my_skills.py"
    source = skill.read_text(encoding="utf-8")
    assert source.count(", error))") == 1
    skill.write_text(source.replace(", error))", ", -error))"), encoding="utf-8")  # turn the wrong way
    done = pytest_run(folder)
    assert done.returncode == 1 and "1 failed" in done.stdout, done.stdout + done.stderr
