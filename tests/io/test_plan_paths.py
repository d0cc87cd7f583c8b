"""Shipped plans by name (``alica:plans/...``), from any folder; written imports that survive a move."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from alica.app.cli import main
from alica.io import Loader, PlanPathError, import_reference, plan_files, plan_path, plans_dir
from alica.io.plan_paths import project_root, shown

SUSSMAN = "on(c, a) and ontable(a) and ontable(b) and clear(c) and clear(b) and handempty(r)"
OWN_PLAN = """\
imports: [alica:plans/tasks.yaml, alica:plans/roles.yaml, alica:plans/skills/move_to_position.yaml]
plans:
  - name: GoTo
    entry_points: [{task: Default, state: Driving}]
    states:
      - {name: Driving, children: [MoveToPosition]}
"""


@pytest.fixture
def empty(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty working folder outside the checkout, with no plan path set."""
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    folder = tmp_path / "empty"
    folder.mkdir()
    monkeypatch.chdir(folder)
    return folder


def test_validate_every_shipped_plan_by_name_from_an_empty_folder(
    empty: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["validate", "alica:plans"]) == 0, capsys.readouterr().err
    shipped = len(plan_files([plans_dir()])[0])
    assert capsys.readouterr().out == f"ok: {shipped} plan file(s) valid\n"
    assert main(["validate", "alica:plans/lunar/mission.yaml"]) == 0
    assert main(["show", "alica:plans/blocksworld/mission.yaml"]) == 0


@pytest.mark.parametrize("bad", ["alica:", "alica:foo/x.yaml", "alica:plans/../pyproject.toml", "alica:/etc/passwd"])
def test_a_bad_shipped_name_is_a_clear_error(empty: Path, capsys: pytest.CaptureFixture[str], bad: str) -> None:
    with pytest.raises(PlanPathError, match="names no shipped plan: write alica:plans/<path>"):
        plan_path(bad)
    assert main(["validate", bad]) == 1
    err = capsys.readouterr().err
    assert f"{bad}:1:1: error: '{bad}' names no shipped plan" in err and "Traceback" not in err


def test_a_bad_shipped_name_in_an_import_is_reported_at_the_import(empty: Path) -> None:
    (empty / "mine.yaml").write_text("imports: [alica:plans/../../secret.yaml]\ntasks: [T]\n", encoding="utf-8")
    problems = Loader().check(empty / "mine.yaml")[1]
    assert [(d.span.line, d.span.column) for d in problems] == [(1, 11)]
    assert "names no shipped plan" in problems[0].message


def test_own_plan_imports_shipped_plans_by_name(empty: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (empty / "goto.yaml").write_text(OWN_PLAN, encoding="utf-8")
    assert main(["validate", "goto.yaml"]) == 0, capsys.readouterr().err
    # the shipped files it imports are shown by name, never as a path into site-packages
    paths = {d.path for d in Loader().check(empty / "goto.yaml")[0]}
    assert {"goto.yaml", "alica:plans/roles.yaml", "alica:plans/skills/move_to_position.yaml"} <= paths
    assert all(p == "goto.yaml" or p.startswith("alica:plans/") for p in paths)


def test_the_plan_search_path_takes_shipped_names_and_reports_bad_ones(
    empty: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (empty / "lib").mkdir()
    (empty / "lib" / "tasks.yaml").write_text("tasks: [Mine]\n", encoding="utf-8")
    (empty / "app").mkdir()
    (empty / "app" / "roles.yaml").write_text(
        "imports: [../lib/tasks.yaml]\nrolesets:\n  - {name: R, roles: [{name: A, priorities: {Mine: 1}}]}\n",
        encoding="utf-8",
    )
    assert main(["validate", "app/roles.yaml"]) == 1
    assert "outside the plan folders" in capsys.readouterr().err
    monkeypatch.setenv("ALICA_PLAN_PATH", os.pathsep.join(["alica:plans", str(empty / "lib")]))
    assert main(["validate", "app/roles.yaml"]) == 0
    monkeypatch.setenv("ALICA_PLAN_PATH", "alica:nowhere")
    assert main(["validate", "app/roles.yaml"]) == 1
    assert "alica: error: ALICA_PLAN_PATH: 'alica:nowhere' names no shipped plan" in capsys.readouterr().err


def test_the_working_folder_does_not_decide_what_validates(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    (tmp_path / "p" / "sub").mkdir(parents=True)
    (tmp_path / "p" / "tasks.yaml").write_text("tasks: [T]\n", encoding="utf-8")
    entry = tmp_path / "p" / "sub" / "roles.yaml"
    entry.write_text(
        "imports: [../tasks.yaml]\nrolesets:\n  - {name: R, roles: [{name: A, priorities: {T: 1}}]}\n",
        encoding="utf-8",
    )
    verdicts = set()
    for here in (tmp_path, tmp_path / "p", tmp_path / "p" / "sub"):
        monkeypatch.chdir(here)
        verdicts.add(bool(Loader().check(entry)[1]))
    assert verdicts == {True}  # refused wherever one stands: no marker, so no project
    (tmp_path / "p" / ".alica-project").write_text("", encoding="utf-8")
    assert project_root(entry) == (tmp_path / "p").resolve()
    for here in (tmp_path, tmp_path / "p", tmp_path / "p" / "sub"):
        monkeypatch.chdir(here)
        assert Loader().check(entry)[1] == []


def test_written_imports_name_shipped_plans_by_name_and_own_files_relatively(tmp_path: Path) -> None:
    out = tmp_path / "build"
    assert import_reference(plans_dir() / "tasks.yaml", out) == "alica:plans/tasks.yaml"
    assert import_reference("alica:plans/skills/pickup.yaml", out) == "alica:plans/skills/pickup.yaml"
    assert import_reference(tmp_path / "mine" / "x.yaml", out) == "../mine/x.yaml"
    # a file written among the shipped plans keeps relative imports to them
    assert import_reference(plans_dir() / "tasks.yaml", plans_dir() / "lunar") == "../tasks.yaml"
    assert shown(plans_dir() / "roles.yaml") in {"alica:plans/roles.yaml", os.path.relpath(plans_dir() / "roles.yaml")}


def test_emit_plan_writes_imports_that_survive_a_move(empty: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = empty / "build" / "stack.yaml"
    code = main(["plan", "alica:plans/blocksworld/mission.yaml", "--world", SUSSMAN, "--emit-plan", str(out)])
    assert code == 0, capsys.readouterr().err
    text = out.read_text(encoding="utf-8")
    assert "alica:plans/blocksworld/mission.yaml" in text and "site-packages" not in text and ".." not in text
    moved = empty / "elsewhere" / "deep"
    moved.mkdir(parents=True)
    (moved / "stack.yaml").write_text(text, encoding="utf-8")
    assert main(["validate", str(moved / "stack.yaml")]) == 0, capsys.readouterr().err
