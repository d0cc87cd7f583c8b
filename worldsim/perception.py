"""Perception for team runs: facts read from the simulated world, written into each agent's world model.

The robots of a simulated team see the world through a reader such as
:func:`worldsim.scenarios.blocks_facts` (an overhead camera, in effect). Every
``every`` simulated seconds :class:`FactPerception` reads the facts once and
writes to each running agent's world model only what changed since it last
wrote there, so the replicas send small deltas.
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
    """

    def __init__(self, read: Callable[[Any], Iterable[Fact]], every: float = 0.2) -> None:
        if every <= 0:
            raise ValueError(f"FactPerception: 'every' must be a positive number of seconds, got {every}")
        self.read = read
        self.every = every
        self.next_at = float("-inf")
        self.seen: dict[str, set[Fact]] = {}
        self.facts: set[Fact] = set()

    def __call__(self, team: Any) -> None:
        """Read the world (when a reading is due) and update every running agent's world model."""
        now = team.now()
        if now + 1e-9 < self.next_at:
            return
        self.next_at = now + self.every
        self.facts = {tuple(f) for f in self.read(team.world)}
        for engine in team.running():
            self.write(engine.name, engine.world_model)

    def write(self, agent: str, world_model: Any) -> int:
        """Bring ``world_model`` in line with the last reading; returns the number of writes."""
        before = self.seen.get(agent, set())
        writes = 0
        for fact in sorted(self.facts - before, key=repr):
            if not world_model.holds(str(fact[0]), *fact[1:]):
                world_model.assert_fact(str(fact[0]), *fact[1:])
                writes += 1
        for fact in sorted(before - self.facts, key=repr):
            if world_model.holds(str(fact[0]), *fact[1:]):
                world_model.retract_fact(str(fact[0]), *fact[1:])
                writes += 1
        self.seen[agent] = set(self.facts)
        return writes
