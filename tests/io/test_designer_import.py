"""alica import-designer on the C++ engine's own designer files: everything imports and validates."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import pytest

from alica.app.cli import main
from alica.io import Loader
from alica.io.designer import Construct, import_designer
from alica.model import PlanLibrary
from tests.io.test_designer_helpers import data, designer_folder


@pytest.fixture(scope="module")
def imported(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    """The shared folder imported once: the output folder and the --json report."""
    out = tmp_path_factory.mktemp("imported") / "out"
    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):  # capsys is per test; this fixture serves the module
        code = main(["import-designer", str(designer_folder()), "--out", str(out), "--json"])
    assert code == 0, buffer.getvalue()[-2000:]
    report = json.loads(buffer.getvalue())
    assert isinstance(report, dict)
    return out, report


@pytest.fixture(scope="module")
def library(imported: tuple[Path, dict[str, object]]) -> PlanLibrary:
    """Every output file loaded together."""
    out, _ = imported
    files = sorted(out.rglob("*.yaml"))
    return Loader(search_path=[out]).load(*files)


def _notes(report: dict[str, object], construct: Construct) -> list[dict[str, str]]:
    notes = report["notes"]
    assert isinstance(notes, list)
    return [n for n in notes if n["construct"] == construct.value]


def test_every_file_is_imported_with_no_error(imported: tuple[Path, dict[str, object]]) -> None:
    out, report = imported
    assert set(report) == {"files", "written", "notes", "errors"}
    assert report["files"] == 110
    assert report["errors"] == []
    written = report["written"]
    assert isinstance(written, list)
    # 75 plans, 26 behaviours, 3 plan types, 2 role sets, 1 task and 1 condition repository; no placeholder; the catalogue
    assert len(written) == 75 + 26 + 3 + 2 + 1 + 1 + 1
    assert written == sorted(written)
    assert {w.split("/")[0] for w in written} == {"plans", "behaviours", "roles", "tasks", "conditions", "skills.yaml"}
    assert all((out / w).is_file() for w in written)
    for note in report["notes"]:  # type: ignore[union-attr]
        assert set(note) == {"file", "key", "construct", "message"} and note["file"] and note["message"]


def test_alica_validate_passes_on_the_output(
    imported: tuple[Path, dict[str, object]], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    out, _ = imported
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    # its files import each other with ../: the marker file makes the output a project of its own,
    # valid from any working folder
    assert (out / ".alica-project").is_file()
    for here in (out.parent, out / "roles", out.parent.parent):
        monkeypatch.chdir(here)
        assert main(["validate", str(out)]) == 0, capsys.readouterr().err[-3000:]
        assert "ok: 109 plan file(s) valid" in capsys.readouterr().out
    (out / ".alica-project").unlink()  # without it, a file may not climb out of its own folder
    assert main(["validate", "-q", str(out)]) == 1
    assert "is outside the plan folders" in capsys.readouterr().err
    (out / ".alica-project").write_text("", encoding="utf-8")


def test_counts_of_the_imported_elements(library: PlanLibrary) -> None:
    documents = library.documents
    plans = [p for d in documents for p in d.plans]
    behaviours = [b for d in documents for b in d.behaviours]
    plantypes = [p for d in documents for p in d.plantypes]
    tasks = [t for d in documents for t in d.tasks]
    rolesets = [r for d in documents for r in d.rolesets]
    assert (len(plans), len(behaviours), len(plantypes)) == (75, 26, 3)
    assert len(tasks) == 64
    assert sorted(r.name for r in rolesets) == ["Roleset", "RolesetTA"]
    assert sum(len(r.roles) for r in rolesets) == 12


def test_cardinalities_and_success_required(imported: tuple[Path, dict[str, object]]) -> None:
    out, _ = imported
    plan = data(out / "plans" / "MasterPlanTaskAssignment.yaml")["plans"][0]  # type: ignore[index]
    maxima = {ep["task"]: (ep["min"], ep["max"]) for ep in plan["entry_points"]}
    assert maxima == {"DefaultTask": (2, 5), "AttackTask": (0, 1000), "MidFieldTask": (0, "*"), "DefendTask": (0, "*")}
    midfield = data(out / "plans" / "MidFieldPlayPlan.yaml")["plans"][0]  # type: ignore[index]
    entries = {ep.get("name", ep["task"]): ep for ep in midfield["entry_points"]}
    # two entry points of one task get distinct names: the unnamed one is named after its task
    assert set(entries) == {"DefaultTask", "NewEntryPoint"}
    assert entries["DefaultTask"]["success_required"] is True
    assert entries["NewEntryPoint"]["success_required"] is False
    assert (entries["NewEntryPoint"]["min"], entries["NewEntryPoint"]["max"]) == (3, 5)


def test_synchronisation_timeouts_are_seconds(library: PlanLibrary) -> None:
    plan = library.plans["MasterSyncTransition"]
    (sync,) = plan.synchronisations
    assert (sync.talk_timeout, sync.sync_timeout, sync.fail_on_timeout) == (0.03, 10.0, False)
    assert sorted(sync.transitions) == ["FirstTaskTran", "SecondTaskTran"]
    assert {t.synchronisation for t in plan.transitions} == {sync.name}


def test_standard_conditions_become_formulas(library: PlanLibrary) -> None:
    def condition(plan: str, source: str) -> str:
        (t,) = [t for t in library.plans[plan].transitions if t.source == source]
        assert t.condition is not None
        return t.condition.text

    assert condition("IsChildSuccessTestPlan", "EntryState") == "succeeded(SuccessOnInitBeh)"  # IsChildSuccess
    assert condition("PlanA", "PlanAA") == "succeeded(PlanAA)"  # AnyChildSuccess over one child
    assert condition("PlanB", "PlanBA") == "succeeded"  # AllChildSuccess
    assert condition("AuthorityTestMaster", "Init") == "true"  # AlwaysTrueCondition
    assert condition("AttackPlan", "Attack") == "false"  # AlwaysFalseCondition


def test_c_plus_plus_conditions_are_declared_predicates(
    imported: tuple[Path, dict[str, object]], library: PlanLibrary
) -> None:
    out, report = imported
    repository = data(out / "conditions" / "ConditionRepository.yaml")
    declared = {d["name"]: d for d in repository["predicates"]}  # type: ignore[union-attr]
    assert declared["IsAnyChildStatus"]["arity"] == 0
    assert "alica-tests" in declared["IsAnyChildStatus"]["doc"]
    assert "AnyChildSuccess" not in declared  # a standard condition with a formula is not declared
    (t,) = library.plans["SimpleTestPlan"].transitions
    assert t.condition is not None and t.condition.text == "IsAnyChildStatus"
    notes = [n["message"] for n in _notes(report, Construct.PREDICATE)]
    assert any("declared as predicate 'IsAnyChildStatus'" in m and "--fact IsAnyChildStatus@T" in m for m in notes)
    # a standard comparison that reads a blackboard key stays a predicate, with a note saying why
    kept = [n for n in _notes(report, Construct.STANDARD_CONDITION) if "IsEqualInt64" in n["message"]]
    assert kept and "blackboard key" in kept[0]["message"]
    # an inline pre-condition is declared in its plan's file
    assert library.plans["SimpleTestPlan"].pre is not None
    assert library.plans["SimpleTestPlan"].pre.text == "SimpleTestPlanPreCondition"  # type: ignore[union-attr]
    # a condition marked disabled is imported too (the C++ engine evaluates it: conditionPlanTypeTest), with a note
    run = library.plans["RuntimeConditionPlan"].run
    assert run is not None and run.text == "RuntimeConditionPlanRuntimeCondition"
    disabled = [n["message"] for n in _notes(report, Construct.DISABLED_CONDITION)]
    assert any("RuntimeConditionPlan" in m and "evaluates it all the same" in m for m in disabled)


def test_role_priorities_name_tasks(library: PlanLibrary) -> None:
    roleset = library.rolesets["RolesetTA"]
    assert roleset.default_priority == 0.5
    attacker = next(r for r in roleset.roles if r.name == "Attacker")
    assert {p.task: p.value for p in attacker.priorities} == {
        "DefaultTask": 0.5,
        "DefendTask": 0.5,
        "AttackTask": 0.6,
        "MidFieldTask": 0.5,
    }


def test_name_clashes_are_renamed_with_a_note(imported: tuple[Path, dict[str, object]], library: PlanLibrary) -> None:
    _, report = imported
    assert library.plans["Tackle"].name == "Tackle"
    behaviour = library.behaviours["TackleBehaviour"]
    assert behaviour.skill == "Tackle"  # the skill keeps the designer's name
    assert library.plantypes["AttackType"].plans == ("AttackPlan", "GoalPlan", "Tackle")
    renamed = {(n["file"], n["message"]) for n in _notes(report, Construct.RENAMED)}
    assert any(f == "behaviours/Tackle.beh" and "'TackleBehaviour'" in m for f, m in renamed)
    assert any(f == "plans/Attack.pty" and "'AttackType'" in m for f, m in renamed)
    spaces = [n for n in _notes(report, Construct.RENAMED) if n["file"] == "plans/OrderedSchedulingTestPlan.pml"]
    assert spaces and spaces[0]["key"] == "transitions[0].name" and "'FromPlanATo_PlanB'" in spaces[0]["message"]


def test_deactivated_plan_and_cycle_through_a_plan_type_are_noted(
    imported: tuple[Path, dict[str, object]], library: PlanLibrary
) -> None:
    _, report = imported
    assert library.plantypes["PlanType"].plans == ("AttackPlan",)
    (deactivated,) = _notes(report, Construct.DEACTIVATED)
    assert deactivated["file"] == "plans/PlanType.pty" and deactivated["key"] == "annotatedPlans[1].activated"
    assert "GoalPlan.pml" in deactivated["message"]
    cut = [n for n in _notes(report, Construct.DROPPED) if n["file"] == "plans/PlanType.pty"]
    assert cut and "MidFieldPlayPlan" in cut[0]["message"] and "cycle" in cut[0]["message"]


def test_constructs_without_counterpart_are_noted(imported: tuple[Path, dict[str, object]]) -> None:
    _, report = imported
    files = {c: {n["file"] for n in _notes(report, c)} for c in Construct}
    assert "placeholders/PlanPlaceholder.plh" in files[Construct.PLACEHOLDER]
    assert "plans/PlaceholderTestPlan.pml" in files[Construct.PLACEHOLDER]  # its child was left out
    assert "behaviours/TriggerA.beh" in files[Construct.EVENT_DRIVEN]
    assert "plans/BlackboardTestPlan.pml" in files[Construct.BLACKBOARD]
    assert "plans/BlackboardTestPlan.pml" in files[Construct.KEY_MAPPING]
    assert "plans/OrderedSchedulingTestPlan.pml" in files[Construct.NO_CONDITION]
    assert {"hairy/Alica.yaml", "nase/Alica.yaml"} <= files[Construct.AGENT_CONFIG]
    assert "UdpProxy.conf" in files[Construct.OTHER_FILE]
    agent = {n["key"]: n["message"] for n in _notes(report, Construct.AGENT_CONFIG) if n["file"] == "hairy/Alica.yaml"}
    assert "--auto-failure-handling" in agent["Alica.AutoFailureHandling"]
    assert "team_timeout=10" in agent["Alica.TeamTimeOut"]
    unnamed = [n for n in _notes(report, Construct.UNNAMED) if n["file"] == "plans/SimpleTestPlan.pml"]
    assert unnamed and "'1412252439927'" in unnamed[0]["message"]


def test_output_files_say_where_they_came_from(imported: tuple[Path, dict[str, object]]) -> None:
    out, _ = imported
    text = (out / "plans" / "SimpleTestPlan.yaml").read_text(encoding="utf-8")
    assert text.startswith(
        "# Imported by 'alica import-designer' from the ALICA Plan Designer file plans/SimpleTestPlan.pml"
    )
    assert "# Notes on this file:" in text
    skills = data(out / "skills.yaml")["skills"]
    assert isinstance(skills, list) and len(skills) == 26
    attack = next(s for s in skills if s["name"] == "Attack")
    assert attack == {
        "name": "Attack",
        "doc": "imported from the ALICA Plan Designer: behaviour Attack (Attack.beh#1402488848841)",
        "params": [],
    }


def test_import_is_deterministic(imported: tuple[Path, dict[str, object]]) -> None:
    out, _ = imported
    again = import_designer(designer_folder())
    assert list(again.outputs) == sorted(again.outputs)
    for rel, text in again.outputs.items():
        assert (out / rel).read_text(encoding="utf-8") == text, rel


def test_human_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["import-designer", str(designer_folder()), "--out", str(tmp_path / "out")]) == 0
    text = capsys.readouterr().out
    assert "read 110 designer file(s) and 3 config file(s)" in text
    assert "refused 0" in text
    assert "deactivated plan in a plan type: 1" in text
    assert "check it with: " in text


def test_the_docs_show_what_the_import_prints(
    imported: tuple[Path, dict[str, object]],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out, _ = imported
    page = (Path(__file__).resolve().parents[2] / "docs" / "coming_from_cpp.md").read_text(encoding="utf-8")
    source = designer_folder()
    monkeypatch.chdir(tmp_path)
    blocks = re.findall(r"```(\w+)\n(.*?)```", page, re.DOTALL)
    transcript = next(text for lang, text in blocks if lang == "text" and "$ alica import-designer" in text)
    shown = transcript.split("$ alica validate")[0].splitlines()[1:]
    assert main(["import-designer", str(source), "--out", "build/alica_tests"]) == 0
    printed = {line.strip() for line in capsys.readouterr().out.splitlines()}
    # every line the page shows, but the elided ones and the first (it names the folder as run from the checkout)
    checked = [line.strip() for line in shown if "..." not in line and line.strip() and "read 110" not in line]
    assert [line for line in checked if line not in printed] == []
    yaml_block = next(text for lang, text in blocks if lang == "yaml" and "IsChildSuccessTestPlan" in text)
    assert (out / "plans" / "IsChildSuccessTestPlan.yaml").read_text(encoding="utf-8") == yaml_block
