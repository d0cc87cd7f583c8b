"""Build documents and validate them in tests without touching the disk."""

from __future__ import annotations

import textwrap

from alica.io.fields import Problems
from alica.io.loader import read_text
from alica.io.validate import Validator
from alica.lang import default_registry
from alica.lang.skills import ParamSpec, SkillRegistry
from alica.model import Document
from alica.source import Diagnostic


def test_skills() -> SkillRegistry:
    """A small registry for validator tests."""
    reg = SkillRegistry()
    reg.declare("DriveTo", ParamSpec("goal", "position"), ParamSpec("tolerance", "float", required=False, default=0.3))
    reg.declare("Grasp", ParamSpec("object", "object"), ParamSpec("retries", "int", required=False, default=3))
    reg.declare("Idle")
    return reg


test_skills.__test__ = False  # type: ignore[attr-defined]


def document(text: str, name: str = "doc.yaml") -> Document:
    """Build a document from YAML text, failing on any structural problem."""
    doc, problems = read_text(textwrap.dedent(text), name)
    assert not problems, [p.format() for p in problems]
    return doc


def problems_of(text: str, name: str = "doc.yaml") -> list[Diagnostic]:
    """Every problem of a one-file document set, structural and semantic."""
    doc, diagnostics = read_text(textwrap.dedent(text), name)
    problems = Problems()
    problems.items.extend(diagnostics)
    Validator([doc], test_skills(), default_registry(), problems).run()
    return sorted(problems.items)


def messages(text: str) -> list[str]:
    """The formatted problems of a one-file document set."""
    return [p.format() for p in problems_of(text)]
