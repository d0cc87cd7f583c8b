"""What the mapping of every file shares: the records, the resolver, the names, the notes."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from alica.io.designer.names import Namespace, is_placeholder
from alica.io.designer.naming import Names, base_reserved
from alica.io.designer.records import Cond, FileRec, KeyMap, Var
from alica.io.designer.report import Construct, Note
from alica.io.designer.resolve import Resolver
from alica.model import ANY_TYPE, Condition, ConditionKind, Declaration, Document, Variable


@dataclass
class Mapped:
    """One mapped designer file.

    Attributes:
        document: what the output file holds (its imports are added when it is written).
        needs: the designer files whose output it imports.
        skills: whether it imports the skill catalogue.
    """

    document: Document
    needs: set[str] = field(default_factory=set)
    skills: bool = False


@dataclass
class Context:
    """The state of one import while files are mapped.

    Attributes:
        records: every record read, by file.
        resolver: resolves references, knowing the refused files.
        names: our names of every element.
        notes: the notes of the mapping.
        standard_predicates: ids of standard-library conditions some transition uses as a predicate.
    """

    records: Mapping[str, FileRec]
    resolver: Resolver
    names: Names
    notes: list[Note] = field(default_factory=list)
    standard_predicates: set[int] = field(default_factory=set)

    def note(self, file: str, key: str, construct: Construct, message: str) -> None:
        """Add a note."""
        self.notes.append(Note(file, key, construct, message))


def plural(count: int, word: str, words: str = "") -> str:
    """``1 entry``, ``2 entries``."""
    return f"{count} {word if count == 1 else (words or word + 's')}"


def variable_names(variables: tuple[Var, ...]) -> dict[int, str]:
    """Our names of an element's variables, by id (the same wherever they are computed)."""
    space = Namespace(base_reserved())
    return {v.id: space.claim("" if is_placeholder(v.name, v.id) else v.name, "Var", "") for v in variables}


def variables(ctx: Context, file: str, variables: tuple[Var, ...], owner: str) -> tuple[Variable, ...]:
    """An element's variables, untyped (a typed one would need a range here), with a note per dropped type."""
    names = variable_names(variables)
    out = []
    for v in variables:
        name = names[v.id]
        if name != v.name:
            ctx.note(file, f"{v.key}.name", Construct.RENAMED, f"variable '{v.name}' of {owner} is named '{name}'")
        if v.type.strip():
            ctx.note(
                file,
                f"{v.key}.variableType",
                Construct.VARIABLE,
                f"variable '{name}' of {owner} has the designer type '{v.type}': imported untyped "
                "(a real or int variable here needs a range, e.g. 'x - real[0, 10]')",
            )
        out.append(Variable(name, ANY_TYPE))
    return tuple(out)


def inline_condition(
    ctx: Context, file: str, cond: Cond | None, kind: ConditionKind, owner: str
) -> tuple[Condition | None, Declaration | None]:
    """An inline pre, runtime or post condition: a declared 0-ary predicate.

    A condition marked ``enabled: false`` is imported too: the C++ engine evaluates it all
    the same (its ``conditionPlanTypeTest`` switches to ``RuntimeConditionPlan`` when that
    plan's disabled runtime condition comes true).
    """
    if cond is None:
        return None, None
    what = {ConditionKind.PRE: "pre", ConditionKind.RUN: "runtime", ConditionKind.POST: "post"}.get(kind, "")
    if not cond.enabled:
        ctx.note(
            file,
            cond.key,
            Construct.DISABLED_CONDITION,
            f"the {what} condition of {owner} is marked disabled in the designer, but the C++ engine evaluates "
            "it all the same: imported like any other",
        )
    name = ctx.names.predicates[cond.id]
    if cond.quantifiers or cond.variables:
        ctx.note(
            file,
            cond.key,
            Construct.QUANTIFIER,
            f"the {what} condition '{name}' of {owner} has {plural(cond.quantifiers, 'quantifier')} and "
            f"{plural(cond.variables, 'constraint variable')}: not imported; write them as a formula "
            "(forall a in agents(E): ...) or a constraint",
        )
    shown = f" ('{cond.text}')" if cond.text.strip() else ""
    ctx.note(
        file,
        cond.key,
        Construct.PREDICATE,
        f"the {what} condition of {owner} is C++ in the designer{shown}: declared as predicate '{name}'; "
        f"write a formula or set it with --fact {name}@T",
    )
    doc = f"{what} condition of {owner}, imported from the ALICA Plan Designer ({file})"
    return Condition(kind, name), Declaration(name, 0, doc)


def mapping_text(entries: tuple[KeyMap, ...]) -> str:
    """A key mapping as text for a note: ``parent -> child``, ``'const' -> child``."""
    parts = []
    for m in entries:
        source = repr(m.value) if m.value is not None else (m.parent_key or "?")
        parts.append(f"{source} -> {m.child_key}")
    return ", ".join(parts)
