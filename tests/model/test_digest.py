"""A library's digest names its content: the same in every process, blind to layout, changed by any edit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from alica.io import load_library
from alica.model.digest import canonical, library_changes, library_digest
from tests.conftest import PLANS

PLAN = """alica: 1
tasks: [Default]
rolesets:
  - name: Crew
    roles:
      - {name: Worker, priorities: {Default: 0.5}, requires: [base, arm, camera]}
predicates: [go/0, ready/1]
behaviours:
  - {name: Hold, skill: Idle}
plans:
  - name: Top
    entry_points: [{task: Default, state: Waiting, min: 1, max: "*"}]
    states:
      - name: Waiting
        children: [Hold]
        transitions:
          - {to: Done, condition: "go"}
      - {name: Done, kind: success}
"""


def _load(folder: Path, text: str):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "plan.yaml").write_text(text, encoding="utf-8")
    return load_library(folder / "plan.yaml")


def test_the_digest_is_the_same_in_processes_with_other_string_hashing() -> None:
    mission = PLANS / "lunar" / "mission.yaml"  # roles with required capabilities (sets)
    code = f"from alica.io import load_library; from alica.model.digest import library_digest; print(library_digest(load_library({str(mission)!r})))"
    digests = {
        subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "PYTHONHASHSEED": seed},
        ).stdout.strip()
        for seed in ("1", "2", "3")
    }
    assert digests == {library_digest(load_library(mission))}


def test_layout_comments_and_the_folder_do_not_change_the_digest(tmp_path: Path) -> None:
    first = _load(tmp_path / "a", PLAN)
    moved = _load(
        tmp_path / "b",
        "# the same plans, laid out otherwise\n\n" + PLAN.replace("\n  - name: Top", "\n\n  - name: Top"),
    )
    assert library_digest(first) == library_digest(moved)
    assert library_changes(first, moved).empty


@settings(max_examples=25, deadline=None)
@given(st.sampled_from(["go", "not go", "go and go", "ready(a)", "true", "false", "go or ready(b)"]))
def test_a_changed_condition_changes_the_digest_and_names_the_plan(tmp_path_factory, condition: str) -> None:
    folder = tmp_path_factory.mktemp("digest")
    before = _load(folder / "a", PLAN)
    after = _load(folder / "b", PLAN.replace('condition: "go"', f'condition: "{condition}"'))
    changes = library_changes(before, after)
    assert (library_digest(before) == library_digest(after)) == (condition == "go")
    assert changes.changed == (() if condition == "go" else ("plan Top",)) and not changes.added


@given(st.frozensets(st.text(max_size=5), max_size=6))
def test_canonical_sets_are_sorted_whatever_their_order(items: frozenset[str]) -> None:
    assert canonical(items) == canonical(frozenset(reversed(list(items))))
    assert canonical(items) == sorted(items, key=json.dumps)  # by their JSON text: the same in every process


def test_added_and_removed_elements_are_named(tmp_path: Path) -> None:
    before = _load(tmp_path / "a", PLAN)
    after = _load(
        tmp_path / "b",
        PLAN.replace(
            "  - {name: Hold, skill: Idle}", "  - {name: Hold, skill: Idle}\n  - {name: Wave, skill: Idle}"
        ).replace("go/0, ready/1", "go/0"),
    )
    changes = library_changes(before, after)
    assert changes.added == ("behaviour Wave",) and changes.removed == ("predicate ready/1",)
    assert changes.text() == "added behaviour Wave; removed predicate ready/1"
