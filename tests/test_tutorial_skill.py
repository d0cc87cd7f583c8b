"""The tutorial docs/tutorial_skill.md works as written.

Its example files are the page's code blocks whose title names the file
(```` ```python title="my_skills.py" ````; a title ``my_skills.py
(continued)`` appends to the file, after two blank lines). They are
written to a fresh folder, every ``alica`` command of the page runs there
through :func:`alica.app.cli.main` and must print what the page shows after
it (a ``...`` line stands for any lines), and the page's unit test runs with
pytest in a subprocess: it passes, and fails when the skill turns the wrong
way.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from collections.abc import Iterator
from itertools import pairwise
from pathlib import Path

import pytest

from alica.app.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "tutorial_skill.md").read_text(encoding="utf-8")
BLOCK = re.compile(r"^```(\w*)([^\n]*)\n(.*?)^```\s*$", re.DOTALL | re.MULTILINE)
TITLE = re.compile(r'title="(\S+\.(?:py|yaml))( \(continued\))?"')
BUDGET = 60
PYTEST_TIMEOUT = 300  # seconds of wall time for one pytest run of the page's test


def blocks() -> list[tuple[str, str, str]]:
    """The page's fenced code blocks as ``(language, attributes, text)``, in order."""
    return [(lang, attributes.strip(), text) for lang, attributes, text in BLOCK.findall(PAGE)]


def example_files() -> dict[str, str]:
    """The example files by relative path, as the page builds them."""
    files: dict[str, str] = {}
    for _, attributes, text in blocks():
        found = TITLE.fullmatch(attributes)
        if found is None:
            continue
        name, continued = found.groups()
        if continued:
            assert name in files, f"'{attributes}' continues a file the page has not started"
            files[name] += "\n\n" + text
        else:
            assert name not in files, f"the page starts {name} twice"
            files[name] = text
    return files


def commands() -> list[tuple[str, str]]:
    """Each ``alica`` command of the page with the output the page shows after it."""
    found = []
    for (lang, _, text), (next_lang, _, output) in pairwise(blocks()):
        if lang == "sh" and text.startswith("alica ") and next_lang == "text":
            assert text.count("\n") == 1, f"one command per block: {text!r}"
            found.append((text.strip(), output))
    return found


def shown(output: str) -> re.Pattern[str]:
    """A pattern for the output a page shows: its lines exactly, ``...`` for any lines."""
    parts = [r"(?:.*\n)*?" if line == "..." else re.escape(line) + r"\n" for line in output.splitlines()]
    return re.compile("".join(parts))


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A user's folder holding the example files; the working folder for the test."""
    for name, text in example_files().items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))
    yield tmp_path
    sys.modules.pop("my_skills", None)


def test_the_example_is_three_files_within_the_line_budget() -> None:
    files = example_files()
    assert sorted(files) == ["my_skills.py", "plans/face.yaml", "test_face.py"]
    lines = sum(len(text.splitlines()) for text in files.values())
    assert lines <= BUDGET
    assert f"{lines} lines in all" in PAGE, "the page states the example's length"


def test_the_page_runs_every_command_it_explains() -> None:
    ran = [shlex.split(command)[1:3] for command, _ in commands()]
    for verb in (["validate"], ["list-skills"], ["skill", "run"], ["run"]):
        assert any(argv[: len(verb)] == verb for argv in ran), verb
    assert all("--skills" in command for command, _ in commands() if not command.startswith("alica validate"))


@pytest.mark.parametrize("command, output", commands(), ids=[c for c, _ in commands()])
def test_a_command_prints_what_the_page_shows(
    folder: Path, capsys: pytest.CaptureFixture[str], command: str, output: str
) -> None:
    code = main(shlex.split(command)[1:])
    out, err = capsys.readouterr()
    printed = out + err
    assert "Traceback" not in printed
    assert shown(output).fullmatch(printed), f"{command} printed:\n{printed}"
    failing = re.search(r"\berror\b|: failure after", output) is not None
    assert (code != 0) == failing, f"{command} exited {code}"


def pytest_run(folder: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_face.py"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=PYTEST_TIMEOUT,
        check=False,
    )


def test_the_unit_test_passes_and_catches_a_broken_skill(folder: Path) -> None:
    assert "python -m pytest -q test_face.py" in [text.strip() for lang, _, text in blocks() if lang == "sh"]
    done = pytest_run(folder)
    assert done.returncode == 0 and "1 passed" in done.stdout, done.stdout + done.stderr
    skill = folder / "my_skills.py"
    source = skill.read_text(encoding="utf-8")
    assert source.count(", error))") == 1
    skill.write_text(source.replace(", error))", ", -error))"), encoding="utf-8")  # turn the wrong way
    done = pytest_run(folder)
    assert done.returncode == 1 and "1 failed" in done.stdout, done.stdout + done.stderr
