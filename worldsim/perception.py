"""Perception for team runs: facts read from the simulated world, written into each agent's world model.

The robots of a simulated team see the world through a reader such as
:func:`alica.worldsim.scenarios.blocks_facts` (an overhead camera, in effect). Every
``every`` simulated seconds :class:`FactPerception` reads the facts once and
brings each running agent's world model in line with the reading: for the
predicates it senses, it asserts what is missing and retracts what is no
longer seen. Only differences are written, so the replicas send small
deltas; and a fact that a skill or a late message wrote wrongly (a robot
said to hold nothing while it holds a block) is put right at the next
reading, not only when the world changes again.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

Fact = tuple[object, ...]


class FactPerception:
    """A ``perception`` hook for :class:`alica.engine.SimulatedTeam`.

    Args:
        read: the facts of a world, as ``(predicate, *args)`` tuples.
        every: seconds of simulated time between two readings.
        predicates: the predicates ``read`` senses (facts of other predicates are
            never touched); by default every predicate it has returned so far.
    """

    def __init__(
        self, read: Callable[[Any], Iterable[Fact]], every: float = 0.2, predicates: Iterable[str] = ()
    ) -> None:
        if every <= 0:
            raise ValueError(f"FactPerception: 'every' must be a positive number of seconds, got {every}")
        self.read = read
        self.every = every
        self.next_at = float("-inf")
        self.predicates: set[str] = set(predicates)
        self.facts: set[Fact] = set()

    def __call__(self, team: Any) -> None:
        """Read the world (when a reading is due) and update every running agent's world model."""
        now = team.now()
        if now + 1e-9 < self.next_at:
            return
        self.next_at = now + self.every
        self.facts = {tuple(f) for f in self.read(team.world)}
        self.predicates.update(str(f[0]) for f in self.facts)
        for engine in team.running():
            self.write(engine.name, engine.world_model)

    def write(self, agent: str, world_model: Any) -> int:
        """Bring ``world_model`` in line with the last reading (the sensed predicates only); returns the number of writes."""
        sensed = self.predicates
        believed = {tuple(f) for f in world_model.facts() if str(f[0]) in sensed}
        writes = 0
        for fact in sorted(self.facts - believed, key=repr):
            world_model.assert_fact(str(fact[0]), *fact[1:])
            writes += 1
        for fact in sorted(believed - self.facts, key=repr):
            world_model.retract_fact(str(fact[0]), *fact[1:])
            writes += 1
        return writes
