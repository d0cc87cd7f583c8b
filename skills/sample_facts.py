"""What a detection of a drill sample tells the world model beyond found(s): shared by the 2-D and 3-D perception."""

from __future__ import annotations

from typing import Any

from alica.worldmodel.protocol import WorldModelLike

__all__ = ["dropped_samples", "report_found", "seen_on_the_ground", "stale_verdicts"]


def seen_on_the_ground(wm: WorldModelLike, sample: str) -> None:
    """A sample seen standing on the ground is in nobody's gripper: retract ``holding(r, sample)``.

    A robot that crashed holding it (its gripper opened, the sample fell) cannot retract its own fact,
    and the planner leaves out a sample a robot outside the team holds.
    """
    for fact in list(wm.facts()):
        if fact.predicate == "holding" and len(fact.args) == 2 and str(fact.args[1]) == sample:
            wm.retract_fact("holding", *fact.args)


def report_found(wm: WorldModelLike, sample: str, now: float) -> None:
    """Write what a perception skill that recognised ``sample`` on the ground knows.

    ``found(sample)`` and ``onground(sample)`` (the planning domain's fact), the time it was
    first found as ``found_at(sample)`` (simulated seconds; kept when it is seen again, so the
    operator can order the samples by when the team found them, not by when their facts
    reached it), and no ``holding(r, sample)`` (:func:`seen_on_the_ground`).
    """
    if wm.get("found_at", sample) is None:
        wm.set("found_at", sample, value=round(now, 3))
    wm.assert_fact("found", sample)
    wm.assert_fact("onground", sample)
    seen_on_the_ground(wm, sample)


def dropped_samples(wm: WorldModelLike | None, belief: Any) -> list[tuple[str, str, tuple[float, float]]]:
    """``(sample, holder, last_seen)`` of the samples held by teammates the agent believes lost, sorted.

    ``belief`` answers ``role(r)`` (a teammate has one) and ``alive(r)``
    (the engine's :class:`~alica.engine.belief.AgentBelief`); without it no
    teammate is known lost. A sample whose last position is unknown is left out.
    """
    if wm is None or belief is None:
        return []
    out = []
    for fact in wm.facts():
        if fact.predicate != "holding" or len(fact.args) != 2:
            continue
        holder, sample = (str(a) for a in fact.args)
        if belief.lookup("role", (holder,)) is None or belief.lookup("alive", (holder,)):
            continue
        seen = wm.get("pos", sample)
        if isinstance(seen, (tuple, list)) and len(seen) >= 2:
            out.append((sample, holder, (float(seen[0]), float(seen[1]))))
    return sorted(out)


def stale_verdicts(verdicts: dict[str, str], wm: WorldModelLike | None, belief: Any) -> set[str]:
    """The candidates whose verdict named a sample a lost teammate held: the sample fell, look again."""
    dropped = {sample for sample, _, _ in dropped_samples(wm, belief)}
    return {cid for cid, name in verdicts.items() if name in dropped} if dropped else set()
