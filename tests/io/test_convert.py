"""``alica convert``: the output loads where it is written and keeps every value the input wrote."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.io import load_document, load_library, plan_path
from alica.io.dump import document_data
from alica.io.loader import parse_text, read_text
from alica.io.xml_write import write_xml
from alica.io.yaml_format import write_yaml
from tests.conftest import PLANS

#: Every optional key written, each with its default value (zeros, false, empty text, '*').
DEFAULTS = textwrap.dedent(
    """\
    skills:
      - name: S
        doc: ''
        params:
          - {name: p, type: any, required: true, doc: ''}
          - {name: q, type: any, required: false}
    tasks:
      - {name: T, description: ''}
    rolesets:
      - name: R
        description: ''
        default_priority: 0
        roles:
          - {name: A, description: '', priorities: {T: 0}}
    behaviours:
      - {name: B, description: '', skill: Idle, frequency: 0}
    plans:
      - name: P
        description: ''
        frequency: 0
        utility: {priority_weight: 1, similarity_weight: 0, threshold: 0.1}
        entry_points:
          - {name: T, task: T, state: S, min: 0, max: '*', success_required: false}
        states:
          - name: S
            kind: normal
            description: ''
            children: [B]
            transitions:
              - {name: S->F, to: F, condition: 'false', sync: Y}
          - {name: F, kind: success}
        synchronisations:
          - {name: Y, transitions: [S->F], talk_timeout: 0.03, sync_timeout: 10, fail_on_timeout: false}
    plantypes:
      - {name: PT, description: '', plans: [P]}
    problems:
      - name: Q
        description: ''
        elements: [P]
        update_time: 1
        timeout: 60
        planner: builtin
        goal: 'true'
    """
)


def converted(text: str, src: str, dst: str) -> str:
    """``text`` of format ``src`` converted to format ``dst`` as ``alica convert`` does."""
    tree, problems = parse_text(text, f"in.{src}", src)
    document, more = read_text(text, f"in.{src}", src)
    assert tree is not None and not problems and not more, [p.format() for p in problems + more]
    data = document_data(document, tree)
    return write_xml(data) if dst == "xml" else write_yaml(data)


def test_yaml_xml_yaml_keeps_every_written_default() -> None:
    back = converted(converted(DEFAULTS, "yaml", "xml"), "xml", "yaml")
    assert yaml.safe_load(back) == yaml.safe_load(DEFAULTS)


def test_default_priority_zero_is_written_to_xml() -> None:
    assert 'default_priority="0"' in converted((PLANS / "roles.yaml").read_text(), "yaml", "xml")


def test_defaults_not_written_stay_out() -> None:
    text = "tasks: [T]\nplans:\n  - {name: P, entry_points: [{task: T, state: S}], states: [{name: S}]}\n"
    assert yaml.safe_load(converted(text, "yaml", "yaml")) == yaml.safe_load(text)


@settings(max_examples=60)
@given(
    priority=st.sampled_from([0, 0.0, -1, 1, 0.25, -0.5]),
    low=st.integers(0, 3),
    required=st.booleans(),
    description=st.sampled_from(["", "a robot", "two\nlines"]),
    frequency=st.sampled_from([0, 0.5, 10]),
    timeout=st.sampled_from([60, 1.5, 120]),
)
def test_values_survive_both_ways(
    priority: float, low: int, required: bool, description: str, frequency: float, timeout: float
) -> None:
    data = {
        "tasks": [{"name": "T", "description": description}],
        "rolesets": [{"name": "R", "description": description, "default_priority": priority, "roles": [{"name": "A"}]}],
        "behaviours": [{"name": "B", "skill": "Idle", "frequency": frequency}],
        "plans": [
            {
                "name": "P",
                "frequency": frequency,
                "entry_points": [{"task": "T", "state": "S", "min": low, "success_required": required}],
                "states": [{"name": "S", "description": description, "children": ["B"]}],
            }
        ],
        "problems": [{"name": "Q", "elements": ["P"], "timeout": timeout, "goal": "true"}],
    }
    text = write_yaml(data)
    assert yaml.safe_load(converted(converted(text, "yaml", "xml"), "xml", "yaml")) == data


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


@pytest.mark.parametrize("ending", ["xml", "yaml"])
def test_output_in_another_folder_loads_there(tmp_path: Path, capsys: pytest.CaptureFixture[str], ending: str) -> None:
    out = tmp_path / "elsewhere" / f"mission.{ending}"
    code, printed, err = run(capsys, "convert", str(PLANS / "lunar" / "mission.yaml"), str(out))
    assert code == 0, err
    assert "import(s) rewritten" in printed
    converted_library = load_library(out)
    assert converted_library == load_library(PLANS / "lunar" / "mission.yaml")
    imports = load_document(out).imports
    # the shipped files it imports by name, so the output stays valid wherever it is moved
    assert imports and all(i.startswith("alica:plans/") and plan_path(i).is_file() for i in imports)
    moved = tmp_path / "moved" / "deeper"
    moved.parent.mkdir()
    out.parent.rename(moved)
    assert load_library(moved / out.name) == converted_library


def test_own_imports_stay_relative_to_the_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "project" / "shared").mkdir(parents=True)
    (tmp_path / "project" / ".alica-project").write_text("", encoding="utf-8")
    (tmp_path / "project" / "shared" / "tasks.yaml").write_text("tasks: [T]\n")
    src = tmp_path / "project" / "roles.yaml"
    src.write_text(
        "imports: [shared/tasks.yaml, alica:plans/skills/facts.yaml]\n"
        "rolesets:\n  - {name: R, roles: [{name: A, priorities: {T: 1}}]}\n"
    )
    out = tmp_path / "project" / "xml" / "roles.xml"
    code, _, err = run(capsys, "convert", str(src), str(out))
    assert code == 0, err
    assert load_document(out).imports == ("../shared/tasks.yaml", "alica:plans/skills/facts.yaml")
    assert load_library(out).rolesets.keys() == load_library(src).rolesets.keys()


def test_output_in_the_same_folder_keeps_imports(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "tasks.yaml").write_text("tasks: [T]\n")
    src = tmp_path / "roles.yaml"
    src.write_text("imports: [tasks.yaml]\nrolesets:\n  - {name: R, roles: [{name: A, priorities: {T: 1}}]}\n")
    code, printed, err = run(capsys, "convert", str(src), str(tmp_path / "roles.xml"))
    assert code == 0, err
    assert "rewritten" not in printed
    assert load_document(tmp_path / "roles.xml").imports == ("tasks.yaml",)
