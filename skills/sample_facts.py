"""What a detection of a drill sample tells the world model beyond found(s): shared by the 2-D and 3-D perception."""

from __future__ import annotations

from alica.worldmodel.protocol import WorldModelLike

__all__ = ["seen_on_the_ground"]


def seen_on_the_ground(wm: WorldModelLike, sample: str) -> None:
    """A sample seen standing on the ground is in nobody's gripper: retract ``holding(r, sample)``.

    A robot that crashed holding it (its gripper opened, the sample fell) cannot retract its own fact,
    and the planner leaves out a sample a robot outside the team holds.
    """
    for fact in list(wm.facts()):
        if fact.predicate == "holding" and len(fact.args) == 2 and str(fact.args[1]) == sample:
            wm.retract_fact("holding", *fact.args)
