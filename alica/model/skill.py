"""Skill declarations written in plan files: a skill catalogue as data.

A plan file's ``skills:`` section declares skills the way a Python plug-in's
``register(registry)`` does, minus the implementation: the name behaviours
give in ``skill:``, the parameters they may pass, a line of documentation and
the capabilities a robot needs. A declaration is visible to every file of the
document set (like a task). When the skill registry the loader is given
already declares the same name (the shipped catalogue, an installed plug-in,
a ``--skills MODULE``), the registry's declaration is used and the file's is
ignored: that is how a module binds an implementation to a skill a plan file
declared. :mod:`alica.io.skill_declarations` turns these declarations into
:class:`alica.lang.skills.SkillSpec` objects.
"""

from __future__ import annotations

from dataclasses import dataclass

from alica.model.behaviour import ParamValue
from alica.model.common import span_field
from alica.source import SourceSpan


@dataclass(frozen=True, slots=True)
class SkillParameter:
    """One parameter of a declared skill, as :class:`alica.lang.skills.ParamSpec` has it.

    Args:
        name: the key behaviours use under ``params``.
        type: one of :data:`alica.lang.skills.PARAM_TYPES` (``any`` when not written).
        required: whether a behaviour must give it (written ``required``; when left
            out, true unless a ``default`` is given).
        default: the value used when a behaviour leaves it out; ``None`` for none.
        doc: one line saying what it is.
    """

    name: str
    type: str = "any"
    required: bool = True
    default: ParamValue = None
    doc: str = ""
    span: SourceSpan | None = span_field()


@dataclass(frozen=True, slots=True)
class SkillDeclaration:
    """A skill declared in a plan file, without an implementation.

    Args:
        name: the name behaviours give in ``skill:``; unique in the document set.
        params: the parameters it takes.
        doc: one line saying what it does.
        capabilities: what a robot needs to run it (e.g. ``arm``).
    """

    name: str
    params: tuple[SkillParameter, ...] = ()
    doc: str = ""
    capabilities: frozenset[str] = frozenset()
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<SkillDeclaration {self.name}>"
