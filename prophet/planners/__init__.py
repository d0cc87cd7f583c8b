"""The planner back-ends by name: the builtin search, Fast Downward, ProTaP (stepwise, for teams) and
the temporal planner (durative actions, makespan).

``PLANNERS`` maps a name to ``"module:Class"``; :func:`get_planner` imports the
back-end only when it is asked for, so an optional back-end that is not
installed costs nothing. :func:`available` says which back-ends can run here
and, for the others, why not.

Example:
    >>> from alica.prophet.planners import get_planner
    >>> planner = get_planner("fd", alias="lama-first")  # doctest: +SKIP
"""

from __future__ import annotations

import importlib
from typing import Any

from alica.errors import PlannerError
from alica.prophet.planner import Planner

PLANNERS: dict[str, str] = {
    "builtin": "alica.prophet.search.planner:BuiltinPlanner",
    "fd": "alica.prophet.planners.fd:FastDownward",
    "protap": "alica.prophet.protap.step_planner:ProtapStepPlanner",
    "temporal": "alica.prophet.planners.temporal:TemporalPlanner",
}
"""Every back-end: name -> ``"module:Class"`` of a :class:`~alica.prophet.planner.Planner` subclass."""

__all__ = ["PLANNERS", "available", "get_planner", "planner_class"]


def planner_class(name: str) -> type[Planner]:
    """The class of the back-end called ``name``, imported on demand.

    Args:
        name: a key of :data:`PLANNERS`.

    Raises:
        PlannerError: the name is unknown (the message lists the known ones),
            or its module cannot be imported.
    """
    target = PLANNERS.get(name)
    if target is None:
        known = ", ".join(sorted(PLANNERS))
        raise PlannerError(f"unknown planner '{name}'; known planners: {known}")
    module_name, _, class_name = target.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise PlannerError(f"planner '{name}' cannot be loaded ({module_name}): {exc}") from exc
    cls = getattr(module, class_name, None)
    if not (isinstance(cls, type) and issubclass(cls, Planner)):
        raise PlannerError(f"planner '{name}': {target} is not a Planner class")
    return cls


def get_planner(name: str, **options: Any) -> Planner:
    """A new planner of the back-end called ``name``.

    Args:
        name: a key of :data:`PLANNERS`, e.g. ``"builtin"`` or ``"fd"``.
        **options: passed to the back-end's constructor (e.g. ``alias`` for ``"fd"``).

    Raises:
        PlannerError: the name is unknown or the back-end cannot be loaded.
    """
    cls = planner_class(name)
    try:
        return cls(**options)
    except TypeError as exc:
        raise PlannerError(f"planner '{name}' does not take these options: {exc}") from exc


def available() -> dict[str, str]:
    """Every back-end with the reason it cannot run here, or ``""`` when it can.

    A back-end class overrides :meth:`~alica.prophet.planner.Planner.unavailable`
    to check what it needs beyond its module (Fast Downward checks that the
    planner is installed).
    """
    reasons: dict[str, str] = {}
    for name in PLANNERS:
        try:
            cls = planner_class(name)
        except PlannerError as exc:
            reasons[name] = str(exc)
            continue
        reasons[name] = cls.unavailable()
    return reasons
