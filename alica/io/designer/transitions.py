"""A designer transition's condition as one of our formulas, or as the predicate of its C++ condition.

- no condition: ``false``, with a note (here a transition without a
  condition always fires; the designer's has no condition to evaluate, so
  it is kept from firing until a person writes one);
- a standard-library condition with a counterpart
  (:func:`~alica.io.designer.conditions.standard_formula`): its formula;
- any other condition: the 0-ary predicate declared for it in the condition
  repository's file, which the plan's file then imports;
- a condition of a refused repository: ``false``, with a note.

The key mapping feeds only the standard conditions' constants; any other
mapping is noted.
"""

from __future__ import annotations

from collections.abc import Sequence

from alica.io.designer.conditions import STANDARD_LIBRARY, standard_formula
from alica.io.designer.context import Context, mapping_text, plural
from alica.io.designer.records import ConditionRepoRec, TransitionRec
from alica.io.designer.report import Construct
from alica.model import Condition, ConditionKind


def transition_condition(
    ctx: Context, file: str, t: TransitionRec, what: str, children: Sequence[tuple[str, str]]
) -> tuple[Condition, str | None]:
    """The condition of transition ``t`` of ``file``, and the designer file it needs (its condition repository).

    Args:
        ctx: the import's context.
        file: the plan's designer file.
        t: the transition.
        what: how notes name the transition.
        children: the children of its source state: (designer name, our name).
    """
    legacy = t.legacy
    if legacy is not None and (legacy.text.strip() or legacy.variables or legacy.quantifiers):
        shown = f"'{legacy.text}', " if legacy.text.strip() else ""
        ctx.note(
            file,
            f"{t.key}.preCondition",
            Construct.LEGACY_CONDITION,
            f"the inline condition of {what} ({shown}{plural(legacy.quantifiers, 'quantifier')}, "
            f"{plural(legacy.variables, 'variable')}) is not imported; the transition keeps its named condition",
        )
    if t.outputs:
        ctx.note(
            file,
            f"{t.key}.keyMapping.output",
            Construct.KEY_MAPPING,
            f"the output mapping of {what} ({mapping_text(t.outputs)}) is not imported",
        )
    if t.condition is None:
        ctx.note(
            file,
            f"{t.key}.condition",
            Construct.NO_CONDITION,
            f"{what} has no condition in the designer: imported as 'false' (a transition without a condition "
            "fires at once here); write a formula",
        )
        return Condition(ConditionKind.TRANSITION, "false"), None
    target = ctx.resolver.target(t.condition, ("condition",))
    repo = ctx.records.get(target.file) if target is not None else None
    if target is None or not isinstance(repo, ConditionRepoRec):
        ctx.note(
            file,
            f"{t.key}.condition",
            Construct.DROPPED,
            f"the condition '{t.condition.text}' of {what} is in a refused file: imported as 'false'",
        )
        return Condition(ConditionKind.TRANSITION, "false"), None
    cond = next(c for c in repo.conditions if c.id == target.id)
    formula = standard_formula(cond, t.inputs, children)
    if formula.text is not None:
        if formula.reason:
            ctx.note(file, f"{t.key}.condition", Construct.STANDARD_CONDITION, f"{what}: {formula.reason}")
        if t.inputs and not formula.consumed:
            ctx.note(
                file,
                f"{t.key}.keyMapping.input",
                Construct.KEY_MAPPING,
                f"the input mapping of {what} ({mapping_text(t.inputs)}) is not imported",
            )
        return Condition(ConditionKind.TRANSITION, formula.text), None
    predicate = ctx.names.predicates[cond.id]
    if cond.library == STANDARD_LIBRARY:
        ctx.standard_predicates.add(cond.id)
        ctx.note(
            file,
            f"{t.key}.condition",
            Construct.STANDARD_CONDITION,
            f"standard condition {cond.name} of {what} has no formula here ({formula.reason}): declared as predicate "
            f"'{predicate}'; write a formula or set it with --fact {predicate}@T",
        )
    if t.inputs:
        ctx.note(
            file,
            f"{t.key}.keyMapping.input",
            Construct.KEY_MAPPING,
            f"the input mapping of {what} ({mapping_text(t.inputs)}) is not imported: predicate '{predicate}' reads no blackboard",
        )
    return Condition(ConditionKind.TRANSITION, predicate), target.file
