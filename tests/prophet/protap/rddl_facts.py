"""Reading the facts back out of a generated ProTaP instance, for tests that compare facts, not strings."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

_FACT = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\(([^)]*)\)\s*=\s*([^;]+);")
_OBJECTS = re.compile(r"^\s*([A-Za-z]+)\s*:\s*\{([^}]*)\};")
_SETTING = re.compile(r"^\s*(domain|non-fluents|max-nondef-actions|horizon|discount)\s*=\s*([^;]+);")
_BLOCK = re.compile(r"^\s*(non-fluents|instance)\s+([A-Za-z0-9_]+)\s*\{")


@dataclass
class Facts:
    """The objects by type, the non-fluent and init-state facts and the settings of an instance text."""

    objects: dict[str, list[str]] = field(default_factory=dict)
    non_fluents: dict[tuple[str, tuple[str, ...]], str] = field(default_factory=dict)
    init: dict[tuple[str, tuple[str, ...]], str] = field(default_factory=dict)
    settings: dict[str, str] = field(default_factory=dict)
    blocks: dict[str, str] = field(default_factory=dict)


def read_facts(text: str) -> Facts:
    """Parse the line-per-fact layout the generator writes; comments are dropped."""
    facts = Facts()
    section = ""
    for raw in text.splitlines():
        line = raw.split("//", 1)[0]
        if block := _BLOCK.match(line):
            facts.blocks[block.group(1)] = block.group(2)
            continue
        if "init-state" in line:
            section = "init"
            continue
        if re.match(r"^\s*non-fluents\s*\{", line):
            section = "nf"
            continue
        if objects := _OBJECTS.match(line):
            facts.objects[objects.group(1)] = [name.strip() for name in objects.group(2).split(",") if name.strip()]
            continue
        if fact := _FACT.match(line):
            key = (fact.group(1), tuple(arg.strip() for arg in fact.group(2).split(",")))
            (facts.init if section == "init" else facts.non_fluents)[key] = fact.group(3).strip()
            continue
        if setting := _SETTING.match(line):
            facts.settings[setting.group(1)] = setting.group(2).strip()
    return facts
