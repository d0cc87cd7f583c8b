"""Hostile plan files end in one ``FILE:LINE:COL: error:`` line, never in a traceback (issue 14).

Each case was an ``alica: internal error`` (exit 70) before its fix; the files
are made here because several cannot be stored as text (NUL bytes, invalid
UTF-8, thousands of digits).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.app.cli import main
from alica.io import yaml_format
from alica.io.loader import Loader
from alica.io.yaml_format import read_yaml

PLAN = (
    "tasks: [Default]\n"
    "plans:\n"
    "  - name: P\n"
    "    frequency: {freq}\n"
    "    entry_points:\n"
    "      - {{task: Default, state: A, min: {low}, max: 2}}\n"
    "    states: [{{name: A, description: {desc}}}]\n"
)
XML = (
    '<alica version="1">\n<task name="Default"/>\n<plan name="P">\n'
    '<entrypoint task="Default" state="A" min="{low}" max="2"/>\n<state name="A" description="{desc}"/>\n'
    "</plan>\n</alica>\n"
)


def plan(freq: str = "10", low: str = "1", desc: str = "ok") -> str:
    return PLAN.format(freq=freq, low=low, desc=desc)


# name -> (file text, expected 'LINE:COL: error: ' fragment)
CASES: dict[str, tuple[str | bytes, str]] = {
    "int_4301_digits.yaml": (plan(low="9" * 4301), "6:40: error: cannot read '9"),
    # a hexadecimal integer of 4000 characters has 4817 decimal digits, more than Python writes as text
    "hex_int_4000_digits.yaml": (plan(low="0x" + "f" * 4000), "6:40: error: cannot read '0xfff"),
    "tagged_int.yaml": (plan(low="!!int x"), "6:40: error: cannot read 'x' as a whole number"),
    "tagged_float.yaml": (plan(low="!!float x"), "6:40: error: cannot read 'x' as a number"),
    "month_13.yaml": (plan(desc="2020-13-45"), "7:37: error: cannot read '2020-13-45' as a date"),
    "frequency_400_digits.yaml": (plan(freq="9" * 400), "4:16: error: 'frequency' of plan 'P' is too large"),
    "min_nan.yaml": (
        plan(low=".nan"),
        "6:40: error: 'min' of an entry point of plan 'P' must be a whole number, not nan",
    ),
    "min_inf.yaml": (
        plan(low=".inf"),
        "6:40: error: 'min' of an entry point of plan 'P' must be a whole number, not inf",
    ),
    "min_1e999.xml": (
        XML.format(low="1e999", desc="ok"),
        "4:43: error: 'min' of an entry point of plan 'P' must be a whole number, not inf",
    ),
    "nested_lists.yaml": ("tasks: " + "[" * 999 + "]" * 999 + "\n", "1:107: error: mappings and lists are nested"),
    "nested_maps.yaml": ("tasks: " + "{a: " * 480 + "1" + "}" * 480 + "\n", "1:404: error: mappings and lists"),
    "nul_import.yaml": ('imports: ["a\\0b.yaml"]\ntasks: [Default]\n', "1:11: error: import path holds the control"),
    "long_import.yaml": ("imports: [" + "a" * 300 + ".yaml]\ntasks: [Default]\n", "1:11: error: cannot use import"),
    "not_utf8.yaml": (b"tasks: [Default]\n# caf\xe9\n", "2:6: error: the file is not UTF-8 text"),
    "not_utf8.xml": (b'<alica version="1">\n  <task name="\xff"/></alica>\n', "2:15: error: the file is not UTF-8"),
}


def run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    monkeypatch.chdir(tmp_path)
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == 1, err
    assert "Traceback" not in out + err and "internal error" not in err
    return err


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("command", ["validate", "convert"])
def test_hostile_file_is_one_located_error(
    name: str, command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    text, expected = CASES[name]
    path = tmp_path / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    out = "out.xml" if name.endswith(".yaml") else "out.yaml"
    argv = ["validate", name] if command == "validate" else ["convert", name, out]
    err = run(tmp_path, monkeypatch, capsys, *argv)
    assert f"{name}:{expected}" in err, err


def test_states_of_one_name_are_refused_by_convert_even_without_validation(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # a fuzzed file with 1000 states of one name: each state's transitions are written under it by name,
    # so convert wrote every transition 1000 times (70 s) and then refused its own output
    states = "".join(f"      - {{name: A, transitions: [{{to: A, condition: c{i}}}]}}\n" for i in range(200))
    text = (
        "tasks: [Default]\nplans:\n  - name: P\n    entry_points: [{task: Default, state: A}]\n    states:\n" + states
    )
    (tmp_path / "p.yaml").write_text(text, encoding="utf-8")
    err = run(tmp_path, monkeypatch, capsys, "convert", "p.yaml", "p.xml", "--no-validate")
    assert "p.yaml:7:9: error: plan 'P' has two states named 'A'" in err
    assert "199 problem(s) found" in err


def test_control_character_cannot_go_to_xml(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "p.yaml").write_text(plan(desc='"a\\x01b"'), encoding="utf-8")
    err = run(tmp_path, monkeypatch, capsys, "convert", "p.yaml", "p.xml")
    assert "p.yaml:7:39: error: the text holds the character U+0001, which XML cannot hold" in err
    assert not (tmp_path / "p.xml").exists()


def test_next_line_character_survives_xml_to_yaml(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "p.xml").write_text(XML.format(low="1", desc="a\u0085b"), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    assert main(["convert", "p.xml", "p.yaml"]) == 0, capsys.readouterr().err
    assert main(["convert", "p.yaml", "again.xml"]) == 0, capsys.readouterr().err
    assert "a\u0085b" in (tmp_path / "again.xml").read_text(encoding="utf-8")


def test_big_file_without_aliases_is_not_an_alias_bomb(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(yaml_format, "MAX_ALIAS_VALUES", 100)
    text = "tasks:\n" + "".join(f"  - name: T{i}\n    description: task {i}\n" for i in range(300))
    tree, problems = read_yaml(text, "big.yaml")
    assert tree is not None and problems == []
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
    tree, problems = read_yaml(bomb, "bomb.yaml")
    assert tree is None and "expands to more than 100 values" in problems[0].message


def test_merge_keys_count_as_alias_expansions(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(yaml_format, "MAX_ALIAS_VALUES", 10)
    base = "base: &b {" + ", ".join(f"k{i}: {i}" for i in range(6)) + "}\n"
    tree, problems = read_yaml(base + "one: {<<: *b}\n", "m.yaml")
    assert tree is not None and problems == []
    tree, problems = read_yaml(base + "one: {<<: *b}\ntwo: {<<: *b}\n", "m.yaml")
    assert tree is None and "through aliases" in problems[0].message


# --------------------------------------------------------------------------- imports stay in the plan folders


def write_set(folder: Path, import_line: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    entry = folder / "main.yaml"
    entry.write_text(f"imports: [{import_line}]\ntasks: [Default]\n", encoding="utf-8")
    return entry


def test_import_outside_the_plan_folders_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    secret = tmp_path / "elsewhere" / "secret.yaml"
    secret.parent.mkdir()
    secret.write_text("tasks: [{name: Secret, password_like_key: 1}]\n", encoding="utf-8")
    entry = write_set(tmp_path / "plans", "../elsewhere/secret.yaml")
    _, diagnostics = Loader().check(entry)
    assert [d.message for d in diagnostics] == ["import '../elsewhere/secret.yaml' is outside the plan folders"]
    assert (diagnostics[0].span.line, diagnostics[0].span.column) == (1, 11)
    absolute = write_set(tmp_path / "plans2", str(secret))
    assert "outside the plan folders" in Loader().check(absolute)[1][0].message


def test_imports_reach_the_search_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "tasks.yaml").write_text("tasks: [Shared]\n", encoding="utf-8")
    entry = write_set(tmp_path / "plans", "../shared/tasks.yaml")
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    assert Loader(search_path=[shared]).check(entry)[1] == []
    monkeypatch.setenv("ALICA_PLAN_PATH", str(shared))
    assert Loader().check(entry)[1] == []


def test_subfolders_and_shipped_plans_may_be_imported(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    (tmp_path / "plans" / "sub").mkdir(parents=True)
    (tmp_path / "plans" / "sub" / "more.yaml").write_text("tasks: [More]\n", encoding="utf-8")
    assert Loader().check(write_set(tmp_path / "plans", "sub/more.yaml"))[1] == []
    from alica.io.loader import plans_dir

    shipped = plans_dir() / "tasks.yaml"
    entry = tmp_path / "p.yaml"
    entry.write_text(f"imports: ['{shipped.as_posix()}']\nrolesets: []\n", encoding="utf-8")
    assert Loader().check(entry)[1] == []


# --------------------------------------------------------------------------- many attributes


class _CountingElement:
    """An lxml element that counts how often attribute values are asked for."""

    def __init__(self, element: object) -> None:
        self.element = element
        self.value_reads = 0
        self.nsmap = getattr(element, "nsmap", {})

    def keys(self) -> list[str]:
        return self.element.keys()  # type: ignore[attr-defined,no-any-return]

    def get(self, key: str) -> str | None:
        self.value_reads += 1
        return self.element.get(key)  # type: ignore[attr-defined,no-any-return]

    @property
    def attrib(self) -> object:
        self.value_reads += 1_000_000  # items() and values() walk the list once per value
        return self.element.attrib  # type: ignore[attr-defined]


def test_attribute_values_are_read_from_the_text_not_by_lookup() -> None:
    from lxml import etree

    from alica.io import xml_format

    attributes = " ".join(f'a{i}="v{i}"' for i in range(200))
    text = f'<alica version="1"><task name="T" {attributes}/></alica>'
    reader = xml_format._Reader(text, "a.xml")
    root = etree.fromstring(text.encode("utf-8"))
    reader.locate(root)
    counting = _CountingElement(root[0])
    reader.places[counting] = reader.places[root[0]]  # type: ignore[index]
    values = [value for _, _, value, _, _ in reader.attributes(counting)]
    assert values == ["T", *(f"v{i}" for i in range(200))]
    assert counting.value_reads == 0


def test_attribute_values_from_the_text_equal_the_parsers() -> None:
    from lxml import etree

    from alica.io.xml_format import read_xml

    text = (
        '<alica version="1">\n<task name="x&amp;y&#10;z&#x41;&lt;&gt;\tq\nr" '
        "description='it&apos;s \"fine\" &quot;'/>\n</alica>\n"
    )
    tree, problems = read_xml(text, "a.xml")
    assert tree is not None and problems == []
    task = tree.value["tasks"].value[0].value  # type: ignore[index,union-attr]
    parsed = etree.fromstring(text.encode("utf-8"))[0]
    assert task["name"].value == parsed.get("name") == "x&y\nzA<> q r"
    assert task["description"].value == parsed.get("description")


@pytest.mark.parametrize("marker", [".alica-project", "pyproject.toml", ".git"])
def test_imports_reach_the_entry_files_project_from_any_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, marker: str
) -> None:
    monkeypatch.delenv("ALICA_PLAN_PATH", raising=False)
    project = tmp_path / "project"
    (project / "plans").mkdir(parents=True)
    (project / "plans" / "tasks.yaml").write_text("tasks: [Shared]\n", encoding="utf-8")
    (tmp_path / "secret.yaml").write_text("tasks: [Secret]\n", encoding="utf-8")
    entry = write_set(project / "plans" / "lunar", "../tasks.yaml")
    assert "outside the plan folders" in Loader().check(entry)[1][0].message  # no marker: its own folder only
    monkeypatch.chdir(project)
    assert "outside the plan folders" in Loader().check(entry)[1][0].message  # the working folder plays no part
    (project / marker).mkdir() if marker == ".git" else (project / marker).write_text("", encoding="utf-8")
    for here in (project, tmp_path, project / "plans" / "lunar"):
        monkeypatch.chdir(here)
        assert Loader().check(entry)[1] == []  # plans/lunar may import plans/tasks.yaml, from anywhere
    escaping = write_set(project / "plans" / "other", "../../../secret.yaml")
    assert "outside the plan folders" in Loader().check(escaping)[1][0].message
