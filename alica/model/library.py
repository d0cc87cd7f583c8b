"""Documents (one file's elements) and the library (every element of a document set)."""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Protocol, TypeVar

from alica.model.behaviour import Behaviour
from alica.model.declaration import Declaration
from alica.model.plan import Plan, PlanType
from alica.model.planning import PlanningProblem
from alica.model.roles import RoleSet, Task
from alica.model.skill import SkillDeclaration

#: Anything a state can run.
AbstractPlan = Behaviour | Plan | PlanType | PlanningProblem

#: The document sections in file order, with the element type each holds.
SECTIONS: tuple[tuple[str, type], ...] = (
    ("tasks", Task),
    ("rolesets", RoleSet),
    ("behaviours", Behaviour),
    ("plans", Plan),
    ("plantypes", PlanType),
    ("problems", PlanningProblem),
)


class _Named(Protocol):
    @property
    def name(self) -> str: ...


_N = TypeVar("_N", bound=_Named)


def _by_name(sections: Iterable[tuple[_N, ...]]) -> dict[str, _N]:
    """Name -> element of the elements in ``sections`` (one section of every document)."""
    return {e.name: e for section in sections for e in section}


def children_of(element: AbstractPlan) -> tuple[str, ...]:
    """Names of the abstract plans ``element`` runs directly: the edges of the plan tree.

    A plan runs its states' children, a plan type its alternatives, a planning
    problem its elements, WaitPlan and AlternativePlan; a behaviour runs nothing.
    """
    if isinstance(element, Plan):
        return tuple(c.name for s in element.states for c in s.children)
    if isinstance(element, PlanType):
        return element.plans
    if isinstance(element, PlanningProblem):
        extra = tuple(p for p in (element.wait_plan, element.alternative_plan) if p)
        return element.elements + extra
    return ()


@dataclass(frozen=True, slots=True)
class Document:
    """The elements written in one plan file, in file order.

    Args:
        path: the file, as given to the loader (ignored by ``==``).
        imports: other files this one refers to, relative to it.
        predicates: the predicates declared here for formulas to read.
        functions: the functions declared here for formulas to read.
        skills: the skills declared here (:mod:`alica.model.skill`), visible to the whole document set.
    """

    imports: tuple[str, ...] = ()
    predicates: tuple[Declaration, ...] = ()
    functions: tuple[Declaration, ...] = ()
    skills: tuple[SkillDeclaration, ...] = ()
    tasks: tuple[Task, ...] = ()
    rolesets: tuple[RoleSet, ...] = ()
    behaviours: tuple[Behaviour, ...] = ()
    plans: tuple[Plan, ...] = ()
    plantypes: tuple[PlanType, ...] = ()
    problems: tuple[PlanningProblem, ...] = ()
    path: str = field(default="", compare=False)

    def elements(self) -> Iterator[Task | RoleSet | AbstractPlan]:
        """Every element, section by section."""
        for section, _ in SECTIONS:
            yield from getattr(self, section)


@dataclass(frozen=True, eq=False)
class PlanLibrary:
    """Every element of a validated document set, by name.

    Build it with :func:`alica.io.load_library`, which validates first; the
    constructor itself trusts its input (unique names, resolved references).
    Two libraries are equal when they hold equal elements, whatever files
    and formats the elements came from.
    """

    documents: tuple[Document, ...]

    @cached_property
    def tasks(self) -> dict[str, Task]:
        """Task name -> task."""
        return _by_name(d.tasks for d in self.documents)

    @cached_property
    def rolesets(self) -> dict[str, RoleSet]:
        """Role set name -> role set."""
        return _by_name(d.rolesets for d in self.documents)

    @cached_property
    def skills(self) -> dict[str, SkillDeclaration]:
        """Skill name -> the declaration a plan file of the set wrote (Python declarations are not here)."""
        return _by_name(d.skills for d in self.documents)

    @cached_property
    def behaviours(self) -> dict[str, Behaviour]:
        """Behaviour name -> behaviour."""
        return _by_name(d.behaviours for d in self.documents)

    @cached_property
    def plans(self) -> dict[str, Plan]:
        """Plan name -> plan."""
        return _by_name(d.plans for d in self.documents)

    @cached_property
    def plantypes(self) -> dict[str, PlanType]:
        """Plan type name -> plan type."""
        return _by_name(d.plantypes for d in self.documents)

    @cached_property
    def problems(self) -> dict[str, PlanningProblem]:
        """Planning problem name -> problem."""
        return _by_name(d.problems for d in self.documents)

    def abstract(self, name: str) -> AbstractPlan:
        """The behaviour, plan, plan type or problem called ``name``.

        Raises:
            KeyError: nothing has that name.
        """
        for index in (self.plans, self.behaviours, self.plantypes, self.problems):
            if name in index:
                return index[name]
        raise KeyError(f"no behaviour, plan, plan type or planning problem named '{name}'")

    def children(self, element: AbstractPlan) -> tuple[str, ...]:
        """Names of the abstract plans ``element`` can run directly (edges of the plan tree)."""
        return children_of(element)

    def roots(self) -> tuple[Plan, ...]:
        """Plans no other element runs: the top of each plan tree."""
        used = {
            c
            for doc in self.documents
            for e in doc.elements()
            if not isinstance(e, (Task, RoleSet))
            for c in self.children(e)
        }
        return tuple(p for p in self.plans.values() if p.name not in used)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PlanLibrary):
            return NotImplemented
        return self._sections() == other._sections()

    def _sections(self) -> tuple[Mapping[str, object], ...]:
        """Name -> element of every section, in :data:`SECTIONS` order, then the declared skills."""
        return (self.tasks, self.rolesets, self.behaviours, self.plans, self.plantypes, self.problems, self.skills)

    def __hash__(self) -> int:
        return hash(tuple(sorted(self.plans)))
