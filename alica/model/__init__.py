"""The team language as immutable, typed objects.

Elements refer to each other by name; a :class:`PlanLibrary` resolves names.
Every element keeps the :class:`~alica.source.SourceSpan` it was read from,
which ``==`` ignores, so a plan read from YAML equals the same plan read from XML.
"""

from alica.model.behaviour import Behaviour, Param, ParamValue
from alica.model.common import (
    ANY_TYPE,
    NUMERIC_TYPES,
    UNBOUNDED,
    Condition,
    ConditionKind,
    Constraint,
    StateKind,
    Variable,
    format_cardinality,
)
from alica.model.declaration import Declaration
from alica.model.library import SECTIONS, AbstractPlan, Document, PlanLibrary, children_of
from alica.model.plan import (
    Binding,
    ChildRef,
    EntryPoint,
    Plan,
    PlanningSignature,
    PlanType,
    State,
    Summand,
    Synchronisation,
    Transition,
    UtilityFunction,
)
from alica.model.planning import PlanningProblem
from alica.model.roles import Priority, Role, RoleSet, Task
from alica.model.skill import SkillDeclaration, SkillParameter

__all__ = [
    "ANY_TYPE",
    "NUMERIC_TYPES",
    "SECTIONS",
    "UNBOUNDED",
    "AbstractPlan",
    "Behaviour",
    "Binding",
    "ChildRef",
    "Condition",
    "ConditionKind",
    "Constraint",
    "Declaration",
    "Document",
    "EntryPoint",
    "Param",
    "ParamValue",
    "Plan",
    "PlanLibrary",
    "PlanType",
    "PlanningProblem",
    "PlanningSignature",
    "Priority",
    "Role",
    "RoleSet",
    "SkillDeclaration",
    "SkillParameter",
    "State",
    "StateKind",
    "Summand",
    "Synchronisation",
    "Task",
    "Transition",
    "UtilityFunction",
    "Variable",
    "children_of",
    "format_cardinality",
]
