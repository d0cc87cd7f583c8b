"""Docs pages as tested truth: their example files, their shell blocks and the outputs they show.

A page is read as a sequence of fenced code blocks:

- A block whose attributes hold ``title="PATH"`` is an example file (``title="PATH
  (continued)"`` appends to it after two blank lines).
- An ``sh`` block is run. The ``text`` block right after it is what it prints: its
  lines exactly, a line ``...`` for any lines, and ``~NUMBER`` for a number that varies
  from run to run (a wall-clock time, a speed-up); everything else must match.
- Lines of an ``sh`` block that install the library (``python3 -m venv``, activating
  it, ``pip install``, ``make``) are not run: the test installed it the same way.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

BLOCK = re.compile(r"^```(\w*)([^\n]*)\n(.*?)^```\s*$", re.DOTALL | re.MULTILINE)
TITLE = re.compile(r'title="([^"\s]+)( \(continued\))?"')
INSTALL = re.compile(r"^(make\b|python3? -m venv\b|\. \.venv/bin/activate|source \.venv/bin/activate|pip install\b)")
VARYING = re.compile(r"~(\d+(?:\.\d+)?)")
NUMBER = r"[-+]?\d+(?:\.\d+)?"


@dataclass(frozen=True)
class Block:
    """A fenced code block: its language, its attributes and its text."""

    language: str
    attributes: str
    text: str


@dataclass(frozen=True)
class Step:
    """A shell block to run, with the output its page shows after it (``None``: none shown)."""

    script: str
    output: str | None

    @property
    def expects_failure(self) -> bool:
        """Whether the shown output is an error, so the script must exit non-zero."""
        return self.output is not None and re.search(r"\berror\b|: failure after", self.output) is not None


def blocks(page: str) -> list[Block]:
    """The page's fenced code blocks, in order."""
    return [Block(lang, attributes.strip(), text) for lang, attributes, text in BLOCK.findall(page)]


def example_files(page: str) -> dict[str, str]:
    """The page's example files by relative path, as the page builds them."""
    files: dict[str, str] = {}
    for block in blocks(page):
        found = TITLE.search(block.attributes)
        if found is None:
            continue
        name, continued = found.groups()
        if continued:
            assert name in files, f"'{block.attributes}' continues a file the page has not started"
            files[name] += "\n\n" + block.text
        else:
            assert name not in files, f"the page starts {name} twice"
            files[name] = block.text
    return files


def runnable(script: str) -> str:
    """A shell block without its install lines (see the module's docstring)."""
    return "\n".join(line for line in script.splitlines() if not INSTALL.match(line.strip()))


def steps(page: str) -> list[Step]:
    """Every shell block of the page that runs something, with the output shown after it."""
    found = []
    listed = [*blocks(page), Block("", "", "")]
    for block, after in pairwise(listed):
        if block.language != "sh" or not runnable(block.text).strip():
            continue
        found.append(Step(runnable(block.text), after.text if after.language == "text" else None))
    return found


def pattern(output: str) -> re.Pattern[str]:
    """What a shown output matches: its lines exactly, ``...`` for any lines, ``~N`` for any number."""
    parts = []
    for line in output.splitlines():
        if line == "...":
            parts.append(r"(?:.*\n)*?")
            continue
        pieces = VARYING.split(line)  # text, number, text, number, ..., text
        parts.append("".join(NUMBER if i % 2 else re.escape(piece) for i, piece in enumerate(pieces)) + r"\n")
    return re.compile("".join(parts))


def write_files(page: str, folder: Path) -> None:
    """Write the page's example files into ``folder``."""
    for name, text in example_files(page).items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
