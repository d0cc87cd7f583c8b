"""Behaviours: atomic single-agent programs that bind a registered skill."""

from __future__ import annotations

from dataclasses import dataclass

from alica.model.common import Condition, Variable, span_field
from alica.source import SourceSpan

#: A parameter value as written: a scalar, a list of scalars, or a ``$variable`` reference.
ParamValue = str | int | float | bool | tuple["ParamValue", ...] | None


@dataclass(frozen=True, slots=True)
class Param:
    """One parameter given to a skill.

    A string value that starts with ``$`` names a variable of the behaviour,
    bound at run time (``goal: $target``).
    """

    name: str
    value: ParamValue
    span: SourceSpan | None = span_field()

    @property
    def variable(self) -> str | None:
        """The variable the value refers to, if it is a ``$name`` reference."""
        if isinstance(self.value, str) and self.value.startswith("$"):
            return self.value[1:]
        return None


@dataclass(frozen=True, slots=True)
class Behaviour:
    """An atomic behaviour in a state: a skill with parameters and conditions.

    Args:
        name: unique among all plans, plan types, behaviours and problems.
        skill: the name of a skill in the skill registry.
        params: the skill's parameters.
        variables: values bound by the parent (``$name`` in params).
        pre: must hold to start the behaviour.
        run: must keep holding while it runs.
        post: holds after it succeeded.
        frequency: ticks per second, 0 for the engine's rate.
    """

    name: str
    skill: str
    params: tuple[Param, ...] = ()
    variables: tuple[Variable, ...] = ()
    pre: Condition | None = None
    run: Condition | None = None
    post: Condition | None = None
    frequency: float = 0.0
    description: str = ""
    span: SourceSpan | None = span_field()

    def __repr__(self) -> str:
        return f"<Behaviour {self.name} skill={self.skill}>"

    @property
    def param_map(self) -> dict[str, object]:
        """Parameter name -> value."""
        return {p.name: p.value for p in self.params}
