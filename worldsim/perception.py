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

With ``places`` it also writes where things are: ``pos(name) = (x, y)`` for
each thing the reader places, whenever the world model has no position for it
or one farther than the thing's tolerance from the reading (a robot driving
is written again every half metre, a block put down elsewhere at once).
Allocation weighs who is nearest to a task with these positions
(``closeness`` in a generated plan's utility), and skills drive to them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Protocol

from alica.lang.fact import Fact
from alica.worldmodel.protocol import WorldModelLike

if TYPE_CHECKING:
    from alica.worldsim.world import World

#: A fact as a reader gives it: a :class:`~alica.lang.fact.Fact` or a flat ``(predicate, *args)`` tuple.
Reading = Fact | tuple[object, ...]
#: Where a thing is as a ``places`` reader gives it: ``x``, ``y`` and the tolerance in metres before it is written again.
Place = tuple[float, float, float]
#: The world-model function the positions go to.
POSITION = "pos"


class _Agent(Protocol):
    @property
    def name(self) -> str: ...

    @property
    def world_model(self) -> WorldModelLike: ...


class _Team(Protocol):
    @property
    def world(self) -> World: ...

    def now(self) -> float: ...

    def running(self) -> Iterable[_Agent]: ...


class FactPerception:
    """A ``perception`` hook for :class:`alica.engine.SimulatedTeam`.

    Args:
        read: the facts of a world, as :class:`~alica.lang.fact.Fact` or ``(predicate, *args)`` tuples.
        every: seconds of simulated time between two readings.
        predicates: the predicates ``read`` senses (facts of other predicates are
            never touched); by default every predicate it has returned so far.
        places: where things are (name -> ``(x, y, tolerance)``), written as ``pos(name)``; none by default.

    Attributes:
        facts: the last reading, as ``read`` gave it (flat tuples stay flat tuples).
    """

    def __init__(
        self,
        read: Callable[[World], Iterable[Reading]],
        every: float = 0.2,
        predicates: Iterable[str] = (),
        places: Callable[[World], Mapping[str, Place]] | None = None,
    ) -> None:
        if every <= 0:
            raise ValueError(f"FactPerception: 'every' must be a positive number of seconds, got {every}")
        self.read = read
        self.every = every
        self.next_at = float("-inf")
        self.predicates: set[str] = set(predicates)
        self.facts: set[Reading] = set()
        self._seen: set[Fact] = set()
        self.places = places
        self._where: Mapping[str, Place] = {}

    def __call__(self, team: _Team) -> None:
        """Read the world (when a reading is due) and update every running agent's world model."""
        now = team.now()
        if now + 1e-9 < self.next_at:
            return
        self.next_at = now + self.every
        self.facts = set(self.read(team.world))
        self._seen = {Fact.of(f) for f in self.facts}
        self.predicates.update(f.predicate for f in self._seen)
        if self.places is not None:
            self._where = self.places(team.world)
        for engine in team.running():
            self.write(engine.name, engine.world_model)

    def write(self, agent: str, world_model: WorldModelLike) -> int:
        """Bring ``world_model`` in line with the last reading (the sensed predicates only); returns the number of writes."""
        sensed = self.predicates
        believed = {f for f in world_model.facts() if f.predicate in sensed}
        writes = 0
        for fact in sorted(self._seen - believed, key=_order):
            world_model.assert_fact(fact.predicate, *fact.args)
            writes += 1
        for fact in sorted(believed - self._seen, key=_order):
            world_model.retract_fact(fact.predicate, *fact.args)
            writes += 1
        for name, (x, y, tolerance) in sorted(self._where.items()):
            known = world_model.get(POSITION, name)
            if isinstance(known, (tuple, list)) and len(known) >= 2:
                if math.hypot(float(known[0]) - x, float(known[1]) - y) <= tolerance:
                    continue
            world_model.set(POSITION, name, value=(round(x, 3), round(y, 3)))
            writes += 1
        return writes


def _order(fact: Fact) -> str:
    return repr(fact.flat)  # the order of the flat tuples the readers give: the writes come in the same order
