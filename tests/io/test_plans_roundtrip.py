"""Every shipped plan file is valid and survives YAML <-> XML conversion unchanged."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest
import yaml

from alica.io import dump_document, format_of, load_document, load_library, read_text, validate_paths
from tests.conftest import PLANS

FILES = sorted(p for p in PLANS.rglob("*") if format_of(p) is not None)
IDS = [str(p.relative_to(PLANS)) for p in FILES]


def test_shipped_plans_are_valid() -> None:
    problems = validate_paths([PLANS])
    assert not problems, "\n".join(p.format() for p in problems)


@pytest.mark.parametrize("path", FILES, ids=IDS)
@pytest.mark.parametrize("first,second", [("yaml", "yaml"), ("xml", "xml"), ("xml", "yaml"), ("yaml", "xml")])
def test_round_trip(path: Path, first: str, second: str) -> None:
    original = load_document(path)
    text = dump_document(original, first)
    once, problems = read_text(text, f"once.{first}", first)
    assert not problems, [p.format() for p in problems]
    assert once == original
    twice, problems = read_text(dump_document(once, second), f"twice.{second}", second)
    assert not problems and twice == original


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_library_of_each_file_loads(path: Path) -> None:
    library = load_library(path)
    assert library.documents


def test_xml_twins_mean_the_same_as_their_yaml() -> None:
    twins = [p for p in FILES if p.suffix == ".xml" and p.with_suffix(".yaml").exists()]
    assert len(twins) >= 2, "the role set and one mission ship in XML too"
    for xml_file in twins:
        assert load_document(xml_file) == load_document(xml_file.with_suffix(".yaml")), xml_file


def test_yaml_files_match_the_json_schema() -> None:
    import jsonschema

    schema = json.loads(resources.files("alica.io").joinpath("schema/plan.schema.json").read_text(encoding="utf-8"))
    for path in FILES:
        if path.suffix == ".yaml":
            jsonschema.validate(yaml.safe_load(path.read_text(encoding="utf-8")), schema)


def test_xml_files_match_the_xsd() -> None:
    from lxml import etree

    xsd = etree.XMLSchema(etree.parse(str(resources.files("alica.io").joinpath("schema/plan.xsd"))))
    for path in FILES:
        if path.suffix == ".xml":
            assert xsd.validate(etree.parse(str(path))), (path, xsd.error_log)


@pytest.mark.parametrize("first,second", [("yaml", "yaml"), ("xml", "xml"), ("xml", "yaml"), ("yaml", "xml")])
def test_a_skill_catalogue_round_trips_like_the_shipped_files(tmp_path: Path, first: str, second: str) -> None:
    from tests.io.test_skill_declarations import CATALOGUE, parameters

    path = tmp_path / "skills.yaml"
    path.write_text(CATALOGUE, encoding="utf-8")
    original = load_document(path)
    once, problems = read_text(dump_document(original, first), f"once.{first}", first)
    assert not problems and once == original
    twice, problems = read_text(dump_document(once, second), f"twice.{second}", second)
    assert not problems and twice == original
    assert [parameters(s) for s in twice.skills] == [parameters(s) for s in original.skills]
