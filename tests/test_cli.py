"""The ``alica`` command, end to end through ``main(argv)``."""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from alica.app import render
from alica.app.cli import main
from alica.io import load_document, plan_files
from alica.io.plan_paths import import_target
from tests.conftest import PLANS

MISSION = PLANS / "lunar" / "mission.yaml"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_validate_shipped_plans(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "validate", str(PLANS))
    assert code == 0, err
    assert out.startswith("ok: ")


def test_validate_missing_path(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "validate", "no/such/place.yaml")
    assert code == 1 and "no/such/place.yaml:1:1: error: no such file or folder" in err


def test_validate_unknown_extension(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "plan.json"
    bad.write_text("{}")
    code, _, err = run(capsys, "validate", str(bad))
    assert code == 1 and "unknown plan file type '.json'" in err


def test_validate_binary_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "plan.yaml"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    code, _, err = run(capsys, "validate", str(bad))
    assert code == 1 and "error:" in err


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "validate")[0] == 2
    assert run(capsys, "frobnicate")[0] == 2
    assert run(capsys)[0] == 2


@pytest.mark.parametrize("command", [[], ["validate"], ["show"], ["convert"], ["render"], ["list-skills"]])
def test_help(capsys: pytest.CaptureFixture[str], command: list[str]) -> None:
    code, out, _ = run(capsys, *command, "--help")
    assert code == 0 and "usage: alica" in out


def test_show_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "show", str(MISSION))
    assert code == 0, err
    assert "plan LunarMission" in out
    assert "task Explore" in out and "state" in out and "skill" in out


def test_show_dot(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "show", str(MISSION), "--format", "dot")
    assert code == 0 and out.startswith("digraph alica {") and out.rstrip().endswith("}")
    assert "cluster_LunarMission" in out


def test_show_svg_without_graphviz(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(render.shutil, "which", lambda name: None)
    code, _, err = run(capsys, "show", str(MISSION), "--format", "svg")
    assert code == 1 and "Graphviz is not installed" in err


def test_show_unknown_plan_name(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "show", str(MISSION), "--name", "NoSuchPlan")
    assert code == 1 and "NoSuchPlan" in err


def test_show_broken_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("plans:\n  - name: P\n    states: []\n")
    code, _, err = run(capsys, "show", str(bad))
    assert code == 1 and "bad.yaml:2:5: error: plan 'P' has no 'entry_points'" in err


def test_render_writes_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _out, err = run(capsys, "render", str(PLANS / "lunar"), "--out", str(tmp_path))
    assert code == 0, err
    assert list(tmp_path.glob("mission.yaml.LunarMission.txt")) and list(tmp_path.glob("*.dot"))


def test_render_writes_one_set_of_files_per_plan_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # plans/blocksworld holds mission.yaml and mission.xml, with the same root plans
    code, out, err = run(capsys, "render", str(PLANS), str(PLANS / "lunar"), "--out", str(tmp_path))
    assert code == 0, err
    match = re.match(r"rendered (\d+) plan tree\(s\) from (\d+) file\(s\)", out)
    assert match, out
    trees, files = int(match.group(1)), int(match.group(2))
    assert files == len(plan_files([PLANS])[0])  # plans/lunar is inside plans/: its files count once
    assert len(list(tmp_path.rglob("*.txt"))) == trees and len(list(tmp_path.rglob("*.dot"))) == trees
    for ending in ("yaml", "xml"):
        assert (tmp_path / "blocksworld" / f"mission.{ending}.BlocksWorldMission.dot").is_file()


NODE = re.compile(r'^\s*"([^"]+)" \[')
EDGE = re.compile(r'^\s*"([^"]+)" -> "([^"]+)"(?: \[(.*)\])?;$')


def dot_parts(dot: str) -> tuple[dict[str, str | None], list[tuple[str, str, str]]]:
    """The nodes of dot text with the cluster each is declared in, and its edges (tail, head, attributes)."""
    nodes: dict[str, str | None] = {}
    edges: list[tuple[str, str, str]] = []
    cluster: str | None = None
    for line in dot.splitlines():
        if line.startswith('  subgraph "cluster_'):
            cluster = line.split('"')[1]
        elif line == "  }":
            cluster = None
        elif edge := EDGE.match(line):
            edges.append((edge.group(1), edge.group(2), edge.group(3) or ""))
        elif node := NODE.match(line):
            nodes[node.group(1)] = cluster
    return nodes, edges


@pytest.mark.parametrize("plan", [PLANS / "blocksworld" / "mission.yaml", MISSION, PLANS / "lunar" / "impera.yaml"])
def test_dot_edges_end_at_real_nodes_and_clusters(capsys: pytest.CaptureFixture[str], plan: Path) -> None:
    code, dot, err = run(capsys, "show", str(plan), "--format", "dot")
    assert code == 0, err
    assert "compound=true" in dot and "invis" not in dot
    nodes, edges = dot_parts(dot)
    into_clusters = 0
    for tail, head, attributes in edges:
        assert head in nodes, f"edge {tail} -> {head} ends at no node"
        if nodes[head] is not None and nodes[head] != nodes.get(tail):
            assert f'lhead="{nodes[head]}"' in attributes, (tail, head, attributes)
            into_clusters += 1
    assert into_clusters > 0


def test_dot_labels_break_lines_without_showing_backslash_n(capsys: pytest.CaptureFixture[str]) -> None:
    code, dot, _ = run(capsys, "show", str(PLANS / "blocksworld" / "mission.yaml"), "--format", "dot")
    assert code == 0
    assert 'label="problem StackBlocks\\ngoal: on(a, b)' in dot  # dot's line break: one backslash, then n
    assert "\\\\n" not in dot  # an escaped backslash would show as a literal \n
    assert 'label="TakeBlockFromTable\\nskill Pickup"' in dot  # and no raw line break inside a label


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz is not installed")
def test_dot_renders_without_warnings(capsys: pytest.CaptureFixture[str]) -> None:
    code, dot, _ = run(capsys, "show", str(PLANS / "blocksworld" / "mission.yaml"), "--format", "dot")
    done = subprocess.run(["dot", "-Tsvg"], input=dot, capture_output=True, text=True, check=False)
    assert code == 0 and done.returncode == 0 and done.stderr == ""


def test_convert_both_ways(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src = PLANS / "roles.yaml"
    xml = tmp_path / "roles.xml"
    back = tmp_path / "roles.yaml"
    assert run(capsys, "convert", str(src), str(xml), "--no-validate")[0] == 0
    assert xml.read_text().startswith("<?xml")
    assert run(capsys, "convert", str(xml), str(back), "--no-validate")[0] == 0
    converted, original = load_document(back), load_document(src)
    assert all(i.startswith("alica:plans/") for i in converted.imports)  # shipped files by name
    assert [import_target(back, i).resolve() for i in converted.imports] == [
        (PLANS / i).resolve() for i in original.imports
    ]
    assert dataclasses.replace(converted, imports=original.imports) == original


def test_convert_refuses_invalid_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("tasks: [A]\nplans:\n  - {name: P, entry_points: [{task: B, state: S}], states: [{name: S}]}\n")
    code, _, err = run(capsys, "convert", str(bad), str(tmp_path / "bad.xml"))
    assert code == 1 and "names task 'B'" in err
    assert not (tmp_path / "bad.xml").exists()


def test_convert_needs_known_endings(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "convert", str(PLANS / "roles.yaml"), str(tmp_path / "roles.txt"))
    assert code == 1 and "convert needs files ending in" in err


def test_list_skills(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "list-skills")
    assert code == 0
    assert "MoveToPosition:" in out and "goal (position, required)" in out
    assert "(runs alica.skills.navigation:MoveToPosition)" in out and "(no implementation yet" in out


def test_shipped_plans_are_found_from_the_package() -> None:
    from alica.io import plans_dir

    assert (plans_dir() / "roles.yaml").is_file()


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    from alica import __version__

    code, out, _ = run(capsys, "--version")
    assert code == 0 and out.strip() == f"alica {__version__}"


def test_validate_reports_a_misspelt_condition_with_a_suggestion(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = tmp_path / "typo.yaml"
    plan.write_text(
        "tasks: [T]\n"
        "plans:\n"
        "  - name: P\n"
        "    entry_points: [{task: T, state: A}]\n"
        "    states:\n"
        "      - name: A\n"
        "        transitions: [{to: B, condition: succeded}]\n"
        "      - {name: B, kind: success}\n",
        encoding="utf-8",
    )
    code, _, err = run(capsys, "validate", str(plan))
    assert code == 1
    assert "typo.yaml:7:42: error: condition of transition 'A->B' of plan 'P': " in err
    assert "unknown predicate 'succeded' (did you mean 'succeeded'?)" in err
    plan.write_text(plan.read_text(encoding="utf-8").replace("succeded", "succeeded"), encoding="utf-8")
    code, out, err = run(capsys, "validate", str(plan))
    assert code == 0 and out.startswith("ok: "), err


# --------------------------------------------------------------------------- a skill catalogue written as data

SKILL_CATALOGUE = """\
alica: 1
skills:
  - name: Attack
    doc: "imported from the ALICA Plan Designer: behaviour Attack (Attack.beh#1402488848841)"
    params:
      - {name: goal, type: str, required: false, default: "", doc: "where to go"}
      - {name: duration, type: float, default: 1.5}
"""

SKILL_PLAN = """\
alica: 1
imports: [skills.yaml]
tasks: [Default]
rolesets:
  - name: Crew
    roles:
      - {name: Worker, priorities: {Default: 0.5}}
behaviours:
  - {name: Strike, skill: Attack, params: {goal: there}}
plans:
  - name: Job
    entry_points:
      - {task: Default, state: Working, min: 1, max: 1, success_required: true}
    states:
      - name: Working
        children: [Strike]
        transitions: [{to: Done, condition: "struck(self) or succeeded"}]
      - {name: Done, kind: success}
"""

#: A skill module that binds an implementation to the catalogue's Attack.
ATTACK_MODULE = """
import py_trees
from py_trees.common import Status

from alica import ParamSpec


class Attack(py_trees.behaviour.Behaviour):
    def __init__(self, name, params, context):
        super().__init__(name)
        self.context = context

    def update(self):
        self.context.world_model.assert_fact("struck", self.context.agent)
        return Status.SUCCESS


def register(registry):
    registry.declare_predicate("struck", 1, "the agent struck")
    registry.declare("Attack", ParamSpec("goal", "str", required=False, default=""), implementation=Attack)
"""


@pytest.fixture
def skills_project(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A folder with a skill catalogue, a plan using it and a module implementing the skill; the working folder."""
    (tmp_path / "skills.yaml").write_text(SKILL_CATALOGUE, encoding="utf-8")
    (tmp_path / "job.yaml").write_text(SKILL_PLAN, encoding="utf-8")
    (tmp_path / "attack_from_catalogue.py").write_text(ATTACK_MODULE, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [str(tmp_path), *sys.path])
    yield tmp_path
    sys.modules.pop("attack_from_catalogue", None)


def test_a_plan_file_skill_catalogue_validates_and_runs(
    skills_project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (skills_project / "facts.yaml").write_text("predicates: [struck/1]\n", encoding="utf-8")
    plan = SKILL_PLAN.replace("imports: [skills.yaml]", "imports: [skills.yaml, facts.yaml]")
    (skills_project / "job.yaml").write_text(plan, encoding="utf-8")
    code, out, err = run(capsys, "validate", str(skills_project))
    assert code == 0 and out == "ok: 3 plan file(s) valid\n", err
    code, out, _ = run(capsys, "run", "job.yaml", "--agents", "ann:Worker", "--stand-ins", "--json")
    summary = json.loads(out)
    assert code == 0 and summary["success"] and summary["skills"]["stand_ins"] == ["Attack"]
    assert 1.5 <= summary["sim_time_s"] < 1.7  # the stand-in runs for the declared default duration
    code, out, err = run(capsys, "run", "job.yaml", "--agents", "ann:Worker")
    assert code == 1 and out == ""
    assert "Job uses skills that have no implementation: Attack; pass --stand-ins" in err
    assert "a plan file declares Attack in skills.yaml:3:5: a --skills MODULE whose register(registry)" in err


def test_a_skills_module_binds_an_implementation_to_a_declared_skill(
    skills_project: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run(capsys, "validate", "job.yaml", "--skills", "attack_from_catalogue")[0] == 0
    code, out, err = run(
        capsys, "run", "job.yaml", "--agents", "ann:Worker", "--skills", "attack_from_catalogue", "--json"
    )
    assert code == 0, err
    summary = json.loads(out)
    assert summary["success"] and summary["skills"] == {"real": ["Attack"], "stand_ins": [], "world": None}
