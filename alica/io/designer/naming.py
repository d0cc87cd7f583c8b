"""Our names for every imported element, and where each file is written.

Names are claimed file by file in sorted order, so an import of the same
folder always gives the same names. Behaviours, plans and plan types share
one namespace: plans claim first, then behaviours, then plan types; a later
element whose name is taken gets a suffix naming its kind (``Tackle.beh``
becomes ``TackleBehaviour`` beside the plan ``Tackle``). Predicates may not
take a name of a plan, behaviour, plan type or task (formulas read those as
symbols: ``succeeded(Tackle)``), nor one of the engine's own facts or a
registered function.
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from alica.io.designer.names import Namespace, is_placeholder, sanitize
from alica.io.designer.records import (
    BehaviourRec,
    Cond,
    ConditionRepoRec,
    FileRec,
    PlanRec,
    PlanTypeRec,
    RoleSetRec,
    TaskRepoRec,
)
from alica.io.designer.report import Construct, Note
from alica.lang import ENGINE_FACTS, ENGINE_VARIABLES, default_registry

#: Where the generated skill catalogue is written, relative to the output folder.
SKILLS_FILE = "skills.yaml"

_SHARED = "behaviours, plans and plan types"
_ABSTRACT = (("pml", "plan", "Plan"), ("beh", "behaviour", "Behaviour"), ("pty", "plan type", "Type"))


def base_reserved() -> frozenset[str]:
    """Names no imported element may take: the engine's facts, ``self`` and the registered functions."""
    return frozenset({s.name for s in ENGINE_FACTS} | ENGINE_VARIABLES | set(default_registry().names()))


@dataclass
class Names:
    """Our names, by designer file or id.

    Attributes:
        abstract: plan, behaviour and plan-type files -> our name.
        original: the same files -> the designer's name.
        skills: behaviour files -> the skill they run.
        tasks: task ids -> our name.
        rolesets: role-set files -> our name.
        predicates: condition ids (of repositories and inline conditions) -> predicate name.
        outputs: designer files -> the output file, relative to the output folder.
        notes: a note for every name that changed.
    """

    abstract: dict[str, str] = field(default_factory=dict)
    original: dict[str, str] = field(default_factory=dict)
    skills: dict[str, str] = field(default_factory=dict)
    tasks: dict[int, str] = field(default_factory=dict)
    rolesets: dict[str, str] = field(default_factory=dict)
    predicates: dict[int, str] = field(default_factory=dict)
    outputs: dict[str, str] = field(default_factory=dict)
    notes: list[Note] = field(default_factory=list)

    def claim(
        self,
        space: Namespace,
        raw: str,
        fallback: str,
        *,
        file: str,
        key: str,
        what: str,
        owner: str = "",
        suffix: str = "",
        element_id: int | None = None,
    ) -> str:
        """Claim a name in ``space`` and note a change (``what`` and ``owner`` name the element in the note)."""
        placeholder = is_placeholder(raw, element_id)
        name = space.claim("" if placeholder else raw, fallback, suffix)
        if placeholder:
            shown = f"the name '{raw}'" if raw.strip() else "no name"
            self.notes.append(
                Note(file, key, Construct.UNNAMED, f"a {what}{owner} has {shown} in the designer: named '{name}'")
            )
        elif name != raw:
            if sanitize(raw, fallback, space.reserved) == name:
                why = "a name formulas can read has letters, digits and '_' only, and is no keyword"
            else:
                why = "the name is taken" + (f" ({_SHARED} share one namespace)" if suffix else "")
            self.notes.append(Note(file, key, Construct.RENAMED, f"{what} '{raw}'{owner} is named '{name}': {why}"))
        return name


def output_paths(files: Iterable[str]) -> dict[str, str]:
    """Each designer file's output file: its path with ``.yaml`` for the extension (``plans/X.pml`` -> ``plans/X.yaml``).

    When two files would share an output (``Attack.pml`` and ``Attack.pty`` side by side), the later one in
    sorted order keeps its extension in the name (``Attack_pty.yaml``). ``skills.yaml`` at the top is taken by
    the skill catalogue.
    """
    taken = {SKILLS_FILE}
    out: dict[str, str] = {}
    for file in sorted(files):
        stem, ext = posixpath.splitext(file)
        candidates = [f"{stem}.yaml", f"{stem}_{ext.lstrip('.')}.yaml"]
        number = 2
        while all(c.lower() in taken for c in candidates):
            candidates.append(f"{stem}_{ext.lstrip('.')}_{number}.yaml")
            number += 1
        chosen = next(c for c in candidates if c.lower() not in taken)
        taken.add(chosen.lower())
        out[file] = chosen
    return out


def _stem(file: str) -> str:
    return posixpath.splitext(posixpath.basename(file))[0]


def _inline(record: FileRec) -> list[tuple[Cond, str, str]]:
    """The inline conditions of a plan or behaviour, disabled ones too: (condition, key, fallback name suffix)."""
    out: list[tuple[Cond | None, str, str]] = []
    if isinstance(record, (PlanRec, BehaviourRec)):
        out += [(record.pre, "preCondition", "PreCondition"), (record.run, "runtimeCondition", "RuntimeCondition")]
    if isinstance(record, BehaviourRec):
        out.append((record.post, "postCondition", "PostCondition"))
    if isinstance(record, PlanRec):
        for state in record.states:
            if state.terminal:
                suffix = f"{sanitize(state.name, 'State')}PostCondition"
                out.append((state.post, f"{state.key}.postCondition", suffix))
    return [(c, key, suffix) for c, key, suffix in out if c is not None]


def allocate(records: Mapping[str, FileRec], accepted: Sequence[str], reserved_skills: Iterable[str]) -> Names:
    """Name every element of the accepted files.

    Args:
        records: every record read, by file.
        accepted: the files that are imported.
        reserved_skills: skill names already declared (the installed catalogue): a generated skill gets another name.
    """
    names = Names()
    files = sorted(accepted)
    names.outputs = output_paths(files)
    base = base_reserved()
    tasks = Namespace(base)
    for file in files:
        record = records[file]
        if isinstance(record, TaskRepoRec):
            for task in record.tasks:
                names.tasks[task.id] = names.claim(
                    tasks, task.name, "Task", file=file, key=f"{task.key}.name", what="task", element_id=task.id
                )
    abstract = Namespace(base)
    for ext, what, suffix in _ABSTRACT:
        for file in files:
            record = records[file]
            if file.rsplit(".", 1)[-1].lower() != ext or not isinstance(record, (PlanRec, BehaviourRec, PlanTypeRec)):
                continue
            names.original[file] = record.name
            names.abstract[file] = names.claim(
                abstract,
                record.name,
                sanitize(_stem(file), what.title().replace(" ", "")),
                file=file,
                key="name",
                what=what,
                suffix=suffix,
                element_id=record.id,
            )
    rolesets = Namespace(base)
    skills = Namespace(reserved_skills)
    for file in files:
        record = records[file]
        if isinstance(record, RoleSetRec):
            names.rolesets[file] = names.claim(
                rolesets, record.name, sanitize(_stem(file), "RoleSet"), file=file, key="name", what="role set"
            )
        elif isinstance(record, BehaviourRec):
            skill = skills.claim(record.name, names.abstract[file])
            names.skills[file] = skill
            if skill != record.name:
                names.notes.append(
                    Note(
                        file,
                        "name",
                        Construct.RENAMED,
                        f"the skill of behaviour '{record.name}' is named '{skill}': the name is not valid or is "
                        "already a skill of the installed catalogue",
                    )
                )
    predicates = Namespace(base | set(names.abstract.values()) | set(names.tasks.values()))
    for file in files:
        record = records[file]
        if isinstance(record, ConditionRepoRec):
            for c in record.conditions:
                names.predicates[c.id] = names.claim(
                    predicates, c.name, "Condition", file=file, key=f"{c.key}.name", what="condition", element_id=c.id
                )
    for file in files:
        record = records[file]
        owner = names.abstract.get(file, "")
        for cond, key, suffix in _inline(record):
            names.predicates[cond.id] = names.claim(
                predicates,
                cond.name,
                sanitize(owner + suffix, "Condition"),
                file=file,
                key=f"{key}.name",
                what="condition",
                element_id=cond.id,
            )
    return names
