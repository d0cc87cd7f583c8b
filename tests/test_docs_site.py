"""The docs site's table of contents and links, checked without mkdocs.

``make docs`` builds the site with ``mkdocs build --strict``; these checks are
the cheap part of it that ``make test`` can run: every page in ``docs/`` is in
the navigation of ``mkdocs.yml`` and every navigation entry is a page, links
between pages name pages that exist, and every object the API reference
renders (``::: name``) can be imported.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
LINK = re.compile(r"\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.DOTALL | re.MULTILINE)
IDENTIFIER = re.compile(r"^:::\s+(\S+)", re.MULTILINE)


def nav_pages(nav: object) -> Iterator[str]:
    """Every page path named in an mkdocs ``nav`` tree (sections, titled and untitled entries)."""
    if isinstance(nav, str):
        if "://" not in nav:
            yield nav
    elif isinstance(nav, list):
        for item in nav:
            yield from nav_pages(item)
    elif isinstance(nav, dict):
        for value in nav.values():
            yield from nav_pages(value)


def page_links(text: str) -> Iterator[str]:
    """The targets of the Markdown links of a page, outside code blocks, without web addresses."""
    for target in LINK.findall(FENCE.sub("", text)):
        if not re.match(r"^[a-z][a-z0-9+.-]*:", target) and not target.startswith("#"):
            yield target.split("#", 1)[0]


def config() -> dict[str, object]:
    loaded = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    assert isinstance(loaded, dict)
    return loaded


def pages() -> list[str]:
    return sorted(path.relative_to(DOCS).as_posix() for path in DOCS.rglob("*.md"))


def test_nav_pages_walks_sections_and_titles() -> None:
    nav = [{"Home": "index.md"}, {"Part": ["a.md", {"B": "sub/b.md"}, {"Web": "https://example.org"}]}]
    assert list(nav_pages(nav)) == ["index.md", "a.md", "sub/b.md"]


def test_page_links_skips_code_web_and_anchors() -> None:
    text = "[a](a.md#x) [w](https://example.org) [s](#here)\n```md\n[c](code.md)\n```\n[b](../b.md)"
    assert list(page_links(text)) == ["a.md", "../b.md"]


def test_every_page_is_in_the_nav_once() -> None:
    listed = list(nav_pages(config()["nav"]))
    assert sorted(set(listed)) == sorted(listed), "a page appears twice in the nav"
    assert sorted(set(pages()) - set(listed)) == [], "pages in docs/ that mkdocs.yml's nav does not list"


def test_every_nav_entry_is_a_page() -> None:
    missing = [page for page in nav_pages(config()["nav"]) if not (DOCS / page).is_file()]
    assert missing == [], "nav entries of mkdocs.yml without a page in docs/"


@pytest.mark.parametrize("page", pages())
def test_links_name_pages_of_the_site(page: str) -> None:
    path = DOCS / page
    broken = []
    for target in page_links(path.read_text(encoding="utf-8")):
        resolved = (path.parent / target).resolve()
        if not target or not resolved.is_relative_to(DOCS.resolve()) or not resolved.exists():
            broken.append(target)
    assert broken == [], f"{page}: links that leave docs/ or name no file"


def _import(identifier: str) -> object:
    parts = identifier.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            value: object = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for name in parts[cut:]:
            value = getattr(value, name)
        return value
    raise ModuleNotFoundError(identifier)


def test_reference_objects_import() -> None:
    identifiers = [
        name
        for path in sorted((DOCS / "reference").glob("*.md"))
        for name in IDENTIFIER.findall(path.read_text(encoding="utf-8"))
    ]
    assert identifiers, "the API reference renders no object"
    for identifier in identifiers:
        _import(identifier)


def test_nested_lists_are_indented_for_python_markdown() -> None:
    pytest.importorskip("mkdocs")  # the hook module needs the docs extra
    pytest.importorskip("griffe")
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "tools" / "docs_hooks.py")
    assert spec is not None and spec.loader is not None
    hooks = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hooks)
    page = "1. top\n   of it\n   - inner\n     more\n2. next\n\n```\n  - code\n```\n- a\n  - b\n"
    expected = "1. top\n   of it\n    - inner\n      more\n2. next\n\n```\n  - code\n```\n- a\n    - b\n"
    assert hooks.nest_lists(page) == expected
