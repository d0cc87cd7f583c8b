"""mkdocs hook: lay out the packages by their installed names for the API reference.

The repository keeps one folder per layer (``alica/``, ``prophet/``,
``skills/``, ``worldsim/``) while they install under the one import name
``alica`` (see ``[tool.setuptools]`` in ``pyproject.toml``). mkdocstrings reads
packages from folders, so before each build this hook links every source file
into ``build/docs-api/`` by its installed name (``alica/skills/...`` for
``skills/...``); ``mkdocs.yml`` points the python handler's ``paths`` there.

The folder is the hook's own, so a build never races ``make check``, which lays
out ``build/typecheck/`` the same way.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import griffe
from mkdocs.plugins import event_priority

sys.path.insert(0, str(Path(__file__).resolve().parent))
from layout import ROOT, stage  # a sibling module, found through the line above

STAGE = ROOT / "build" / "docs-api"


@event_priority(100)  # before mkdocstrings sets up its handler
def on_config(config: Any) -> Any:
    """mkdocs event: stage the sources before any plugin reads them."""
    stage(STAGE)
    return config


ROLE = re.compile(r":(?:class|func|meth|attr|mod|data|exc|obj):`~?([^`]+)`")


class SphinxRoles(griffe.Extension):
    """griffe extension: show Sphinx roles of docstrings (``:class:`~a.B```) as code (`` `B` ``).

    The docstrings are written for Python's ``help()`` and for Sphinx-style
    readers; Markdown would print the role markup literally.
    """

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(_code, obj.docstring.value)


def _code(match: re.Match[str]) -> str:
    target = match.group(1)
    shown = target.rsplit(".", 1)[-1] if match.group(0).split("`", 1)[1].startswith("~") else target
    return f"`{shown}`"


ITEM = re.compile(r"^( *)([-*+]|\d+[.)]) +")


def nest_lists(markdown: str) -> str:
    """Indent nested list items by 4 spaces per level, as Python-Markdown needs.

    The pages are written for GitHub, where an item indented to its parent's
    text (2 or 3 spaces) is nested; Python-Markdown would flatten it into the
    parent list. Item lines, and the indented lines that follow them, are
    shifted to 4 spaces per level; fenced code is left alone.
    """
    out: list[str] = []
    stack: list[tuple[int, int]] = []  # per open item: (its text's column in the source, its indent on output)
    shift = 0
    fence = ""
    for line in markdown.split("\n"):
        stripped = line.lstrip(" ")
        indent = len(line) - len(stripped)
        if fence or stripped.startswith(("```", "~~~")):
            marker = stripped[:3]
            fence = "" if fence and stripped.startswith(fence) else (fence or marker)
            stack, shift = ([], 0) if indent == 0 else (stack, shift)
            out.append(line)
            continue
        item = ITEM.match(line)
        if item:
            while stack and indent < stack[-1][0]:
                stack.pop()
            level = stack[-1][1] + 4 if stack else 0
            shift = level - indent
            stack.append((len(item.group(0)), level))
            out.append(" " * level + stripped)
        elif not stripped:
            out.append(line)
        elif indent == 0:
            stack, shift = [], 0
            out.append(line)
        else:
            out.append(" " * max(indent + shift, 0) + stripped)
    return "\n".join(out)


def on_page_markdown(markdown: str, **kwargs: Any) -> str:
    """mkdocs event: nest the page's lists the way GitHub shows them."""
    return nest_lists(markdown)
