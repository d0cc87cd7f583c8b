"""Import a folder of ALICA Plan Designer files: read, check, name, map, render.

The steps, each in its own module:

1. find the designer files (and the agent configs) under the folder, in sorted order;
2. read each into typed records (:mod:`~alica.io.designer.records`), a bad file into errors;
3. resolve references and refuse the files that cannot be imported (:mod:`~alica.io.designer.resolve`);
4. name every element (:mod:`~alica.io.designer.naming`);
5. map each file to one of our documents (:mod:`~alica.io.designer.plans`, :mod:`~alica.io.designer.elements`);
6. render each as YAML text under a header (:mod:`~alica.io.designer.writer`).

Nothing is written until :func:`write_result`; the same folder always gives
the same result.
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from alica.io.designer.agent_config import agent_config_notes, other_config_note
from alica.io.designer.context import Context, Mapped
from alica.io.designer.elements import (
    map_behaviour,
    map_conditions,
    map_plantype,
    map_roleset,
    map_tasks,
    note_placeholder,
    skill_catalogue,
)
from alica.io.designer.naming import SKILLS_FILE, allocate
from alica.io.designer.plans import map_plan
from alica.io.designer.reader import read_file
from alica.io.designer.records import (
    KINDS,
    BehaviourRec,
    ConditionRepoRec,
    FileRec,
    PlaceholderRec,
    PlanRec,
    PlanTypeRec,
    RoleSetRec,
    TaskRepoRec,
)
from alica.io.designer.report import FileError, Note
from alica.io.designer.resolve import Index, Resolver, decide
from alica.io.designer.writer import document_text, header, skills_text
from alica.io.plan_paths import PROJECT_MARKER
from alica.source import byte_place

#: The name of the C++ engine's agent config files.
AGENT_CONFIG = "alica.yaml"


@dataclass
class ImportResult:
    """What an import gives.

    Attributes:
        files: the number of designer files read (plans, behaviours, plan types, role sets,
            task and condition repositories, placeholders).
        outputs: output files (relative to the output folder, ``/``-separated) -> their text, sorted.
        notes: every note, by file and key.
        errors: every error, by file and key; a file with an error is not written.
    """

    files: int = 0
    outputs: dict[str, str] = field(default_factory=dict)
    notes: list[Note] = field(default_factory=list)
    errors: list[FileError] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        """Whether every file was imported (notes allowed)."""
        return not self.errors


def _relative(root: Path, path: Path) -> str:
    return path.relative_to(root).as_posix()


def discover(src: Path) -> tuple[list[str], list[str], list[str]]:
    """The designer files, agent configs and other config files under ``src`` (relative, sorted)."""
    designer, configs, other = [], [], []
    for path in sorted(src.rglob("*")):
        if not path.is_file():
            continue
        rel = _relative(src, path)
        ext = path.suffix.lower().lstrip(".")
        if ext in KINDS:
            designer.append(rel)
        elif path.name.lower() == AGENT_CONFIG:
            configs.append(rel)
        elif ext == "conf":
            other.append(rel)
    return sorted(designer), sorted(configs), sorted(other)


def _read_text(path: Path, rel: str) -> tuple[str | None, FileError | None]:
    try:
        data = path.read_bytes()
    except OSError as exc:
        return None, FileError(rel, "", f"cannot read the file: {exc.strerror or exc}")
    try:
        return data.decode("utf-8-sig"), None
    except UnicodeDecodeError as exc:
        place = byte_place(data, exc.start, rel)
        return None, FileError(rel, "", f"not UTF-8 text (byte 0x{data[exc.start]:02x})", place.line, place.column)


def _describe(record: FileRec) -> str:
    kind = KINDS[record.file.rsplit(".", 1)[-1].lower()]
    return f"{kind} '{record.name}', id {record.id}"


def import_designer(src: Path, reserved_skills: Iterable[str] = ()) -> ImportResult:
    """Import every designer file under ``src``.

    Args:
        src: the folder of the designer files (e.g. a package's ``etc``).
        reserved_skills: skill names already declared (the installed catalogue); a generated skill
            never takes one (it would run that skill instead of the behaviour's own).

    Returns:
        The outputs, notes and errors; nothing is written.
    """
    designer, configs, others = discover(src)
    records, unreadable, read_errors = _read_all(src, designer)
    index = Index(records, [*unreadable, *(e.file for e in read_errors)])
    decision = decide(index, unreadable, read_errors)
    accepted = [f for f in sorted(records) if f not in decision.refused]
    written = [f for f in accepted if not isinstance(records[f], PlaceholderRec)]
    names = allocate(records, written, reserved_skills)
    ctx = Context(records, Resolver(index, decision.refused, decision.cut), names)
    mapped = _map_all(ctx, [records[f] for f in accepted])
    notes = names.notes + decision.notes + ctx.notes
    errors = list(decision.errors)
    for rel in configs:
        text, problem = _read_text(src / rel, rel)
        config_notes, config_errors = agent_config_notes(text, rel) if text is not None else ([], [])
        notes += config_notes
        errors += config_errors + ([problem] if problem is not None else [])
    notes += [other_config_note(rel) for rel in others]
    notes.sort(key=Note.sort_key)
    outputs = _render(ctx, mapped, notes)
    behaviours = [r for r in (records[f] for f in written) if isinstance(r, BehaviourRec)]
    if behaviours:
        head = header(
            "the ALICA Plan Designer's behaviours",
            "one skill per behaviour, without parameters; give each an implementation with --skills MODULE",
            [],
        )
        outputs[SKILLS_FILE] = skills_text(skill_catalogue(ctx, behaviours), head)
    return ImportResult(len(designer), dict(sorted(outputs.items())), notes, sorted(errors))


def _read_all(src: Path, designer: list[str]) -> tuple[dict[str, FileRec], list[str], list[FileError]]:
    """The records of the files that could be read, the files that could not, and every problem found."""
    records: dict[str, FileRec] = {}
    unreadable: list[str] = []
    errors: list[FileError] = []
    for rel in designer:
        text, problem = _read_text(src / rel, rel)
        record, found = read_file(text, rel) if text is not None else (None, [problem] if problem else [])
        errors.extend(found)
        if record is None:
            unreadable.append(rel)
        else:
            records[rel] = record
    return records, unreadable, errors


def _map_all(ctx: Context, records: list[FileRec]) -> dict[str, Mapped]:
    """Map the accepted files (placeholders only get their note)."""
    mapped: dict[str, Mapped] = {}
    for record in records:  # plans first: they tell which standard conditions stay predicates
        if isinstance(record, PlanRec):
            mapped[record.file] = map_plan(ctx, record)
    for record in records:
        if isinstance(record, TaskRepoRec):
            mapped[record.file] = map_tasks(ctx, record)
        elif isinstance(record, RoleSetRec):
            mapped[record.file] = map_roleset(ctx, record)
        elif isinstance(record, BehaviourRec):
            mapped[record.file] = map_behaviour(ctx, record)
        elif isinstance(record, PlanTypeRec):
            mapped[record.file] = map_plantype(ctx, record)
        elif isinstance(record, PlaceholderRec):
            note_placeholder(ctx, record)
    for record in records:
        if isinstance(record, ConditionRepoRec):
            mapped[record.file] = map_conditions(ctx, record)
    return mapped


def _render(ctx: Context, mapped: dict[str, Mapped], notes: list[Note]) -> dict[str, str]:
    """Each mapped file as YAML text under its header, by output path."""
    by_file: dict[str, list[str]] = {}
    for note in notes:
        by_file.setdefault(note.file, []).append(f"{note.key}: {note.message}" if note.key else note.message)
    outputs: dict[str, str] = {}
    for rel, m in mapped.items():
        out = ctx.names.outputs[rel]
        folder = posixpath.dirname(out) or "."
        needs = {posixpath.relpath(ctx.names.outputs[n], folder) for n in m.needs if n in ctx.names.outputs}
        imports = sorted(needs) + ([posixpath.relpath(SKILLS_FILE, folder)] if m.skills else [])
        head = header(f"the ALICA Plan Designer file {rel}", _describe(ctx.records[rel]), by_file.get(rel, []))
        outputs[out] = document_text(m.document, imports, head)
    return outputs


def write_result(result: ImportResult, out: Path) -> list[str]:
    """Write the outputs under ``out`` (created if needed); returns the files written, relative and sorted.

    Raises:
        OSError: a file cannot be written.
    """
    for rel, text in result.outputs.items():
        target = out.joinpath(*rel.split("/"))
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    if result.outputs:  # its files import each other across its folders: make it a project of its own
        marker = out / PROJECT_MARKER
        if not marker.exists():
            marker.write_text(
                "# Marks a project of alica plan files: files below this folder may import each other.\n",
                encoding="utf-8",
            )
    return list(result.outputs)
