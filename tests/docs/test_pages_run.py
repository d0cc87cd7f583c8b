"""The quickstart, the tutorial and the README's plan example run as written, in an empty folder,
against the library installed from a wheel; every output a page shows must match what it prints."""

from __future__ import annotations

import difflib
from pathlib import Path

import pytest

from tests.docs.conftest import ROOT, Installed
from tests.docs.pages import blocks, pattern, steps, write_files

PAGES = ["docs/quickstart.md", "docs/tutorial_skill.md"]


@pytest.fixture
def empty(tmp_path: Path) -> Path:
    folder = tmp_path / "work"
    folder.mkdir()
    return folder


def test_the_installed_command_is_the_wheels(installed: Installed, empty: Path) -> None:
    done = installed.run("alica validate alica:plans && python -c 'import alica; print(alica.__file__)'", empty)
    assert done.returncode == 0, done.stdout
    assert done.stdout.startswith("ok: ") and str(installed.bin.parent) in done.stdout.splitlines()[-1]


@pytest.mark.parametrize("page", PAGES)
def test_a_page_runs_as_written(installed: Installed, empty: Path, page: str) -> None:
    text = (ROOT / page).read_text(encoding="utf-8")
    write_files(text, empty)
    problems = []
    for step in steps(text):
        done = installed.run(step.script, empty)
        if step.output is not None and not pattern(step.output).fullmatch(done.stdout):
            diff = "\n".join(
                difflib.unified_diff(
                    step.output.splitlines(), done.stdout.splitlines(), "shown", "printed", lineterm=""
                )
            )
            problems.append(f"$ {step.script}\n{diff}")
        elif (done.returncode != 0) != step.expects_failure:
            problems.append(f"$ {step.script}\nexited {done.returncode}:\n{done.stdout}")
    assert not problems, f"{page} drifted from what it shows:\n\n" + "\n\n".join(problems)


def test_the_readme_plan_example_validates_in_an_empty_folder(installed: Installed, empty: Path) -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    example = next(b.text for b in blocks(readme) if b.language == "yaml")
    (empty / "fetch_sample.yaml").write_text(example, encoding="utf-8")
    done = installed.run("alica validate fetch_sample.yaml", empty)
    assert (done.returncode, done.stdout) == (0, "ok: 1 plan file(s) valid\n")


def test_the_pattern_of_a_shown_output_can_fail() -> None:
    shown = "ok: ~3.5 s\n...\nend\n"
    assert pattern(shown).fullmatch("ok: 12 s\nmore\nlines\nend\n")
    assert not pattern(shown).fullmatch("ok: 12 s wall\nend\n")
    assert not pattern(shown).fullmatch("ok: fast\nend\n")
    assert not pattern("a\nb\n").fullmatch("a\nc\n")
