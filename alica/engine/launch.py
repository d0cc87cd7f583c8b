"""What a state's children get when the agent enters the state: their variables, and a behaviour's runner.

When a plan node enters a state (:meth:`PlanNode.enter_state
<alica.engine.node.PlanNode.enter_state>`), every child of the state is bound:

* **variables**: each binding of the child reference is evaluated in the
  parent's context; a binding to a typed variable of the parent plan takes
  the value the constraint solver gives this agent (:mod:`alica.engine.solving`);
  a binding whose value is not known yet is handed on as its text, with the
  parent's variables replaced by their values;
* **a behaviour's runner**: its parameters bound from those variables, its
  skill found by the :class:`~alica.engine.behaviours.SkillBinder`, and the
  :class:`~alica.engine.behaviours.SkillContext` the skill is given (the
  agent's world model, belief, random generator, robot interface, scratch
  space and constraint query).

:class:`Launcher` satisfies :class:`alica.engine.node.Launch`, the interface
the plan nodes and slots call.
"""

from __future__ import annotations

import random
import re
from collections.abc import Mapping

import py_trees

from alica.engine.behaviours import BehaviourRunner, SkillBinder, SkillContext
from alica.engine.node import PlanNode
from alica.engine.parts import AgentContext
from alica.engine.slot import Slot
from alica.engine.solving import Solving, binding_names
from alica.errors import AlicaError
from alica.model import Behaviour, ChildRef
from alica.worldmodel import WorldModelLike

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _substitute(text: str, env: Mapping[str, object]) -> str:
    """``text`` with the names of ``env``'s string (and number) variables replaced by their values."""

    def value(match: re.Match[str]) -> str:
        found = env.get(match.group(0))
        return str(found) if isinstance(found, (str, int, float)) and not isinstance(found, bool) else match.group(0)

    return _NAME.sub(value, text)


class Launcher:
    """Binds the children of the states one agent enters (see the module docstring).

    Args:
        ctx: the agent's name, clock, formulas and belief.
        solving: the agent's constraint queries.
        skills: finds the implementation of each behaviour's skill.
        world_model: the agent's world model, handed to skills.
        rng: the agent's random generator, handed to skills.
        world: the robot interface, handed to skills.
        scratch: the agent's scratch space, shared by its behaviours.
    """

    def __init__(
        self,
        ctx: AgentContext,
        solving: Solving,
        skills: SkillBinder,
        world_model: WorldModelLike,
        rng: random.Random,
        world: object | None,
        scratch: dict[str, object],
    ) -> None:
        self.ctx = ctx
        self.solving = solving
        self.skills = skills
        self.world_model = world_model
        self.rng = rng
        self.world = world
        self.scratch = scratch

    def bind(self, node: PlanNode, ref: ChildRef) -> dict[str, object]:
        """The variables of a child: its bindings evaluated in the parent's context.

        A binding to a variable of the parent plan that has a type (``real[..]``,
        an object type, ...) takes the value the constraint solver gives this
        agent (:mod:`alica.engine.solving`). A binding whose value is not known
        yet (``pos(a)`` before ``a`` is seen) is handed on as its text, for the
        skill to resolve later, with the parent's variables replaced by their
        values (``pos(x)`` with ``x = a`` becomes ``pos(a)``).

        Raises:
            NoSolution: a binding reads a solved variable and the constraints have no solution now.
        """
        ctx = self.ctx
        env: dict[str, object] = {"self": ctx.name}
        if not ref.bindings:
            return env
        solved = self.solving.bound_names(node, binding_names(ref))
        if solved:
            values = self.solving.values(node, tuple(sorted(set(solved.values()))))
            env.update({child: values[parent] for child, parent in solved.items()})
        belief = ctx.belief.at(node)
        for binding in ref.bindings:
            if binding.variable in solved:
                continue
            try:
                env[binding.variable] = ctx.formulas.value(binding.value, belief, node.env)
            except AlicaError:
                env[binding.variable] = _substitute(binding.value, node.env)
        return env

    def runner(self, slot: Slot) -> BehaviourRunner:
        """The runner of a behaviour child, with its parameters bound."""
        behaviour = slot.element
        assert isinstance(behaviour, Behaviour)
        params: dict[str, object] = {}
        for param in behaviour.params:
            variable = param.variable
            params[param.name] = slot.env.get(variable, param.value) if variable else param.value
        path = f"{slot.parent.key_text}/{slot.parent.state}/{behaviour.name}"
        ctx = self.ctx
        context = SkillContext(ctx.name, ctx.now, self.world_model, ctx.belief, self.rng, self.world, behaviour, path)
        context.solver = self.solving.asker(slot)
        context.scratch = self.scratch
        try:
            factory = self.skills.factory(behaviour)
        except AlicaError as exc:
            message = str(exc)

            def factory(name: str, params: Mapping[str, object], context: SkillContext) -> py_trees.behaviour.Behaviour:
                raise AlicaError(message)

        return BehaviourRunner(behaviour, params, factory, context)
