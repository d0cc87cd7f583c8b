"""What a skill is given when it is built: the agent, its time, its world model and the robot world.

The engine passes its :class:`~alica.engine.SkillContext` (a dataclass) and
:func:`alica.skills.testing.run_skill` passes the same. Skills type against
:class:`SkillContextLike`, so any object with these members serves;
:class:`SkillEnv` is a plain one (the opponents' inner skills run with it).
"""

from __future__ import annotations

import random
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Protocol

from alica.errors import AlicaError
from alica.lang.belief import BeliefBase
from alica.worldmodel.protocol import WorldModelLike

__all__ = ["SkillContextLike", "SkillEnv", "SolveAnswer"]


class SolveAnswer(Protocol):
    """What a constraint query answers (the engine's :class:`~alica.engine.solving.SolveResult`)."""

    @property
    def ok(self) -> bool:
        """Whether there are values."""
        ...

    @property
    def values(self) -> Mapping[str, object]:
        """This agent's values, by variable name."""
        ...


class SkillContextLike(Protocol):
    """The members of a skill's context that skills read."""

    @property
    def agent(self) -> str:
        """The agent's name (its robot in the world is named alike)."""
        ...

    @property
    def now(self) -> Callable[[], float]:
        """A function giving the current (simulated) time."""
        ...

    @property
    def world_model(self) -> WorldModelLike | None:
        """The agent's world-model replica (outcome facts go here), or None."""
        ...

    @property
    def rng(self) -> random.Random:
        """A random generator seeded from the run's seed and the agent."""
        ...

    @property
    def world(self) -> object | None:
        """The robot world (a :class:`~alica.worldsim.interface.RobotWorld`), when there is one."""
        ...

    @property
    def extra(self) -> Mapping[str, object]:
        """Run options (``jobs``, ``optimize_time``)."""
        ...

    @property
    def belief(self) -> BeliefBase | None:
        """The agent's whole belief base (the engine's: teammates' roles and liveness too), or None alone."""
        ...

    @property
    def solver(self) -> Callable[[tuple[str, ...]], SolveAnswer] | None:
        """The engine's constraint query for this behaviour; None outside an engine (see :meth:`solve`)."""
        ...

    def solve(self, *names: str) -> SolveAnswer:
        """The values the constraint solver gives the behaviour's variables ``names`` now.

        Raises:
            AlicaError: the skill runs outside an engine (:attr:`solver` is None).
        """
        ...

    @property
    def scratch(self) -> dict[str, object]:
        """The agent's own scratch space, shared by its behaviours and never sent to the team.

        A pipeline of skills in consecutive states hands its data on here (a
        point cloud, the clusters found in it, a cropped image): too large or
        too private for the shared world model. Keys are the producing skill's
        documented outputs, e.g. ``"cloud"``.
        """
        ...


@dataclass(frozen=True, slots=True)
class SkillEnv:
    """A plain :class:`SkillContextLike`.

    Attributes:
        agent: the agent's name.
        now: the clock.
        rng: the random generator.
        world: the robot world, or None.
        world_model: the world model, or None (what the skill writes goes nowhere).
        extra: run options.
        scratch: the agent's scratch space (see :attr:`SkillContextLike.scratch`).
        belief: the agent's belief base, or None.
        solver: a constraint query, or None (no engine: :meth:`solve` raises).
    """

    agent: str
    now: Callable[[], float]
    rng: random.Random
    world: object | None = None
    world_model: WorldModelLike | None = None
    extra: Mapping[str, object] = field(default_factory=dict)
    scratch: dict[str, object] = field(default_factory=dict)
    belief: BeliefBase | None = None
    solver: Callable[[tuple[str, ...]], SolveAnswer] | None = None

    def solve(self, *names: str) -> SolveAnswer:
        """The solver's values for ``names`` (see :meth:`SkillContextLike.solve`)."""
        if self.solver is None:
            raise AlicaError(f"'{self.agent}' runs outside an engine: there are no constraints to solve")
        return self.solver(tuple(names))

    @classmethod
    def without_world_model(cls, context: SkillContextLike) -> SkillEnv:
        """``context`` with the same agent, clock, generator, world, options and scratch space, but no world model."""
        return cls(
            context.agent,
            context.now,
            context.rng,
            context.world,
            None,
            dict(context.extra),
            context.scratch,
            context.belief,
            context.solver,
        )
