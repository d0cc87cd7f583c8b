"""References between designer files, and which files can be imported.

Every element with an id that another file may name is indexed: the files
themselves (plans, behaviours, plan types, placeholders), tasks, conditions
and variables. A reference ``File.ext#id`` is resolved by its id; the id must
exist and be of a kind the key allows. References inside a file (a state's
id in an entry point, a transition's in a synchronisation) must name an
element of that file.

A file is *refused* (not written) when it cannot be read, refers to
nothing, closes a cycle of the plan tree, needs a task of a refused task
repository, or is a plan type left without plans. A cycle that runs through
a plan type with another alternative is broken there instead: the plan that
leads back is left out of the type, with a note (the C++ engine chooses a
type's plan at run time and allows the recursion; our plan trees have none). Other references to a
refused file are dropped where they are used, with a note, so what is
written still validates; :func:`decide` repeats the checks until no more
files are refused.
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from alica.io.designer.json_view import Ref
from alica.io.designer.records import (
    KINDS,
    BehaviourRec,
    ConditionRepoRec,
    FileRec,
    PlanRec,
    PlanTypeRec,
    RoleSetRec,
    TaskRepoRec,
)
from alica.io.designer.report import Construct, FileError, Note

#: What a child of a state may be.
CHILD_KINDS = ("pml", "beh", "pty", "plh")

_KIND_NAMES = {
    **KINDS,
    "task": "task",
    "condition": "condition",
    "variable": "variable",
}


@dataclass(frozen=True, slots=True)
class Target:
    """An element a reference may name: its file, kind (an extension, or task/condition/variable) and id."""

    file: str
    kind: str
    id: int


class Index:
    """Every referable element of the files read, by id.

    Args:
        records: the records of the files that could be read, by file.
        unreadable: files that could not be read, or not without errors: their ids are unknown or
            unreliable, so a reference by their file name to an id nobody has is to a refused file.
    """

    def __init__(self, records: Mapping[str, FileRec], unreadable: Iterable[str]) -> None:
        self.records = records
        self.by_id: dict[int, Target] = {}
        self.errors: list[FileError] = []
        self.unreadable = {posixpath.basename(f): f for f in unreadable}
        for file in sorted(records):
            for element_id, kind, key in _referable(records[file]):
                other = self.by_id.get(element_id)
                if other is not None:
                    where = "another element of this file" if other.file == file else f"an element of {other.file}"
                    self.errors.append(FileError(file, key, f"id {element_id} is also the id of {where}"))
                    continue
                self.by_id.setdefault(element_id, Target(file, kind, element_id))

    def find(self, ref: Ref, kinds: Iterable[str]) -> tuple[Target | None, str | None, str]:
        """Resolve ``ref`` by its id.

        Returns:
            ``(target, refused_file, problem)``: the target when found; else the
            unreadable file the reference names (its ids are unknown), or a
            problem (empty when there is none).
        """
        kinds = tuple(kinds)
        target = self.by_id.get(ref.id)
        if target is None:
            unreadable = self.unreadable.get(posixpath.basename(ref.file))
            if unreadable is not None:
                return None, unreadable, ""
            return None, None, f"'{ref.text}' refers to nothing"
        if target.kind not in kinds:
            wanted = " or ".join(_KIND_NAMES[k] for k in kinds)
            return None, None, f"'{ref.text}' refers to a {_KIND_NAMES[target.kind]} of {target.file}, not a {wanted}"
        return target, None, ""


def _referable(record: FileRec) -> list[tuple[int, str, str]]:
    """``(id, kind, key)`` of each element of ``record`` another file may name."""
    ext = record.file.rsplit(".", 1)[-1].lower()
    out = [(record.id, ext, "id")]
    if isinstance(record, TaskRepoRec):
        out += [(t.id, "task", t.key) for t in record.tasks]
    elif isinstance(record, ConditionRepoRec):
        out += [(c.id, "condition", c.key) for c in record.conditions]
    elif isinstance(record, (PlanRec, BehaviourRec, PlanTypeRec)):
        out += [(v.id, "variable", v.key) for v in record.variables]
    return out


@dataclass
class Decision:
    """Which files are imported, and why the others are not.

    Attributes:
        refused: refused files (the unreadable ones among them).
        errors: every error, of every refused file.
        notes: notes on the references of the imported files.
        cut: plans left out of plan types to break cycles: (plan-type file, key of the reference).
    """

    refused: set[str] = field(default_factory=set)
    errors: list[FileError] = field(default_factory=list)
    notes: list[Note] = field(default_factory=list)
    cut: set[tuple[str, str]] = field(default_factory=set)


class Resolver:
    """Resolves references for the mapping, once :func:`decide` has refused files.

    Args:
        index: the index of every file read.
        refused: the refused files.
        cut: the references left out to break cycles.
    """

    def __init__(self, index: Index, refused: set[str], cut: set[tuple[str, str]]) -> None:
        self.index = index
        self.refused = refused
        self.cut = cut

    def is_cut(self, file: str, key: str) -> bool:
        """Whether the reference at ``key`` of ``file`` was left out to break a cycle."""
        return (file, key) in self.cut

    def target(self, ref: Ref | None, kinds: Iterable[str]) -> Target | None:
        """The element ``ref`` names; ``None`` when it lies in a refused file (or is unset)."""
        if ref is None:
            return None
        target, _, _ = self.index.find(ref, kinds)
        if target is None or target.file in self.refused:
            return None
        return target

    def record(self, target: Target) -> FileRec:
        """The record of the file holding ``target``."""
        return self.index.records[target.file]


def decide(index: Index, unreadable: Iterable[str], read_errors: Iterable[FileError]) -> Decision:
    """Check every reference and the plan tree, and refuse files until the rest can be imported."""
    decision = Decision()
    decision.refused.update(unreadable)
    decision.errors.extend(read_errors)
    decision.refused.update(e.file for e in decision.errors)
    for error in index.errors:
        decision.errors.append(error)
        decision.refused.add(error.file)
    for file in sorted(index.records):
        errors, notes = _check(index, index.records[file])
        decision.notes.extend(notes)
        if errors:
            decision.errors.extend(errors)
            decision.refused.add(file)
    changed = True
    while changed:
        changed = False
        for file in sorted(index.records):
            if file in decision.refused:
                continue
            errors = _dependencies(index, index.records[file], decision.refused, decision.cut)
            if errors:
                decision.errors.extend(errors)
                decision.refused.add(file)
                changed = True
        cycle = _cycle(index, decision.refused, decision.cut)
        if cycle is not None:
            _break(index, cycle, decision.refused, decision.cut, decision)
            changed = True
    decision.notes = [n for n in decision.notes if n.file not in decision.refused]
    return decision


class _Checker:
    """Collects the problems of one file's references."""

    def __init__(self, index: Index, file: str) -> None:
        self.index = index
        self.file = file
        self.errors: list[FileError] = []
        self.notes: list[Note] = []

    def ref(self, ref: Ref | None, kinds: Iterable[str]) -> Target | None:
        if ref is None:
            return None
        target, _, problem = self.index.find(ref, kinds)
        if problem:
            self.errors.append(FileError(self.file, ref.key, problem))
        if target is not None and posixpath.basename(ref.file) != posixpath.basename(target.file):
            self.notes.append(
                Note(
                    self.file,
                    ref.key,
                    Construct.REFERENCE,
                    f"'{ref.text}' names {ref.file}, but id {ref.id} is in {target.file}; resolved by the id",
                )
            )
        return target

    def local(self, value: int | None, known: Iterable[int], key: str, what: str) -> None:
        if value is not None and value not in set(known):
            self.errors.append(FileError(self.file, key, f"{value} is the id of no {what} of this plan"))


def _check(index: Index, record: FileRec) -> tuple[list[FileError], list[Note]]:
    """The problems of the references of one file that do not depend on which files are refused."""
    c = _Checker(index, record.file)
    if isinstance(record, PlanRec):
        _check_plan(c, record)
    elif isinstance(record, PlanTypeRec):
        for annotated in record.plans:
            c.ref(annotated.plan, ("pml",))
    elif isinstance(record, RoleSetRec):
        if not -1.0 <= record.default_priority <= 1.0:
            c.errors.append(FileError(c.file, "defaultPriority", f"{record.default_priority:g} is outside [-1, 1]"))
        for role in record.roles:
            for priority in role.priorities:
                c.ref(priority.task, ("task",))
                if not -1.0 <= priority.value <= 1.0:
                    c.errors.append(FileError(c.file, priority.key, f"priority {priority.value:g} is outside [-1, 1]"))
    return c.errors, c.notes


def _check_plan(c: _Checker, plan: PlanRec) -> None:
    states = [s.id for s in plan.states]
    transitions = [t.id for t in plan.transitions]
    variables = [v.id for v in plan.variables]
    seen: dict[int, str] = {}
    for element_id, key in (
        [(s.id, s.key) for s in plan.states]
        + [(t.id, t.key) for t in plan.transitions]
        + [(e.id, e.key) for e in plan.entry_points]
        + [(s.id, s.key) for s in plan.syncs]
    ):
        if element_id in seen:
            c.errors.append(FileError(c.file, f"{key}.id", f"id {element_id} is also the id of {seen[element_id]}"))
        seen.setdefault(element_id, key)
    for ep in plan.entry_points:
        if ep.task is None:
            c.errors.append(FileError(c.file, f"{ep.key}.task", "the entry point names no task"))
        c.ref(ep.task, ("task",))
        if ep.state is None:
            c.errors.append(FileError(c.file, f"{ep.key}.state", "the entry point has no initial state"))
        c.local(ep.state, states, f"{ep.key}.state", "state")
        if ep.min < 0 or ep.min > ep.max:
            c.errors.append(FileError(c.file, ep.key, f"cardinality [{ep.min}, {ep.max}] is empty or negative"))
    if not plan.entry_points:
        c.errors.append(FileError(c.file, "entryPoints", "the plan has no entry point"))
    for state in plan.states:
        for wrapper in state.wrappers:
            c.ref(wrapper.target, CHILD_KINDS)
        for binding in state.bindings:
            c.local(binding.variable, variables, f"{binding.key}.variable", "variable")
            sub_plan = c.ref(binding.sub_plan, CHILD_KINDS)
            sub_variable = c.ref(binding.sub_variable, ("variable",))
            if sub_plan is not None and sub_variable is not None and sub_plan.file != sub_variable.file:
                c.errors.append(
                    FileError(
                        c.file,
                        f"{binding.key}.subVariable",
                        f"'{binding.sub_variable.text if binding.sub_variable else ''}' is not a variable of {sub_plan.file}",
                    )
                )
    for t in plan.transitions:
        c.local(t.source, states, f"{t.key}.inState", "state")
        c.local(t.target, states, f"{t.key}.outState", "state")
        if t.source is None or t.target is None:
            c.errors.append(FileError(c.file, t.key, "the transition needs an inState and an outState"))
        c.ref(t.condition, ("condition",))
        c.local(t.sync, [s.id for s in plan.syncs], f"{t.key}.synchronisation", "synchronisation")
    for s in plan.syncs:
        for i, t_id in enumerate(s.transitions):
            c.local(t_id, transitions, f"{s.key}.syncedTransitions[{i}]", "transition")


def _dependencies(index: Index, record: FileRec, refused: set[str], cut: set[tuple[str, str]]) -> list[FileError]:
    """Errors of a file that needs what a refused file holds."""
    errors: list[FileError] = []
    if isinstance(record, PlanRec):
        for ep in record.entry_points:
            if ep.task is None:
                continue
            target, unreadable, _ = index.find(ep.task, ("task",))
            holder = target.file if target is not None else unreadable
            if holder is not None and holder in refused:
                errors.append(
                    FileError(
                        record.file, f"{ep.key}.task", f"'{ep.task.text}' is a task of {holder}, which was refused"
                    )
                )
    elif isinstance(record, PlanTypeRec):
        if _usable(index, record, refused, cut) == 0:
            errors.append(
                FileError(record.file, "annotatedPlans", "the plan type has no activated plan that could be imported")
            )
    return errors


def children(index: Index, record: FileRec, refused: set[str], cut: set[tuple[str, str]]) -> list[tuple[Ref, str]]:
    """The plans and plan types ``record`` runs (a plan's children, a plan type's activated plans), with their files."""
    refs: list[Ref] = []
    if isinstance(record, PlanRec):
        refs = [w.target for s in record.states for w in s.wrappers if w.target is not None]
    elif isinstance(record, PlanTypeRec):
        refs = [a.plan for a in record.plans if a.activated and a.plan is not None]
    out = []
    for ref in refs:
        target, _, _ = index.find(ref, ("pml", "pty"))
        if target is not None and target.file not in refused and (record.file, ref.key) not in cut:
            out.append((ref, target.file))
    return out


def _usable(index: Index, record: PlanTypeRec, refused: set[str], cut: set[tuple[str, str]]) -> int:
    """How many plans of a plan type can be imported: activated, found, not refused, not left out for a cycle."""
    usable = 0
    for annotated in record.plans:
        if not annotated.activated or annotated.plan is None or (record.file, annotated.plan.key) in cut:
            continue
        target, _, _ = index.find(annotated.plan, ("pml",))
        usable += target is not None and target.file not in refused
    return usable


@dataclass(frozen=True, slots=True)
class _Cycle:
    """A cycle of the plan tree: its files in order and the references between them (from file, reference)."""

    files: tuple[str, ...]
    edges: tuple[tuple[str, Ref], ...]


def _cycle(index: Index, refused: set[str], cut: set[tuple[str, str]]) -> _Cycle | None:
    """The first cycle of the plan tree, visiting files in sorted order (an explicit stack: no recursion limit)."""
    state: dict[str, int] = {}
    for root in sorted(index.records):
        if root in refused or root in state or not isinstance(index.records[root], (PlanRec, PlanTypeRec)):
            continue
        path: list[str] = [root]
        via: list[tuple[str, Ref]] = []
        todo = [iter(children(index, index.records[root], refused, cut))]
        state[root] = 1
        while todo:
            step = next(todo[-1], None)
            if step is None:
                todo.pop()
                state[path.pop()] = 2
                if via:
                    via.pop()
                continue
            ref, child = step
            if state.get(child) == 1:
                start = path.index(child)
                edges = tuple(via[start:]) + ((path[-1], ref),)
                return _Cycle(tuple(path[start:]) + (child,), edges)
            if child not in state:
                state[child] = 1
                path.append(child)
                via.append((path[-2], ref))
                todo.append(iter(children(index, index.records[child], refused, cut)))
    return None


def _break(index: Index, cycle: _Cycle, refused: set[str], cut: set[tuple[str, str]], decision: Decision) -> None:
    """Break a cycle: leave an alternative out of a plan type on it when the type keeps another, else refuse a file."""
    shown = " -> ".join(cycle.files)
    for source, ref in cycle.edges:
        record = index.records[source]
        if isinstance(record, PlanTypeRec) and _usable(index, record, refused, cut) > 1:
            cut.add((source, ref.key))
            decision.notes.append(
                Note(
                    source,
                    ref.key,
                    Construct.DROPPED,
                    f"plan '{ref.text}' is left out of plan type '{record.name}': through it the plan type would run "
                    f"itself ({shown}), and plan trees here have no cycles",
                )
            )
            return
    source, ref = cycle.edges[-1]
    decision.errors.append(FileError(source, ref.key, f"'{ref.text}' closes a cycle in the plan tree: {shown}"))
    refused.add(source)
