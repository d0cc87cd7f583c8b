"""``alica center`` with a user's own skills: ``--skills``, and the skill modules and plan folders a trace header records.

Each test goes through the command (``alica.app.cli.main``); only the final ``serve`` is
replaced by one that hands back the app, which a Starlette test client then asks.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from alica.app.center.team_view import TeamView
from alica.app.cli import main
from tests.skills.test_plugins import COUNTER

from .conftest import TOKEN

SKILL_MODULE = COUNTER  # a plug-in module: CountTicks, which writes counted(agent)

TASKS = """
alica: 1
tasks:
  - name: Default
rolesets:
  - name: Crew
    default_priority: 0
    roles:
      - name: Worker
        priorities: {Default: 0.5}
"""

PLAN = """
alica: 1
imports: [IMPORT]
behaviours:
  - name: Count
    skill: CountTicks
    params: {times: 6}
plans:
  - name: Job
    entry_points:
      - {name: Start, task: Default, state: Working, min: 1, max: 1, success_required: true}
    states:
      - name: Working
        children: [{ref: Count}]
        transitions:
          - {to: Done, condition: "counted(self)"}
      - name: Done
        kind: success
"""


@pytest.fixture
def project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """``proj/`` (the working folder) with the skill module and a plan that imports ``../shared/tasks.yaml``.

    ``shared/`` is reached only through ``ALICA_PLAN_PATH``, set here for the run.
    """
    (tmp_path / "shared").mkdir()
    (tmp_path / "shared" / "tasks.yaml").write_text(TASKS, encoding="utf-8")
    folder = tmp_path / "proj"
    folder.mkdir()
    (folder / "count_skill_c.py").write_text(SKILL_MODULE, encoding="utf-8")
    (folder / "job.yaml").write_text(PLAN.replace("IMPORT", "../shared/tasks.yaml"), encoding="utf-8")
    monkeypatch.chdir(folder)
    monkeypatch.setattr(sys, "path", list(sys.path))
    monkeypatch.setenv("ALICA_PLAN_PATH", str(tmp_path / "shared"))
    yield folder
    sys.modules.pop("count_skill_c", None)


@pytest.fixture
def served(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The apps ``alica center`` would serve (the command returns instead of serving)."""
    apps: list[Any] = []
    monkeypatch.setattr("alica.app.center.server.serve", lambda app, host, port, token, out=None: apps.append(app))
    return apps


def _center(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["center", *argv, "--token", TOKEN])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, err


def _get(app: Any, path: str) -> Any:
    response = TestClient(app).get(path, headers={"Authorization": f"Bearer {TOKEN}"})
    assert response.status_code == 200, response.text
    return response.json()


def _record(project: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    trace = project / "run.jsonl"
    code = main(["run", "job.yaml", "--agents", "ann:Worker", "--skills", "count_skill_c", "--trace", str(trace)])
    out, err = capsys.readouterr()
    assert code == 0, out + err
    return trace


def test_the_plan_view_takes_the_users_skills(
    project: Path, served: list[Any], capsys: pytest.CaptureFixture[str]
) -> None:
    code, err = _center(capsys, "--plan", "job.yaml")
    assert code == 1 and "CountTicks" in err and not served  # unknown without the module
    code, err = _center(capsys, "--plan", "job.yaml", "--skills", "count_skill_c")
    assert code == 0, err
    plan = _get(served[0], "/api/plan")
    assert plan["roots"] == ["Job"]
    working = plan["trees"]["Job"]["states"][0]
    assert working["children"] == [{"kind": "behaviour", "name": "Count", "skill": "CountTicks"}]


def test_a_skills_module_that_does_not_load_is_a_clear_error(
    project: Path, served: list[Any], capsys: pytest.CaptureFixture[str]
) -> None:
    code, err = _center(capsys, "--plan", "job.yaml", "--skills", "no_such_skills_module")
    assert code == 1 and "no_such_skills_module" in err and not served
    trace = _record(project, capsys)
    code, err = _center(capsys, "--trace", str(trace), "--skills", "no_such_skills_module")
    assert code == 1 and "no_such_skills_module" in err and not served


def test_the_trace_header_records_the_skill_modules_and_the_plan_path(
    project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trace = _record(project, capsys)
    header = json.loads(trace.read_text(encoding="utf-8").splitlines()[0])
    assert header["skills"] == ["count_skill_c"]
    assert header["plan_path"] == ["alica:plans", str((project.parent / "shared").resolve())]


def test_a_replay_loads_the_plans_with_the_recorded_skills_and_folders(
    project: Path, served: list[Any], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    trace = _record(project, capsys)
    sys.modules.pop("count_skill_c", None)
    monkeypatch.delenv("ALICA_PLAN_PATH")  # the replay finds shared/ from the header alone
    code, err = _center(capsys, "--trace", str(trace))
    assert code == 0, err
    trees = _get(served[0], "/api/trees")
    assert trees["notes"] == [] and trees["agents"] == {"ann": "Job"}
    assert [s["name"] for s in trees["trees"]["Job"]["states"]] == ["Working", "Done"]
    ann = _get(served[0], "/api/state?t=0")["agents"]["ann"]
    assert (ann["plan"], ann["task"], ann["state"]) == ("Job", "Start", "Working")  # the entry point's state


def test_without_the_recorded_skills_the_replay_says_why_it_has_no_trees(
    project: Path, served: list[Any], capsys: pytest.CaptureFixture[str]
) -> None:
    trace = _record(project, capsys)
    code, err = _center(capsys, "--trace", str(trace), "--no-trace-skills")
    assert code == 0
    notes = _get(served[0], "/api/trees")["notes"]
    assert any("count_skill_c" in n and "--no-trace-skills" in n for n in notes), notes
    assert any("job.yaml does not load" in n and "CountTicks" in n for n in notes), notes
    assert "job.yaml does not load" in err  # said on the terminal too
    # an explicit --skills adds to what the header names: here it is all there is
    code, err = _center(capsys, "--trace", str(trace), "--no-trace-skills", "--skills", "count_skill_c")
    assert code == 0 and _get(served[1], "/api/trees")["agents"] == {"ann": "Job"}


def test_a_recorded_module_that_is_not_there_is_a_note(
    project: Path, served: list[Any], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    trace = _record(project, capsys)
    sys.modules.pop("count_skill_c", None)
    elsewhere = project.parent / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(project))])
    code, err = _center(capsys, "--trace", str(trace))
    assert code == 0
    notes = _get(served[0], "/api/trees")["notes"]
    assert any(n.startswith("skill module count_skill_c (recorded in the trace header) does not load") for n in notes)
    assert "count_skill_c" in err


def test_a_header_with_malformed_sources_is_read_with_notes(
    tmp_path: Path, served: list[Any], capsys: pytest.CaptureFixture[str]
) -> None:
    header = {"t": 0.0, "agent": "-", "event": "trace", "format": "alica-trace", "version": 2, "agents": {}}
    header.update(skills="count_skill_c", plan_path=[str(tmp_path / "gone")])
    trace = tmp_path / "odd.jsonl"
    trace.write_text(json.dumps(header) + "\n", encoding="utf-8")
    code, _ = _center(capsys, "--trace", str(trace))
    assert code == 0
    notes = " ".join(_get(served[0], "/api/trees")["notes"])
    assert "the trace header's skills is not a list of module names" in notes
    assert f"plan folder {tmp_path / 'gone'} (recorded in the trace header's plan_path) is not there" in notes


def test_a_plan_node_without_a_transition_is_in_its_entry_state() -> None:
    allocation = {"t": 0.0, "agent": "a", "event": "allocation", "key": "P", "plan": "P", "entries": {"a": "Go"}}
    for entries, state in (({"P": {"Go": "S0"}}, "S0"), ({"P": {"Other": "S9"}}, None), (None, None)):
        view = TeamView({}, entries=entries)
        view.apply(allocation)
        assert view.snapshot()["agents"]["a"]["state"] == state
        assert view.copy().snapshot()["agents"]["a"]["state"] == state
    view = TeamView({}, entries={"P": {"Go": "S0"}})
    view.apply(allocation)
    view.apply({"t": 1.0, "agent": "a", "event": "transition", "key": "P", "plan": "P", "source": "S0", "target": "S1"})
    assert view.snapshot()["agents"]["a"]["state"] == "S1"  # a transition's target wins
