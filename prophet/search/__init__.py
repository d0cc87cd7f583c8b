"""The builtin planner: bitset states, FF and landmarks, LAMA's lazy search, anytime weighted A*.

See ``docs/search.md``. Entry points: :class:`BuiltinPlanner` (the
:class:`~alica.prophet.planner.Planner` interface) and :func:`search_task` (a
grounded task directly).
"""

from __future__ import annotations

from alica.prophet.search.anytime import DEFAULT_WEIGHTS, FIRST_HEURISTICS, FirstSearch, search_task
from alica.prophet.search.planner import BuiltinPlanner

__all__ = ["DEFAULT_WEIGHTS", "FIRST_HEURISTICS", "BuiltinPlanner", "FirstSearch", "search_task"]
