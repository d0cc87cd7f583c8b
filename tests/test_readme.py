"""The README's examples run and say what the README says."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from alica.io import validate_paths
from tests.conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, re.DOTALL)


def test_readme_starts_with_the_two_commands() -> None:
    first = _blocks("sh")[0]
    assert first.splitlines()[0].startswith("make demo") and first.splitlines()[1].startswith("make test")


def test_readme_plan_example_is_valid_in_an_empty_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    monkeypatch.chdir(tmp_path)
    example = tmp_path / "fetch_sample.yaml"  # it imports the shipped plans by name
    example.write_text(_blocks("yaml")[0], encoding="utf-8")
    problems = validate_paths([example])
    assert not problems, [p.format() for p in problems]


def test_readme_python_example(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)
    exec(compile(_blocks("python")[2], "README.md", "exec"), {})
    assert capsys.readouterr().out.strip() == "True"


def test_readme_team_example(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)
    exec(compile(_blocks("python")[0], "README.md", "exec"), {})
    assert capsys.readouterr().out.strip() == "Explore"


def test_readme_skill_example(monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)
    exec(compile(_blocks("python")[1], "README.md", "exec"), {})
    assert capfd.readouterr().out.strip().splitlines()[-1] == "success"


def test_readme_planning_example(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)
    exec(compile(_blocks("python")[3], "README.md", "exec"), {})
    assert capsys.readouterr().out.splitlines() == [
        "Unstack(c, a), Putdown(c)",
        "Pickup(b), Stack(b, c)",
        "Pickup(a), Stack(a, b)",
    ]
