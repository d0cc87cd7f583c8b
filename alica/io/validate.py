"""Checks over a whole document set, run before anything is built.

Every problem is collected with its place, so a person sees them all at once.
Structural checks (types, keys) happened in :mod:`alica.io.build`; these are
the checks that need several elements: references, uniqueness, reachability,
the acyclic plan tree, numeric rules of the language, skills and formulas.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from typing import Protocol, TypeVar

from alica.errors import FormulaError
from alica.io.fields import Problems, suggest
from alica.io.plan_paths import import_target, plan_path
from alica.io.reads import Read, agent_domains, reads
from alica.io.skill_declarations import with_declarations
from alica.lang import ENGINE_VARIABLES, Registry, Vocabulary, check, default_vocabulary, literals, parse
from alica.lang.ast import Node, is_logical
from alica.lang.skills import SkillRegistry
from alica.model import (
    ANY_TYPE,
    NUMERIC_TYPES,
    AbstractPlan,
    Behaviour,
    Binding,
    Condition,
    Declaration,
    Document,
    Plan,
    PlanningProblem,
    PlanType,
    RoleSet,
    Variable,
    children_of,
    format_cardinality,
)
from alica.source import SourceSpan


class _Element(Protocol):
    """A model element as :meth:`Validator._unique` reads it: a name and where it was written."""

    @property
    def name(self) -> str: ...

    @property
    def span(self) -> SourceSpan | None: ...


_E = TypeVar("_E", bound=_Element)

#: A type name: real, int, point, any or an object type.
_TYPE_NAME = re.compile(r"^[A-Za-z_][\w-]*$")

#: How far utility weights may stray from summing to 1.
WEIGHT_TOLERANCE = 1e-6


def formula_span(span: SourceSpan | None, text: str, column: int) -> SourceSpan | None:
    """The file position of 1-based ``column`` of a formula whose text starts at ``span``."""
    if span is None:
        return None
    before = text[: max(column - 1, 0)]
    if "\n" in before:
        return SourceSpan(span.file, span.line + before.count("\n"), span.column + len(before) - before.rfind("\n") - 1)
    return span.shifted(column - 1)


class Validator:
    """Validates the documents of one set.

    Args:
        documents: the entry file's document and everything it imports.
        skills: the skill declarations behaviours are checked against, besides
            the skills the documents declare (:mod:`alica.io.skill_declarations`).
        functions: the registered predicates and functions formulas may call.
        problems: where problems go.
        vocabulary: the predicates and functions every formula may read without a
            declaration (the engine's own facts by default); each file adds its own
            declarations and those of the files it imports.
    """

    def __init__(
        self,
        documents: Sequence[Document],
        skills: SkillRegistry,
        functions: Registry,
        problems: Problems,
        vocabulary: Vocabulary | None = None,
    ) -> None:
        self.documents = documents
        self.functions = functions
        self.problems = problems
        self.vocabularies = _Vocabularies(documents, vocabulary or default_vocabulary(), problems)
        self.vocabulary: Vocabulary | None = None
        self.bound: frozenset[str] = ENGINE_VARIABLES
        #: Within a plan: its entry points, tasks and states, the names agents(E) may use.
        self.domains: frozenset[str] | None = None
        #: The variables of the element being checked, and how messages name it.
        self.variables: tuple[str, ...] = ()
        self.owner = ""
        self.tasks = self._unique("task", (t for d in documents for t in d.tasks))
        self.rolesets = self._unique("role set", (r for d in documents for r in d.rolesets))
        abstract: list[AbstractPlan] = []
        for d in documents:
            abstract.extend(d.behaviours)
            abstract.extend(d.plans)
            abstract.extend(d.plantypes)
            abstract.extend(d.problems)
        self.abstract = self._unique("behaviour, plan, plan type or planning problem", abstract)
        declared = self._unique("skill", (s for d in documents for s in d.skills))
        #: The registry's Python declarations and the set's file declarations (the registry wins).
        self.skills = with_declarations(skills, declared.values(), problems)

    def run(self) -> None:
        """Run every check."""
        for rs in self.rolesets.values():
            self._roleset(rs)
        for element in self.abstract.values():
            self.vocabulary = self.vocabularies.of(element)
            self.domains = None
            if isinstance(element, Behaviour):
                self._behaviour(element)
            elif isinstance(element, Plan):
                self._plan(element)
            elif isinstance(element, PlanType):
                self._plantype(element)
            elif isinstance(element, PlanningProblem):
                self._problem(element)
        self._cycles()

    # -- helpers -----------------------------------------------------------

    def _unique(self, kind: str, elements: Iterable[_E]) -> dict[str, _E]:
        seen: dict[str, _E] = {}
        for element in elements:
            if not element.name:
                continue
            if element.name in seen:
                first = seen[element.name].span
                where = f" (first at {first})" if first else ""
                self.problems.add(
                    element.span,
                    f"duplicate name '{element.name}': another {kind} has it{where}",
                    "rename one of them; names must be unique in the files loaded together",
                )
                continue
            seen[element.name] = element
        return seen

    def _unique_in(self, owner: str, kind: str, items: Iterable[_Element]) -> set[str]:
        names: set[str] = set()
        for item in items:
            if item.name in names:
                self.problems.add(
                    item.span, f"{owner} has two {kind}s named '{item.name}'", f"give each {kind} its own name"
                )
            names.add(item.name)
        return names

    def _formula(
        self,
        text: str,
        span: SourceSpan | None,
        what: str,
        *,
        effect: bool = False,
        boolean: bool = False,
        bound: Iterable[str] = (),
        constraint: bool = False,
    ) -> Node | None:
        """Check one formula; returns its tree, or None when it does not parse.

        Within a plan, its ``agents(E)`` domains must name the plan's entry points,
        tasks or states; in a constraint, ``x(a)`` for an agent ``a`` must read a
        declared variable (or a registered or declared function).
        """
        node: Node | None = None
        skip: set[int] = set()
        try:
            node = parse(text)
            names = self.bound | set(bound)
            if self.domains is not None:
                self._domains(node, text, span, what)
            if constraint:
                skip = self._per_agent_reads(node, text, span, what)
            issues = check(node, self.functions, text=text, boolean=boolean, vocabulary=self.vocabulary, bound=names)
            if effect:
                literals(node)
        except FormulaError as exc:
            issues = [exc]
        for issue in issues:
            if issue.column in skip and issue.message.startswith("unknown "):
                continue  # reported as a per-agent read of an undeclared variable
            self.problems.add(
                formula_span(span, text, issue.column),
                f"{what}: {issue.message}",
                issue.hint or "see the formula syntax in docs/plan_format.md",
            )
        return node

    def _domains(self, node: Node, text: str, span: SourceSpan | None, what: str) -> None:
        """``agents(E)``: ``E`` must be an entry point, task or state of the plan."""
        assert self.domains is not None
        for domain in agent_domains(node, text):
            if domain.name not in self.domains:
                self.problems.add(
                    formula_span(span, text, domain.column),
                    f"{what}: agents({domain.name}) names no entry point, task or state of the plan",
                    suggest(domain.name, self.domains)
                    or "name one of: " + ", ".join(sorted(self.domains)) + " (agents(E) are the agents in E)",
                )

    def _per_agent_reads(self, node: Node, text: str, span: SourceSpan | None, what: str) -> set[int]:
        """Report ``x(a)`` for an agent ``a`` where ``x`` is no variable and no known function; their columns."""
        reported: set[int] = set()
        for read in reads(node):
            if not read.per_agent or not read.of_agent or read.name in self.bound:
                continue
            if read.name in self.functions or (self.vocabulary is not None and self.vocabulary.lookup(read.name)):
                continue
            reported.add(read.column)
            close = suggest(read.name, self.variables)
            self.problems.add(
                formula_span(span, text, read.column),
                f"{what}: '{read.name}(...)' reads per-agent variable '{read.name}', which {self.owner} does not declare",
                close
                or f"declare it under 'variables:' of {self.owner}, e.g. '{read.name} - real[0, 10]', "
                f"or declare '{read.name}' as a function",
            )
        return reported

    def _condition(self, cond: Condition | None, what: str, *, effect: bool = False, bound: Iterable[str] = ()) -> None:
        if cond is not None:
            self._formula(cond.text, cond.span, what, effect=effect, boolean=True, bound=bound)

    def _ref(
        self, name: str, span: SourceSpan | None, what: str, kinds: tuple[type, ...] | None = None
    ) -> object | None:
        element = self.abstract.get(name)
        if element is None:
            hint = suggest(name, self.abstract) or "define it in this file or import the file that defines it"
            self.problems.add(span, f"{what} names '{name}', which is not defined", hint)
            return None
        if kinds is not None and not isinstance(element, kinds):
            wanted = " or ".join(_kind(k) for k in kinds)
            self.problems.add(
                span, f"{what} names '{name}', which is a {_kind(type(element))}, not a {wanted}", f"name a {wanted}"
            )
            return None
        return element

    def _task(self, name: str, span: SourceSpan | None, what: str) -> None:
        if name and name not in self.tasks:
            hint = suggest(name, self.tasks) or "add it under 'tasks:' or import the task repository"
            self.problems.add(span, f"{what} names task '{name}', which is not defined", hint)

    # -- elements ----------------------------------------------------------

    def _roleset(self, rs: RoleSet) -> None:
        self._unique_in(f"role set '{rs.name}'", "role", rs.roles)
        if not rs.roles:
            self.problems.add(rs.span, f"role set '{rs.name}' has no roles", "list its roles under 'roles:'")
        if not -1.0 <= rs.default_priority <= 1.0:
            self.problems.add(
                rs.span,
                f"default priority {rs.default_priority:g} of role set '{rs.name}' is outside [-1, 1]",
                "use a value in [-1, 1]",
            )
        for role in rs.roles:
            seen: set[str] = set()
            for p in role.priorities:
                what = f"priority of role '{role.name}' for task '{p.task}'"
                if p.task in seen:
                    self.problems.add(p.span, f"role '{role.name}' gives task '{p.task}' two priorities", "keep one")
                seen.add(p.task)
                self._task(p.task, p.span, f"role '{role.name}'")
                if not (-1.0 <= p.value <= 1.0) or math.isnan(p.value):
                    self.problems.add(
                        p.span,
                        f"{what} is {p.value:g}, outside [-1, 1]",
                        "use a value in [-1, 1]; a negative one means the role cannot take the task",
                    )

    def _behaviour(self, b: Behaviour) -> None:
        what = f"behaviour '{b.name}'"
        self.bound = ENGINE_VARIABLES | {v.name for v in b.variables}
        self._variables(b.variables, what)
        for kind, cond in (("pre", b.pre), ("run", b.run), ("post", b.post)):
            self._condition(cond, f"{kind} condition of {what}")
        variables = {v.name for v in b.variables}
        for p in b.params:
            if p.variable is not None and p.variable not in variables:
                self.problems.add(
                    p.span,
                    f"parameter '{p.name}' of {what} refers to '${p.variable}', which is not a variable of the behaviour",
                    "declare it under 'variables:' or fix the name",
                )
        if b.skill not in self.skills:
            hint = suggest(b.skill, self.skills.names()) or (
                "run 'alica list-skills' to see the registered skills; a plug-in's skills need --skills MODULE"
            )
            self.problems.add(b.span, f"{what} binds unknown skill '{b.skill}'", hint)
            return
        spec = self.skills.get(b.skill)
        given = {p.name for p in b.params}
        for p in b.params:
            param = spec.param(p.name)
            if param is None:
                known = [q.name for q in spec.params]
                hint = suggest(p.name, known) or ("it takes " + ", ".join(known) if known else "it takes no parameters")
                self.problems.add(p.span, f"skill '{b.skill}' has no parameter '{p.name}'", hint)
                continue
            reason = param.check(p.value)
            if reason is not None:
                self.problems.add(
                    p.span,
                    f"parameter '{p.name}' of {what} {reason}, not {p.value!r}",
                    f"see 'alica list-skills' for {b.skill}",
                )
        for param in spec.params:
            if param.required and param.name not in given:
                self.problems.add(
                    b.span,
                    f"{what} does not give required parameter '{param.name}' of skill '{b.skill}'",
                    f"add '{param.name}' under 'params:' ({param.doc or param.type})",
                )

    def _plan(self, plan: Plan) -> None:
        what = f"plan '{plan.name}'"
        self.bound = ENGINE_VARIABLES | {v.name for v in plan.variables}
        self.domains = frozenset(
            [ep.name for ep in plan.entry_points]
            + [ep.task for ep in plan.entry_points]
            + [s.name for s in plan.states]
        )
        self._variables(plan.variables, what)
        states = self._unique_in(what, "state", plan.states)
        self._unique_in(what, "entry point", plan.entry_points)
        self._unique_in(what, "transition", plan.transitions)
        syncs = self._unique_in(what, "synchronisation", plan.synchronisations)
        self._unique_in(what, "variable", plan.variables)
        self._condition(plan.pre, f"pre condition of {what}")
        self._condition(plan.run, f"run condition of {what}")
        if not plan.entry_points:
            self.problems.add(
                plan.span, f"{what} has no entry point", "add an entry point with a task and an initial state"
            )
        for ep in plan.entry_points:
            ep_what = f"entry point '{ep.name}' of {what}"
            self._task(ep.task, ep.span, ep_what)
            if ep.state is None:
                self.problems.add(
                    ep.span, f"{ep_what} has no initial state", "add 'state:' naming the state agents start in"
                )
            elif ep.state not in states:
                self.problems.add(
                    ep.span,
                    f"{ep_what} starts in unknown state '{ep.state}'",
                    suggest(ep.state, states) or "name one of the plan's states",
                )
            if ep.min > ep.max:
                self.problems.add(
                    ep.span, f"{ep_what} has min {ep.min} > max {format_cardinality(ep.max)}", "make min at most max"
                )
        by_name = {s.name: s for s in plan.states}
        for state in plan.states:
            for child in state.children:
                target = self._ref(child.name, child.span, f"state '{state.name}' of {what}")
                binds = isinstance(target, (Plan, Behaviour))  # a plan type's plans each declare their own
                variables = {v.name for v in target.variables} if isinstance(target, (Plan, Behaviour)) else set()
                for binding in child.bindings:
                    if binds and binding.variable not in variables:
                        self.problems.add(
                            binding.span,
                            f"'{child.name}' has no variable '{binding.variable}' to bind",
                            suggest(binding.variable, variables) or f"declare it under 'variables:' of '{child.name}'",
                        )
                    self._formula(
                        binding.value,
                        binding.span,
                        f"binding of '{binding.variable}' in state '{state.name}' of {what}",
                    )
                    if isinstance(target, (Plan, Behaviour)):
                        self._binding_types(binding, target, plan, f"state '{state.name}' of {what}")
            self._condition(state.post, f"post condition of state '{state.name}' of {what}")
        for t in plan.transitions:
            t_what = f"transition '{t.name}' of {what}"
            source = by_name.get(t.source)
            if source is not None and source.terminal:
                self.problems.add(
                    t.span,
                    f"{t_what} leaves {source.kind.value} state '{t.source}'; terminal states have no outgoing transitions",
                    "remove the transition or make the state normal",
                )
            if t.target not in states:
                self.problems.add(
                    t.span,
                    f"{t_what} enters unknown state '{t.target}'",
                    suggest(t.target, states) or "name one of the plan's states",
                )
            if t.synchronisation is not None and t.synchronisation not in syncs:
                self.problems.add(
                    t.span,
                    f"{t_what} joins unknown synchronisation '{t.synchronisation}'",
                    suggest(t.synchronisation, syncs) or "declare it under 'synchronisations:'",
                )
            self._condition(t.condition, f"condition of {t_what}")
        transitions = {t.name: t for t in plan.transitions}
        for sync in plan.synchronisations:
            if len(sync.transitions) < 2:
                self.problems.add(
                    sync.span,
                    f"synchronisation '{sync.name}' of {what} needs at least two transitions",
                    "list the transitions that must fire together",
                )
            for name in sync.transitions:
                listed = transitions.get(name)
                if listed is None:
                    self.problems.add(
                        sync.span,
                        f"synchronisation '{sync.name}' of {what} lists unknown transition '{name}'",
                        suggest(name, transitions) or "transition names default to 'Source->Target'",
                    )
                elif listed.synchronisation != sync.name:
                    self.problems.add(
                        listed.span,
                        f"transition '{name}' is listed by synchronisation '{sync.name}' but does not say 'sync: {sync.name}'",
                        f"add 'sync: {sync.name}' to the transition",
                    )
        reachable: set[str] = set()
        for ep in plan.entry_points:
            if ep.state in states:
                reachable |= plan.reachable_states(ep.name)
        if plan.entry_points and all(ep.state in states for ep in plan.entry_points):
            for state in plan.states:
                if state.name not in reachable:
                    self.problems.add(
                        state.span,
                        f"state '{state.name}' of {what} cannot be reached from any entry point",
                        "add a transition into it or remove it",
                    )
        self._utility(plan)
        self._constraints(plan)
        declared = {v.name for v in plan.variables}
        for c in plan.constraints:
            for var in c.variables:
                if var not in declared:
                    self.problems.add(
                        c.span,
                        f"constraint '{c.name}' of {what} constrains '{var}', which is not a variable of the plan",
                        "declare it under 'variables:'",
                    )
        if plan.signature is not None:
            sig = plan.signature
            self._unique_in(f"the signature of {what}", "parameter", sig.parameters)
            parameters = [v.name for v in sig.parameters]
            self._condition(sig.precondition, f"precondition of {what}", bound=parameters)
            self._condition(sig.effect, f"effect of {what}", effect=True, bound=parameters)

    def _variables(self, variables: tuple[Variable, ...], what: str) -> None:
        """Declarations: a known type, a finite range for real, int and point variables, candidates that parse."""
        self.variables = tuple(v.name for v in variables)
        self.owner = what
        for v in variables:
            v_what = f"variable '{v.name}' of {what}"
            if not _TYPE_NAME.match(v.type):
                self.problems.add(
                    v.span,
                    f"{v_what} has unknown type '{v.type}'",
                    "use real, int, point, any, or the name of an object type such as Frontier",
                )
            elif not v.numeric and (v.low is not None or v.high is not None):
                close = suggest(v.type, sorted(NUMERIC_TYPES))
                self.problems.add(
                    v.span,
                    f"{v_what} has a range, but its type '{v.type}' is not real, int or point",
                    close or "only real, int and point variables have a range; an object type has none",
                )
            if v.numeric:
                self._range(v, v_what)
            if v.candidates is not None:
                if not v.object_type:
                    self.problems.add(
                        v.span,
                        f"{v_what} has candidates, but its type is {v.type}",
                        "candidates list the values of a variable of an object type, e.g. 'frontier - Frontier'",
                    )
                self._candidates(v, v_what)

    def _range(self, v: Variable, what: str) -> None:
        example = f"'{v.name} - {v.type}[-10, 10]' or 'range: [-10, 10]'"
        if v.low is None or v.high is None:
            if v.low is not None or v.high is not None:
                return  # one bound was given, or one did not read as a number: reported where it was read
            self.problems.add(
                v.span, f"{what} has no range", f"{_article(v.type)} {v.type} variable needs one: write {example}"
            )
        elif not (math.isfinite(v.low) and math.isfinite(v.high)):
            self.problems.add(v.span, f"the range [{v.low:g}, {v.high:g}] of {what} is not finite", "use finite bounds")
        elif v.low > v.high:
            self.problems.add(
                v.span,
                f"the range [{v.low:g}, {v.high:g}] of {what} is empty: low > high",
                f"write the smaller bound first: [{v.high:g}, {v.low:g}]",
            )
        elif v.type == "int" and not (v.low.is_integer() and v.high.is_integer()):
            self.problems.add(
                v.span, f"the range [{v.low:g}, {v.high:g}] of int {what} has a fraction", "use whole numbers"
            )

    def _candidates(self, v: Variable, what: str) -> None:
        """The candidates formula must parse and name known functions (reported at the variable)."""
        text = v.candidates or ""
        try:
            issues = check(parse(text), self.functions, text=text, vocabulary=self.vocabulary, bound=self.bound)
        except FormulaError as exc:
            issues = [exc]
        for issue in issues:
            self.problems.add(
                v.span,
                f"candidates '{text}' of {what}: {issue.message} (column {issue.column})",
                issue.hint or "write a formula whose value is the list of candidates, e.g. frontiers()",
            )

    def _constraints(self, plan: Plan) -> None:
        """Constraint formulas are truth values, utilities numbers; a variable is read one way only."""
        what = f"plan '{plan.name}'"
        self.variables = tuple(v.name for v in plan.variables)
        self.owner = what
        declared = set(self.variables)
        first: dict[tuple[str, bool], SourceSpan | None] = {}
        for c in plan.constraints:
            c_what = f"constraint '{c.name}' of {what}"
            parts = []
            if c.text or not c.utility:
                node = self._formula(c.text, c.span, c_what, boolean=True, constraint=True)
                parts.append((node, c.text, c.span))
            if c.utility:
                node = self._formula(c.utility, c.utility_span, f"utility of {c_what}", constraint=True)
                if node is not None and is_logical(node):
                    self.problems.add(
                        c.utility_span,
                        f"utility of {c_what}: '{c.utility}' is a truth value, not a number to maximise",
                        "write a number, e.g. 'sum a in agents(E): gain(frontier(a))'; put conditions under 'formula:'",
                    )
                parts.append((node, c.utility, c.utility_span))
            for node, text, span in parts:
                if node is None:
                    continue
                for read in reads(node):
                    if read.name not in declared:
                        continue
                    place = formula_span(span, text, read.column)
                    key = (read.name, read.per_agent)
                    other = (read.name, not read.per_agent)
                    if key not in first:
                        first[key] = place
                        if other in first:
                            self._mixed_read(read, place, first[other], c_what)

    def _mixed_read(self, read: Read, place: SourceSpan | None, earlier: SourceSpan | None, what: str) -> None:
        how, other = (f"{read.name}(a)", read.name) if read.per_agent else (read.name, f"{read.name}(a)")
        where = f" at {earlier}" if earlier is not None else ""
        self.problems.add(
            place,
            f"{what}: variable '{read.name}' is read as '{how}' here and as '{other}'{where}",
            f"read it as '{read.name}(a)' everywhere for one value per agent, or as '{read.name}' for one team value",
        )

    def _binding_types(self, binding: Binding, target: Plan | Behaviour, plan: Plan, what: str) -> None:
        """A child's variable bound to a parent's variable must have the same type (unless one is untyped)."""
        child = next((v for v in target.variables if v.name == binding.variable), None)
        parent = next((v for v in plan.variables if v.name == binding.value.strip()), None)
        if child is None or parent is None or ANY_TYPE in (child.type, parent.type) or child.type == parent.type:
            return
        self.problems.add(
            binding.span,
            f"binding of '{binding.variable}' in {what}: '{binding.variable}' of '{target.name}' is {child.type}, "
            f"but '{parent.name}' of plan '{plan.name}' is {parent.type}",
            "bind variables of the same type, or leave the child's variable untyped",
        )

    def _utility(self, plan: Plan) -> None:
        u = plan.utility
        what = f"the utility of plan '{plan.name}'"
        total = u.weight_sum
        if abs(total - 1.0) > WEIGHT_TOLERANCE:
            parts = [f"priority_weight {u.priority_weight:g}", f"similarity_weight {u.similarity_weight:g}"] + [
                f"{s.name} {s.weight:g}" for s in u.summands
            ]
            self.problems.add(
                u.span or plan.span,
                f"weights of {what} sum to {total:g}, not 1 ({', '.join(parts)})",
                "scale the weights so they add up to 1 (IMPERA Definition 6.3)",
            )
        self._unique_in(what, "summand", u.summands)
        for s in u.summands:
            self._formula(s.expression, s.span, f"summand '{s.name}' of {what}", bound=("task", "entry"))

    def _plantype(self, pt: PlanType) -> None:
        if not pt.plans:
            self.problems.add(
                pt.span, f"plan type '{pt.name}' has no plans", "list its alternative plans under 'plans:'"
            )
        if len(set(pt.plans)) != len(pt.plans):
            self.problems.add(pt.span, f"plan type '{pt.name}' lists a plan twice", "list each alternative once")
        for name in pt.plans:
            self._ref(name, pt.span, f"plan type '{pt.name}'", (Plan,))

    def _problem(self, p: PlanningProblem) -> None:
        what = f"planning problem '{p.name}'"
        self.bound = ENGINE_VARIABLES | {v.name for v in p.objects}
        if not p.elements:
            self.problems.add(
                p.span, f"{what} has no elements", "list the skill plans the planner may use under 'elements:'"
            )
        for name in p.elements:
            element = self._ref(name, p.span, what, (Plan,))
            if isinstance(element, Plan) and element.signature is None:
                self.problems.add(
                    element.span,
                    f"plan '{name}' is an element of {what} but has no planning signature",
                    "add 'signature:' with parameters, precondition and effect",
                )
        if p.wait_plan is None:
            self.problems.add(
                p.span,
                f"{what} has no WaitPlan",
                "add 'wait_plan:' naming the plan the team runs until the first plan is ready",
            )
        else:
            self._ref(p.wait_plan, p.span, f"the WaitPlan of {what}", (Plan, PlanType))
        if p.alternative_plan is not None:
            self._ref(p.alternative_plan, p.span, f"the AlternativePlan of {what}", (Plan, PlanType))
        self._condition(p.goal, f"goal of {what}")
        self._condition(p.world, f"world of {what}", effect=True)

    def _cycles(self) -> None:
        """A plan must not contain itself through states, plan types or problems."""
        colour: dict[str, int] = {}
        reported: set[frozenset[str]] = set()

        def visit(name: str, path: list[str]) -> None:
            colour[name] = 1
            path.append(name)
            for child in children_of(self.abstract[name]):
                if child not in self.abstract:
                    continue
                if colour.get(child) == 1:
                    loop = path[path.index(child) :] + [child]
                    key = frozenset(loop)
                    if key not in reported:
                        reported.add(key)
                        self.problems.add(
                            self.abstract[child].span,
                            f"the plan tree has a cycle: {' -> '.join(loop)}",
                            "a plan must not run itself, directly or through other plans; break the cycle",
                        )
                elif child not in colour:
                    visit(child, path)
            path.pop()
            colour[name] = 2

        for name in self.abstract:
            if name not in colour:
                visit(name, [])


class _Vocabularies:
    """What each file's formulas may read: the base vocabulary, its own declarations and its imports'."""

    def __init__(self, documents: Sequence[Document], base: Vocabulary, problems: Problems) -> None:
        self.base = base
        self.problems = problems
        self.by_path = {_resolved(d.path): d for d in documents if d.path}
        self.owner = {id(e): d for d in documents for e in d.elements()}
        self.cache: dict[int, Vocabulary] = {}
        self.reported: set[tuple[str, int, str]] = set()
        for document in documents:
            self.of_document(document)

    def of(self, element: object) -> Vocabulary | None:
        """The vocabulary of the file that holds ``element`` (None for an element built without a file)."""
        document = self.owner.get(id(element))
        return self.of_document(document) if document is not None else self.base

    def of_document(self, document: Document) -> Vocabulary:
        """The declarations visible in ``document``."""
        hit = self.cache.get(id(document))
        if hit is not None:
            return hit
        vocabulary = self.base.copy()
        for visible in self._visible(document):
            for kind, declarations in (("predicate", visible.predicates), ("function", visible.functions)):
                for declaration in declarations:
                    self._declare(vocabulary, kind, declaration)
        self.cache[id(document)] = vocabulary
        return vocabulary

    def _visible(self, document: Document) -> list[Document]:
        """``document`` and every file it imports, directly or not, each once."""
        out, seen, todo = [], set(), [document]
        while todo:
            current = todo.pop(0)
            if id(current) in seen:
                continue
            seen.add(id(current))
            out.append(current)
            for name in current.imports:
                target = self.by_path.get(_resolved(name, current.path))
                if target is not None:
                    todo.append(target)
        return out

    def _declare(self, vocabulary: Vocabulary, kind: str, d: Declaration) -> None:
        try:
            if kind == "predicate":
                vocabulary.declare_predicate(d.name, d.arity, d.doc, origin=str(d.span or ""))
            else:
                vocabulary.declare_function(d.name, d.arity, d.doc, origin=str(d.span or ""))
        except ValueError as exc:
            key = (str(d.span), d.arity, kind)
            if key not in self.reported:
                self.reported.add(key)
                self.problems.add(d.span, f"{kind} {d}: {exc}", "declare each name as one kind only")


def _resolved(path: str, importer: str | None = None) -> str:
    """A plan file's path, or an import's of the file ``importer``, resolved (as given when it cannot be)."""
    try:
        return str((import_target(importer, path) if importer else plan_path(path)).resolve())
    except (OSError, ValueError):  # ValueError: a NUL byte in an import path
        return path


def _kind(cls: type) -> str:
    return {Behaviour: "behaviour", Plan: "plan", PlanType: "plan type", PlanningProblem: "planning problem"}.get(
        cls, cls.__name__
    )


def _article(word: str) -> str:
    return "an" if word[:1].lower() in "aeiou" else "a"
