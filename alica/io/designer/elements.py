"""Designer tasks, role sets, behaviours, plan types, condition repositories and placeholders as our elements.

- A task repository (``.tsk``) becomes a file of ``tasks:``.
- A role set (``.rst``) becomes a role set whose priorities name our tasks.
- A behaviour (``.beh``) becomes a behaviour running a skill of its designer
  name; the skill is declared in the generated catalogue (:func:`skill_catalogue`),
  to be given an implementation with ``--skills MODULE``.
- A plan type (``.pty``) lists its activated plans.
- A condition repository (``.cnd``) declares one 0-ary predicate per condition
  of the C++ test library, and per standard condition a transition could not
  write as a formula.
- A placeholder (``.plh``) has no counterpart.
"""

from __future__ import annotations

import posixpath

from alica.io.designer.conditions import STANDARD_LIBRARY
from alica.io.designer.context import Context, Mapped, inline_condition, plural, variables
from alica.io.designer.names import Namespace
from alica.io.designer.naming import base_reserved
from alica.io.designer.records import (
    BehaviourRec,
    ConditionRepoRec,
    PlaceholderRec,
    PlanTypeRec,
    RoleSetRec,
    TaskRepoRec,
)
from alica.io.designer.report import Construct
from alica.model import Behaviour, ConditionKind, Declaration, Document, PlanType, Priority, Role, RoleSet, Task


def map_tasks(ctx: Context, rec: TaskRepoRec) -> Mapped:
    """A task repository: its tasks, described by their comments."""
    tasks = tuple(Task(ctx.names.tasks[t.id], t.comment if t.comment != t.name else "") for t in rec.tasks)
    return Mapped(Document(tasks=tasks))


def map_roleset(ctx: Context, rec: RoleSetRec) -> Mapped:
    """A role set, with each role's task priorities."""
    name = ctx.names.rolesets[rec.file]
    needs: set[str] = set()
    space = Namespace(base_reserved())
    roles = []
    if rec.default_roleset:
        ctx.note(
            rec.file,
            "defaultRoleSet",
            Construct.ROLE,
            f"role set '{name}' is the designer's default role set: with several role sets, choose it with 'alica run --roleset {name}'",
        )
    for role in rec.roles:
        role_name = ctx.names.claim(
            space,
            role.name,
            "Role",
            file=rec.file,
            key=f"{role.key}.name",
            what="role",
            owner=f" of role set '{name}'",
            element_id=role.id,
        )
        if role.characteristics:
            ctx.note(
                rec.file,
                f"{role.key}.characteristics",
                Construct.ROLE,
                f"role '{role_name}' has {plural(role.characteristics, 'characteristic')}: not imported; "
                "list the capabilities an agent needs under 'requires:'",
            )
        priorities = []
        for p in role.priorities:
            target = ctx.resolver.target(p.task, ("task",))
            if target is None:
                shown = p.task.text if p.task is not None else "?"
                ctx.note(
                    rec.file,
                    p.key,
                    Construct.DROPPED,
                    f"the priority of role '{role_name}' for '{shown}' is left out: its task repository was refused",
                )
                continue
            needs.add(target.file)
            priorities.append(Priority(ctx.names.tasks[target.id], p.value))
        roles.append(Role(role_name, tuple(priorities), description=role.comment))
    roleset = RoleSet(name, tuple(roles), rec.default_priority, rec.comment)
    return Mapped(Document(rolesets=(roleset,)), needs)


def map_behaviour(ctx: Context, rec: BehaviourRec) -> Mapped:
    """A behaviour: it runs the skill of its designer name (declared in the generated catalogue)."""
    name = ctx.names.abstract[rec.file]
    owner = f"behaviour '{name}'"
    if rec.event_driven or rec.deferring:
        kinds = " and ".join(k for k, on in (("event-driven", rec.event_driven), ("deferring", rec.deferring)) if on)
        ctx.note(
            rec.file,
            "eventDriven" if rec.event_driven else "deferring",
            Construct.EVENT_DRIVEN,
            f"{owner} is {kinds} in the designer: imported as a behaviour ticked at its frequency",
        )
    if rec.blackboard or rec.inherit_blackboard:
        inherit = ", inheriting its parent's" if rec.inherit_blackboard else ""
        ctx.note(
            rec.file,
            "blackboard",
            Construct.BLACKBOARD,
            f"{owner} has a typed blackboard ({plural(rec.blackboard, 'entry', 'entries')}{inherit}): not imported; "
            "give the skill parameters instead (declare them in the skill catalogue)",
        )
    if rec.interface:
        ctx.note(
            rec.file,
            "isInterface",
            Construct.SETTINGS,
            f"{owner} is an interface (isInterface): imported as a plain behaviour",
        )
    if rec.implementation:
        ctx.note(
            rec.file,
            "implementationName",
            Construct.SETTINGS,
            f"implementation name '{rec.implementation}' of {owner} has no counterpart: bind the skill with --skills MODULE",
        )
    declarations: list[Declaration] = []
    conditions = []
    for cond, kind in ((rec.pre, ConditionKind.PRE), (rec.run, ConditionKind.RUN), (rec.post, ConditionKind.POST)):
        condition, declaration = inline_condition(ctx, rec.file, cond, kind, owner)
        conditions.append(condition)
        if declaration is not None:
            declarations.append(declaration)
    behaviour = Behaviour(
        name,
        ctx.names.skills[rec.file],
        (),
        variables(ctx, rec.file, rec.variables, owner),
        conditions[0],
        conditions[1],
        conditions[2],
        max(rec.frequency, 0.0),
        rec.comment,
    )
    return Mapped(Document(predicates=tuple(declarations), behaviours=(behaviour,)), skills=True)


def map_plantype(ctx: Context, rec: PlanTypeRec) -> Mapped:
    """A plan type: its activated plans, in the designer's order."""
    name = ctx.names.abstract[rec.file]
    needs: set[str] = set()
    plans = []
    for annotated in rec.plans:
        if annotated.plan is None:
            continue
        if not annotated.activated:
            ctx.note(
                rec.file,
                f"{annotated.key}.activated",
                Construct.DEACTIVATED,
                f"plan '{annotated.plan.text}' is deactivated in plan type '{name}': left out of the type",
            )
            continue
        if ctx.resolver.is_cut(rec.file, annotated.plan.key):
            continue  # left out to break a cycle, with a note
        target = ctx.resolver.target(annotated.plan, ("pml",))
        if target is None:
            ctx.note(
                rec.file,
                f"{annotated.key}.plan",
                Construct.DROPPED,
                f"plan '{annotated.plan.text}' of plan type '{name}' is left out: its file was refused",
            )
            continue
        needs.add(target.file)
        plans.append(ctx.names.abstract[target.file])
    if rec.bindings or rec.variables:
        ctx.note(
            rec.file,
            "variableBindings" if rec.bindings else "variables",
            Construct.PLANTYPE_BINDING,
            f"plan type '{name}' has {plural(len(rec.variables), 'variable')} and "
            f"{plural(rec.bindings, 'variable binding')}: not imported",
        )
    return Mapped(Document(plantypes=(PlanType(name, tuple(plans), rec.comment),)), needs)


def map_conditions(ctx: Context, rec: ConditionRepoRec) -> Mapped:
    """A condition repository: a predicate for each condition without a formula counterpart."""
    declarations = []
    for c in rec.conditions:
        if c.library == STANDARD_LIBRARY and c.id not in ctx.standard_predicates:
            continue
        name = ctx.names.predicates[c.id]
        reads = f"; in C++ it reads {', '.join(f'{k} ({t})' for k, t in c.inputs)}" if c.inputs else ""
        ref = f"{posixpath.basename(rec.file)}#{c.id}"
        declarations.append(Declaration(name, 0, f"condition {c.name} of {c.library or 'no library'} ({ref}){reads}"))
        if c.library != STANDARD_LIBRARY:
            ctx.note(
                rec.file,
                c.key,
                Construct.PREDICATE,
                f"condition {c.name} of {c.library or 'no library'} is C++ in the designer: declared as predicate '{name}'; "
                f"write a formula or set it with --fact {name}@T",
            )
    return Mapped(Document(predicates=tuple(declarations)))


def note_placeholder(ctx: Context, rec: PlaceholderRec) -> None:
    """A placeholder has no counterpart: say so."""
    ctx.note(
        rec.file,
        "",
        Construct.PLACEHOLDER,
        f"placeholder '{rec.name}' (bound to an implementation by a mapping outside the designer files) has no "
        "counterpart: not imported; the children that refer to it are left out",
    )


def skill_catalogue(ctx: Context, behaviours: list[BehaviourRec]) -> list[dict[str, object]]:
    """The generated skill catalogue: one skill per behaviour, without parameters, sorted by name."""
    out: list[dict[str, object]] = []
    for rec in behaviours:
        ref = f"{posixpath.basename(rec.file)}#{rec.id}"
        out.append(
            {
                "name": ctx.names.skills[rec.file],
                "doc": f"imported from the ALICA Plan Designer: behaviour {rec.name} ({ref})",
                "params": [],
            }
        )
    return sorted(out, key=lambda s: str(s["name"]))
