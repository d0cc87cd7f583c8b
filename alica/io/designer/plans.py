"""A designer plan (``.pml``) as one of our plans.

States, entry points, transitions and synchronisations keep their structure;
names are made valid and unique within the plan (a designer transition
without a name gets ours, ``Source->Target``). A transition's condition
becomes a formula when it is a standard-library condition with a
counterpart (:mod:`alica.io.designer.conditions`), else the condition's
declared predicate. What has no counterpart is left out with a note:
blackboards and key mappings, configurations, placeholders, quantifiers.
States no entry point reaches are left out too (our validator refuses them).
"""

from __future__ import annotations

import math

from alica.io.designer.context import Context, Mapped, inline_condition, mapping_text, plural, variable_names, variables
from alica.io.designer.names import Namespace, is_placeholder
from alica.io.designer.naming import base_reserved
from alica.io.designer.records import (
    UNBOUNDED_CARDINALITY,
    BehaviourRec,
    PlanRec,
    PlanTypeRec,
    StateRec,
    TransitionRec,
    Wrapper,
)
from alica.io.designer.report import Construct
from alica.io.designer.resolve import CHILD_KINDS
from alica.io.designer.transitions import transition_condition
from alica.model import (
    UNBOUNDED,
    Binding,
    ChildRef,
    Condition,
    ConditionKind,
    Declaration,
    Document,
    EntryPoint,
    Plan,
    State,
    StateKind,
    Synchronisation,
    Transition,
    UtilityFunction,
)


class _PlanMapper:
    def __init__(self, ctx: Context, rec: PlanRec) -> None:
        self.ctx = ctx
        self.rec = rec
        self.file = rec.file
        self.name = ctx.names.abstract[rec.file]
        self.owner = f"plan '{self.name}'"
        self.predicates: list[Declaration] = []
        self.imports: set[str] = set()
        self.state_names: dict[int, str] = {}
        self.children: dict[int, list[tuple[str, str, str]]] = {}  # state id -> (designer name, ours, file)

    def note(self, key: str, construct: Construct, message: str) -> None:
        self.ctx.note(self.file, key, construct, message)

    def run(self) -> Mapped:
        rec = self.rec
        self._settings()
        plan_variables = variables(self.ctx, self.file, rec.variables, self.owner)
        pre, pre_decl = inline_condition(self.ctx, self.file, rec.pre, ConditionKind.PRE, self.owner)
        run, run_decl = inline_condition(self.ctx, self.file, rec.run, ConditionKind.RUN, self.owner)
        self.predicates += [d for d in (pre_decl, run_decl) if d is not None]
        reachable = self._reachable()
        states = self._states(reachable)
        entry_points = self._entry_points()
        transitions, names = self._transitions(reachable)
        syncs, joined = self._syncs(names)
        transitions = [Transition(t.name, t.source, t.target, t.condition, joined.get(t.name)) for t in transitions]
        plan = Plan(
            self.name,
            tuple(entry_points),
            tuple(states),
            tuple(transitions),
            tuple(syncs),
            plan_variables,
            pre,
            run,
            UtilityFunction(threshold=max(rec.threshold, 0.0)),
            frequency=max(rec.frequency, 0.0),
            description=rec.comment,
        )
        return Mapped(Document(predicates=tuple(self.predicates), plans=(plan,)), self.imports)

    def _settings(self) -> None:
        rec = self.rec
        if rec.master:
            self.note(
                "masterPlan",
                Construct.SETTINGS,
                f"{self.owner} is a master plan: run it as the root, e.g. 'alica run FILE --name {self.name} --agents ...'",
            )
        if rec.interface:
            self.note(
                "isInterface",
                Construct.SETTINGS,
                f"{self.owner} is an interface (isInterface): imported as a plain plan",
            )
        if rec.implementation:
            self.note(
                "implementationName",
                Construct.SETTINGS,
                f"implementation name '{rec.implementation}' of {self.owner} (C++ code) has no counterpart",
            )
        if rec.blackboard or rec.inherit_blackboard:
            inherit = ", inheriting its parent's" if rec.inherit_blackboard else ""
            self.note(
                "blackboard",
                Construct.BLACKBOARD,
                f"{self.owner} has a typed blackboard ({plural(rec.blackboard, 'entry', 'entries')}{inherit}): not imported; "
                "use facts of the world model instead",
            )
        if rec.frequency < 0 or rec.threshold < 0:
            self.note(
                "frequency", Construct.SETTINGS, f"negative frequency or utility threshold of {self.owner} read as 0"
            )

    # -- states ------------------------------------------------------------

    def _reachable(self) -> set[int]:
        rec = self.rec
        outgoing: dict[int, list[int]] = {}
        terminal = {s.id for s in rec.states if s.terminal}
        for t in rec.transitions:
            if t.source is not None and t.target is not None and t.source not in terminal:
                outgoing.setdefault(t.source, []).append(t.target)
        seen = {ep.state for ep in rec.entry_points if ep.state is not None}
        todo = list(seen)
        while todo:
            for nxt in outgoing.get(todo.pop(), []):
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return seen

    def _states(self, reachable: set[int]) -> list[State]:
        space = Namespace(base_reserved())
        kept = [s for s in self.rec.states if s.id in reachable]
        for s in self.rec.states:
            if s.id not in reachable:
                self.note(
                    s.key,
                    Construct.STRUCTURE,
                    f"state '{s.name}' of {self.owner} cannot be reached from any entry point: left out",
                )
        for s in kept:
            fallback = ("Success" if s.success else "Failure") if s.terminal else "State"
            self.state_names[s.id] = self.ctx.names.claim(
                space,
                s.name,
                fallback,
                file=self.file,
                key=f"{s.key}.name",
                what="state",
                owner=f" of {self.owner}",
                element_id=s.id,
            )
        return [self._state(s) for s in kept]

    def _state(self, s: StateRec) -> State:
        name = self.state_names[s.id]
        children: list[ChildRef] = []
        files: list[str] = []
        self.children[s.id] = []
        for w in s.wrappers:
            child = self._child(w, name)
            if child is not None:
                children.append(ChildRef(child[1]))
                files.append(child[2])
                self.children[s.id].append(child)
        children = self._bindings(s, children, files)
        kind = StateKind.NORMAL
        post: Condition | None = None
        if s.terminal:
            kind = StateKind.SUCCESS if s.success else StateKind.FAILURE
            post, decl = inline_condition(
                self.ctx, self.file, s.post, ConditionKind.POST, f"state '{name}' of {self.owner}"
            )
            if decl is not None:
                self.predicates.append(decl)
        return State(name, kind, tuple(children), post, s.comment)

    def _child(self, w: Wrapper, state: str) -> tuple[str, str, str] | None:
        """(designer name, our name, file) of a wrapper's child, or None when it is left out."""
        if w.target is None:
            return None
        where = f"state '{state}' of {self.owner}"
        target = self.ctx.resolver.target(w.target, CHILD_KINDS)
        if target is None:
            self.note(
                f"{w.key}.abstractPlan",
                Construct.DROPPED,
                f"child '{w.target.text}' of {where} is left out: its file was refused (see the errors)",
            )
            return None
        if target.kind == "plh":
            self.note(
                f"{w.key}.abstractPlan",
                Construct.PLACEHOLDER,
                f"child '{w.target.text}' of {where} is a placeholder, bound to an implementation at deploy time: "
                "left out; put the implementing plan or behaviour in the state instead",
            )
            return None
        if w.configuration:
            self.note(
                f"{w.key}.configuration",
                Construct.CONFIGURATION,
                f"the configuration of a child of {where} is not imported",
            )
        if w.inputs or w.outputs:
            shown = mapping_text(w.inputs + w.outputs)
            self.note(
                f"{w.key}.keyMapping",
                Construct.KEY_MAPPING,
                f"the key mapping of child '{w.target.text}' of {where} ({shown}) is not imported",
            )
        self.imports.add(target.file)
        return self.ctx.names.original[target.file], self.ctx.names.abstract[target.file], target.file

    def _bindings(self, s: StateRec, children: list[ChildRef], files: list[str]) -> list[ChildRef]:
        """Children with the state's variable bindings attached (``bind: {child variable: parent variable}``)."""
        parent = variable_names(self.rec.variables)
        extra: dict[int, list[Binding]] = {}
        for b in s.bindings:
            sub = self.ctx.resolver.target(b.sub_plan, CHILD_KINDS)
            index = files.index(sub.file) if sub is not None and sub.file in files else -1
            record = self.ctx.records.get(sub.file) if sub is not None else None
            child_vars = record.variables if isinstance(record, (PlanRec, BehaviourRec, PlanTypeRec)) else None
            if index < 0 or b.variable is None or b.sub_variable is None or child_vars is None or sub is None:
                self.note(
                    b.key,
                    Construct.VARIABLE,
                    f"a variable binding of state '{self.state_names[s.id]}' of {self.owner} is left out: "
                    "its child is not imported in the state",
                )
                continue
            if sub.kind == "pty":
                self.note(
                    b.key,
                    Construct.PLANTYPE_BINDING,
                    f"a variable binding to plan type '{children[index].name}' is left out: plan types have no variables here",
                )
                continue
            child_name = variable_names(child_vars).get(b.sub_variable.id)
            if child_name is None:
                continue
            extra.setdefault(index, []).append(Binding(child_name, parent[b.variable]))
        return [ChildRef(c.name, tuple(extra.get(i, ()))) if i in extra else c for i, c in enumerate(children)]

    # -- entry points ------------------------------------------------------

    def _entry_points(self) -> list[EntryPoint]:
        space = Namespace(base_reserved())
        out = []
        for ep in self.rec.entry_points:
            task_target = self.ctx.resolver.target(ep.task, ("task",))
            if task_target is None or ep.state is None:
                continue  # refused (the plan would have been refused with it)
            task = self.ctx.names.tasks[task_target.id]
            self.imports.add(task_target.file)
            raw = task if is_placeholder(ep.name, ep.id) else ep.name
            name = space.claim(raw, task, "")
            if is_placeholder(ep.name, ep.id):
                shown = f"the name '{ep.name}'" if ep.name.strip() else "no name"
                self.note(
                    f"{ep.key}.name",
                    Construct.UNNAMED,
                    f"an entry point of {self.owner} has {shown} in the designer: named '{name}'"
                    + (" (after its task)" if name == task else " (after its task; another entry point has that name)"),
                )
            elif name != ep.name:
                self.note(
                    f"{ep.key}.name", Construct.RENAMED, f"entry point '{ep.name}' of {self.owner} is named '{name}'"
                )
            if ep.dynamic:
                self.note(
                    f"{ep.key}.isDynamic",
                    Construct.SETTINGS,
                    f"entry point '{name}' of {self.owner} is dynamic: imported as a fixed one",
                )
            high = UNBOUNDED if ep.max >= UNBOUNDED_CARDINALITY else float(ep.max)
            out.append(EntryPoint(name, task, self.state_names.get(ep.state), ep.min, high, ep.success_required))
        return out

    # -- transitions -------------------------------------------------------

    def _transitions(self, reachable: set[int]) -> tuple[list[Transition], dict[int, str]]:
        """The transitions (without their synchronisation yet) and the names of those that have one, by id."""
        named = Namespace(base_reserved())
        defaults: set[str] = set()
        terminal = {s.id for s in self.rec.states if s.terminal}
        out: list[Transition] = []
        names: dict[int, str] = {}
        for t in self.rec.transitions:
            if t.source not in reachable or t.target not in reachable or t.source is None or t.target is None:
                continue
            source, target = self.state_names[t.source], self.state_names[t.target]
            if t.source in terminal:
                self.note(
                    t.key,
                    Construct.STRUCTURE,
                    f"transition {source}->{target} of {self.owner} leaves a terminal state: left out",
                )
                continue
            if is_placeholder(t.name, t.id):
                name = f"{source}->{target}"
                number = 2
                while name in defaults:
                    name = f"{source}->{target}_{number}"
                    number += 1
                defaults.add(name)
            else:
                name = self.ctx.names.claim(
                    named,
                    t.name,
                    "Transition",
                    file=self.file,
                    key=f"{t.key}.name",
                    what="transition",
                    owner=f" of {self.owner}",
                )
            condition = self._condition(t, name)
            out.append(Transition(name, source, target, condition))
            names[t.id] = name
        return out, names

    def _condition(self, t: TransitionRec, name: str) -> Condition:
        children = [(o, ours) for o, ours, _ in self.children.get(t.source or 0, [])]
        condition, needs = transition_condition(
            self.ctx, self.file, t, f"transition '{name}' of {self.owner}", children
        )
        if needs is not None:
            self.imports.add(needs)
        return condition

    # -- synchronisations --------------------------------------------------

    def _syncs(self, names: dict[int, str]) -> tuple[list[Synchronisation], dict[str, str]]:
        """The synchronisations, and the synchronisation of each synchronised transition (by transition name)."""
        space = Namespace(base_reserved())
        by_id = {t.id: t for t in self.rec.transitions}
        out: list[Synchronisation] = []
        joined: dict[str, str] = {}
        for s in self.rec.syncs:
            members = [t.id for t in self.rec.transitions if t.sync == s.id]
            for t_id in s.transitions:
                own = by_id[t_id].sync if t_id in by_id else None
                if own is None and t_id not in members:
                    members.append(t_id)
                elif own is not None and own != s.id:
                    self.note(
                        s.key,
                        Construct.STRUCTURE,
                        f"synchronisation '{s.name}' lists a transition that belongs to another synchronisation: left to that one",
                    )
            member_names = [names[t_id] for t_id in members if t_id in names]
            if len(member_names) < 2:
                self.note(
                    s.key,
                    Construct.STRUCTURE,
                    f"synchronisation '{s.name}' of {self.owner} has {len(member_names)} imported transition(s): left out "
                    "(a synchronisation needs two)",
                )
                continue
            name = self.ctx.names.claim(
                space,
                s.name,
                "Sync",
                file=self.file,
                key=f"{s.key}.name",
                what="synchronisation",
                owner=f" of {self.owner}",
                element_id=s.id,
            )
            talk, wait = max(s.talk_ms, 0.0) / 1000.0, max(s.sync_ms, 0.0) / 1000.0
            out.append(Synchronisation(name, tuple(member_names), _seconds(talk), _seconds(wait), s.fail))
            for member in member_names:
                joined[member] = name
        return out, joined


def _seconds(value: float) -> float:
    """Milliseconds turned to seconds, without float noise (30 ms -> 0.03)."""
    return round(value, 9) if math.isfinite(value) else value


def map_plan(ctx: Context, rec: PlanRec) -> Mapped:
    """Map one plan file: the plan, the predicates of its inline conditions, the designer files it needs."""
    return _PlanMapper(ctx, rec).run()
