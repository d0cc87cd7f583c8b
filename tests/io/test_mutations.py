"""Mutated plan files either load or raise PlanFormatError: never anything else.

Two kinds of mutation: on the text (characters deleted, inserted, lines
swapped or duplicated) and on the data (a value replaced by one of another
type, a key renamed, an entry dropped), both over every shipped plan file.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.errors import PlanFormatError
from alica.io import load_library
from alica.io.yaml_format import write_yaml
from tests.conftest import PLANS

FILES = sorted(p for p in PLANS.rglob("*") if p.suffix in (".yaml", ".xml"))
SAMPLES = st.sampled_from(FILES) if FILES else st.nothing()

ODD_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 5),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.lists(st.integers(0, 3), max_size=3),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    st.sampled_from(["*", "$x", "forall x in T:", "On(a,", "-2", "1e400", "Nope", "success", "?r - robot"]),
)


def _load(tmp: Path, path: Path, text: str) -> None:
    target = tmp / "plans" / path.relative_to(PLANS)
    target.write_text(text, encoding="utf-8")
    try:
        load_library(target)
    except PlanFormatError as exc:
        assert exc.diagnostics
        for d in exc.diagnostics:
            assert d.span.line >= 0 and d.message


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("mutations")
    shutil.copytree(PLANS, tmp / "plans")
    return tmp


def _restore(tmp: Path, path: Path) -> None:
    shutil.copyfile(path, tmp / "plans" / path.relative_to(PLANS))


@settings(max_examples=150)
@given(path=SAMPLES, data=st.data())
def test_text_mutations(workdir: Path, path: Path, data: st.DataObject) -> None:
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines(keepends=True)
    kind = data.draw(st.sampled_from(["delete", "insert", "swap", "duplicate", "truncate"]))
    if kind == "delete" and text:
        i = data.draw(st.integers(0, len(text) - 1))
        n = data.draw(st.integers(1, 8))
        text = text[:i] + text[i + n :]
    elif kind == "insert":
        i = data.draw(st.integers(0, len(text)))
        text = (
            text[:i]
            + data.draw(st.sampled_from([":", "-", "[", "{", "'", '"', "<", ">", "&", "\t", "  ", "\n", "*", "#", "x"]))
            + text[i:]
        )
    elif kind == "swap" and len(lines) > 1:
        i = data.draw(st.integers(0, len(lines) - 2))
        lines[i], lines[i + 1] = lines[i + 1], lines[i]
        text = "".join(lines)
    elif kind == "duplicate" and lines:
        i = data.draw(st.integers(0, len(lines) - 1))
        lines.insert(i, lines[i])
        text = "".join(lines)
    elif kind == "truncate":
        text = text[: data.draw(st.integers(0, len(text)))]
    try:
        _load(workdir, path, text)
    finally:
        _restore(workdir, path)


def _paths(value: object, prefix: tuple = ()) -> list[tuple]:  # type: ignore[type-arg]
    out = [prefix]
    if isinstance(value, dict):
        for k, v in value.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out += _paths(v, (*prefix, i))
    return out


@settings(max_examples=150)
@given(path=st.sampled_from([p for p in FILES if p.suffix == ".yaml"]) if FILES else st.nothing(), data=st.data())
def test_data_mutations(workdir: Path, path: Path, data: st.DataObject) -> None:
    tree = yaml.safe_load(path.read_text(encoding="utf-8"))
    where = data.draw(st.sampled_from(_paths(tree)[1:]))
    parent = tree
    for key in where[:-1]:
        parent = parent[key]
    last = where[-1]
    action = data.draw(st.sampled_from(["replace", "drop", "rename"]))
    if action == "replace":
        parent[last] = data.draw(ODD_VALUES)
    elif action == "drop":
        del parent[last]
    elif isinstance(parent, dict):
        parent[data.draw(st.text(min_size=1, max_size=8)) + "_"] = parent.pop(last)
    try:
        _load(workdir, path, write_yaml(tree))
    finally:
        _restore(workdir, path)


def test_there_are_files_to_mutate() -> None:
    assert len(FILES) >= 10
