"""Broken designer folders: located errors, the other files still imported, exit codes and the --json report."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.io import Loader, validate_paths
from alica.io.designer import import_designer, write_result
from tests.io.test_designer_helpers import write_json

TASKS = {"id": 10, "name": "taskrepository", "tasks": [{"id": 11, "name": "Default"}, {"id": 12, "name": "Help"}]}
CONDITIONS = {
    "id": 20,
    "name": "ConditionRepository",
    "conditions": [
        {"id": 21, "name": "Done", "libraryName": "my-robots", "blackboard": []},
        {"id": 22, "name": "AnyChildSuccess", "libraryName": "alica_standard_library", "blackboard": []},
    ],
}


def behaviour(ident: int, name: str) -> dict[str, object]:
    return {"id": ident, "name": name, "frequency": 10, "blackboard": [], "variables": []}


def plan(
    ident: int, name: str, children: list[str], condition: str | None = "ConditionRepository.cnd#21"
) -> dict[str, object]:
    """A plan with one entry point: state Run (the children) and a transition to the success state Done."""
    run, done, ep, t = ident + 1, ident + 2, ident + 3, ident + 4
    return {
        "id": ident,
        "name": name,
        "utilityThreshold": 0.1,
        "entryPoints": [
            {
                "id": ep,
                "name": "",
                "task": "taskrepository.tsk#11",
                "state": run,
                "minCardinality": 0,
                "maxCardinality": 2147483647,
                "successRequired": True,
            }
        ],
        "states": [
            {
                "id": run,
                "name": "Run",
                "type": "State",
                "confAbstractPlanWrappers": [
                    {
                        "id": ident + 10 + i,
                        "abstractPlan": c,
                        "configuration": None,
                        "keyMapping": {"input": [], "output": []},
                    }
                    for i, c in enumerate(children)
                ],
                "variableBindings": [],
                "outTransitions": [t],
            },
            {"id": done, "name": "Done", "type": "TerminalState", "success": True, "confAbstractPlanWrappers": []},
        ],
        "transitions": [
            {
                "id": t,
                "name": "",
                "inState": run,
                "outState": done,
                "condition": condition,
                "keyMapping": {"input": [], "output": []},
                "synchronisation": None,
            }
        ],
        "synchronisations": [],
        "variables": [],
    }


def folder(root: Path, plans: dict[str, dict[str, object]]) -> Path:
    """A designer folder: tasks, conditions, the behaviour Work, and ``plans`` (file name -> plan)."""
    src = root / "etc"
    write_json(src, "tasks/taskrepository.tsk", TASKS)
    write_json(src, "conditions/ConditionRepository.cnd", CONDITIONS)
    write_json(src, "behaviours/Work.beh", behaviour(30, "Work"))
    for name, value in plans.items():
        write_json(src, f"plans/{name}", value)
    return src


def run(src: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict[str, list[dict[str, object]]]]:
    code = main(["import-designer", str(src), "--out", str(out), "--json"])
    report = json.loads(capsys.readouterr().out)
    return code, report


def validates(out: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("ALICA_PLAN_PATH", str(out))
    code = main(["validate", str(out)])
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()


def test_a_clean_folder_imports_and_validates(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Work.beh#30"])})
    code, report = run(src, tmp_path / "out", capsys)
    assert code == 0 and report["errors"] == []
    assert report["written"] == [
        "behaviours/Work.yaml",
        "conditions/ConditionRepository.yaml",
        "plans/Top.yaml",
        "skills.yaml",
        "tasks/taskrepository.yaml",
    ]
    validates(tmp_path / "out", monkeypatch, capsys)


def test_bad_json_is_an_error_with_its_line_and_the_rest_is_imported(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Work.beh#30"])})
    (src / "plans" / "Broken.pml").write_text(
        '{\n  "id": 1,\n  "name": "Broken",\n  "states": [,]\n}\n', encoding="utf-8"
    )
    code, report = run(src, tmp_path / "out", capsys)
    assert code == 1
    (error,) = report["errors"]
    assert error["file"] == "plans/Broken.pml" and error["line"] == 4 and error["column"] == 14
    assert str(error["message"]).startswith("bad JSON: ")
    assert "plans/Top.yaml" in report["written"] and "plans/Broken.yaml" not in report["written"]
    validates(tmp_path / "out", monkeypatch, capsys)


def test_a_reference_to_nothing_refuses_its_file_and_the_parent_drops_the_child(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    src = folder(
        tmp_path,
        {
            "Child.pml": plan(200, "Child", ["Work.beh#30", "Nope.beh#999"]),
            "Top.pml": plan(100, "Top", ["Child.pml#200", "Work.beh#30"]),
        },
    )
    code, report = run(src, tmp_path / "out", capsys)
    assert code == 1
    (error,) = report["errors"]
    assert error == {
        "file": "plans/Child.pml",
        "key": "states[0].confAbstractPlanWrappers[1].abstractPlan",
        "message": "'Nope.beh#999' refers to nothing",
    }
    assert "plans/Child.yaml" not in report["written"] and "plans/Top.yaml" in report["written"]
    dropped = [n for n in report["notes"] if n["construct"] == "dropped reference"]
    assert dropped == [
        {
            "file": "plans/Top.pml",
            "key": "states[0].confAbstractPlanWrappers[0].abstractPlan",
            "construct": "dropped reference",
            "message": "child 'Child.pml#200' of state 'Run' of plan 'Top' is left out: its file was refused (see the errors)",
        }
    ]
    validates(tmp_path / "out", monkeypatch, capsys)


def test_a_cycle_is_an_error_of_the_file_that_closes_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    src = folder(
        tmp_path,
        {"A.pml": plan(100, "A", ["B.pml#200"]), "B.pml": plan(200, "B", ["A.pml#100", "Work.beh#30"])},
    )
    code, report = run(src, tmp_path / "out", capsys)
    assert code == 1
    (error,) = report["errors"]
    assert error["file"] == "plans/B.pml" and error["key"] == "states[0].confAbstractPlanWrappers[0].abstractPlan"
    assert error["message"] == "'A.pml#100' closes a cycle in the plan tree: plans/A.pml -> plans/B.pml -> plans/A.pml"
    assert "plans/A.yaml" in report["written"]
    validates(tmp_path / "out", monkeypatch, capsys)


def test_a_refused_task_repository_refuses_the_plans_that_need_its_tasks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Work.beh#30"])})
    (src / "tasks" / "taskrepository.tsk").write_text("{", encoding="utf-8")
    code, report = run(src, tmp_path / "out", capsys)
    assert code == 1
    files = {(e["file"], e["key"]) for e in report["errors"]}
    assert ("plans/Top.pml", "entryPoints[0].task") in files
    assert report["written"] == ["behaviours/Work.yaml", "conditions/ConditionRepository.yaml", "skills.yaml"]


def test_values_of_the_wrong_type_are_located(tmp_path: Path) -> None:
    bad = plan(100, "Top", ["Work.beh#30"])
    bad["entryPoints"][0]["minCardinality"] = "two"  # type: ignore[index]
    bad["states"][0]["name"] = ["Run"]  # type: ignore[index]
    src = folder(tmp_path, {"Top.pml": bad})
    result = import_designer(src)
    assert {(e.file, e.key, e.message) for e in result.errors} == {
        ("plans/Top.pml", "entryPoints[0].minCardinality", "must be a whole number, not text"),
        ("plans/Top.pml", "states[0].name", "must be text, not a list"),
    }


def test_the_summary_prints_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Nope.pml#5"])})
    assert main(["import-designer", str(src), "--out", str(tmp_path / "out")]) == 1
    captured = capsys.readouterr()
    assert "refused 1" in captured.out
    assert (
        "plans/Top.pml: states[0].confAbstractPlanWrappers[0].abstractPlan: 'Nope.pml#5' refers to nothing"
        in captured.err
    )


def test_usage_errors_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Work.beh#30"])})
    a_file = tmp_path / "file.txt"
    a_file.write_text("x", encoding="utf-8")
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["import-designer", str(tmp_path / "missing"), "--out", str(tmp_path / "o")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["import-designer", str(a_file), "--out", str(tmp_path / "o")]) == 2
    assert "is not a folder" in capsys.readouterr().err
    assert main(["import-designer", str(src), "--out", str(a_file)]) == 2
    assert "is a file" in capsys.readouterr().err
    assert main(["import-designer", str(empty), "--out", str(tmp_path / "o")]) == 2
    assert "no ALICA Plan Designer files" in capsys.readouterr().err
    assert main(["import-designer", str(src)]) == 2  # --out is required
    assert not (tmp_path / "o").exists()


def test_a_file_that_is_not_utf8_is_an_error(tmp_path: Path) -> None:
    src = folder(tmp_path, {"Top.pml": plan(100, "Top", ["Work.beh#30"])})
    (src / "plans" / "Latin.pml").write_bytes(b'{"id": 7, "name": "Gr\xfcn"}')
    result = import_designer(src)
    (error,) = result.errors
    assert error.format() == "plans/Latin.pml:1:22: not UTF-8 text (byte 0xfc)"
    assert "plans/Top.yaml" in result.outputs


_JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=5), inner, max_size=3),
    max_leaves=6,
)
_REFERENCES = st.sampled_from(
    ["Work.beh#30", "Top.pml#100", "taskrepository.tsk#11", "ConditionRepository.cnd#21", 101]
)


def _paths(value: object, prefix: tuple[object, ...] = ()) -> list[tuple[object, ...]]:
    out = [prefix] if prefix else []
    if isinstance(value, dict):
        for key, item in value.items():
            out += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            out += _paths(item, (*prefix, index))
    return out


def _set(root: object, path: tuple[object, ...], new: object) -> None:
    """Replace the value at ``path`` by ``new``, if the path still leads somewhere after earlier changes."""
    target = root
    for depth, key in enumerate(path):
        if isinstance(target, dict) and isinstance(key, str) and key in target:
            container: dict[str, object] | list[object] = target
        elif isinstance(target, list) and isinstance(key, int) and key < len(target):
            container = target
        else:
            return
        if depth == len(path) - 1:
            container[key] = new  # type: ignore[index]
            return
        target = container[key]  # type: ignore[index]


@settings(max_examples=40)
@given(st.data())
def test_a_mutated_plan_is_imported_or_refused_never_a_crash(data: st.DataObject) -> None:
    child = plan(200, "Child", ["Work.beh#30"])
    paths = _paths(child)
    mutated = json.loads(json.dumps(child))
    for _ in range(data.draw(st.integers(1, 3))):
        _set(mutated, data.draw(st.sampled_from(paths)), data.draw(_JSON | _REFERENCES))
    with tempfile.TemporaryDirectory() as tmp:
        src = folder(Path(tmp), {"Child.pml": mutated, "Top.pml": plan(100, "Top", ["Child.pml#200", "Work.beh#30"])})
        result = import_designer(src)  # never raises
        assert all(e.file == "plans/Child.pml" for e in result.errors), [e.format() for e in result.errors]
        assert "plans/Top.yaml" in result.outputs  # the parent is imported, with or without its child
        out = Path(tmp) / "out"
        write_result(result, out)
        problems = validate_paths([out], Loader(search_path=[out]))
        assert not problems, [p.format() for p in problems]
