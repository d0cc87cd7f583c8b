"""``BuiltinPlanner``: the pure-Python planner behind the :class:`~alica.prophet.planner.Planner` interface."""

from __future__ import annotations

from collections.abc import Iterator, Sequence

from alica.prophet.planner import Feature, Limits, Planner, SearchEvent
from alica.prophet.search.anytime import DEFAULT_WEIGHTS, FirstSearch, search_task

BYTES_PER_OPERATOR = 512
"""The search's memory estimate per operator besides its masks (three masks of half the facts' bits on average)."""


class BuiltinPlanner(Planner):
    """Grounds the task, then runs :func:`~alica.prophet.search.anytime.search_task`.

    Args:
        weights: the weighted A* weights of the anytime phase.
        progress_every: expansions between two ``Progress`` events.
        first: how the first plan is searched (:class:`~alica.prophet.search.anytime.FirstSearch`);
            ``None``: the default first search.
    """

    name = "builtin"
    features = frozenset(
        {
            Feature.STRIPS,
            Feature.TYPING,
            Feature.NEGATIVE_PRECONDITIONS,
            Feature.EQUALITY,
            Feature.CONDITIONAL_EFFECTS,
            Feature.ACTION_COSTS,
            Feature.DERIVED_PREDICATES,
        }
    )

    takes_limits = True

    def __init__(
        self,
        *,
        weights: Sequence[float] = DEFAULT_WEIGHTS,
        progress_every: int = 1000,
        first: FirstSearch | None = None,
    ) -> None:
        self.weights = tuple(weights)
        self.progress_every = progress_every
        self.first = first

    def _search(
        self, domain: object, problem: object, *, anytime: bool, limits: Limits | None = None
    ) -> Iterator[SearchEvent]:
        from alica.prophet.ground import ground  # lazy: the grounding is only needed here
        from alica.prophet.pddl import Domain, Problem

        if not isinstance(domain, Domain) or not isinstance(problem, Problem):
            raise TypeError(
                f"the builtin planner takes a pddl Domain and Problem, got {type(domain).__name__}, {type(problem).__name__}"
            )
        self.last_ground_task = None
        task = ground(domain, problem, limits)
        self.last_ground_task = task
        if limits is not None:  # the search's bitsets: per operator, masks as wide as the facts
            n_ops, n_facts = len(task.operators), len(task.facts)
            limits.check(
                "preparing the search",
                limits.resident() + n_ops * (BYTES_PER_OPERATOR + 3 * n_facts // 16),
                f"{n_ops} ground operators over {n_facts} facts",
            )
        yield from search_task(
            task,
            anytime=anytime,
            weights=self.weights,
            progress_every=self.progress_every,
            first=self.first,
            limits=limits if limits is not None and limits.bounds_search else None,
        )
