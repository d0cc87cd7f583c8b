"""ProTaP behind the planner interface: a plan file's planning problem names ``planner: protap``.

:class:`ProtapStepPlanner` reads the pipeline's PDDL task as a ProTaP problem
(:func:`~alica.prophet.protap.places.read_places`), searches with
:class:`~alica.prophet.protap.planner.ProtapPlanner` in slices (a
``Progress`` event after each, so the runtime budgets it per engine tick)
and returns **the next step** as a plan: per robot its do, then its goto.
It is a *stepwise* planner (:attr:`~alica.prophet.planner.Planner.stepwise`):
the runtime runs the step with each action pinned to the robot the planner
named, and when the step is over plans the next one from the world as it
is then, the outcome of actions that failed included, until the goal holds.

Example::

    problems:
      - name: SurveySites
        planner: protap
        elements: [GotoSite, TakeSample, ScanSite]
        goal: "sampled(s1) and scanned(s2)"
"""

from __future__ import annotations

import random
from collections.abc import Iterator, Mapping, Sequence

from alica.prophet.pddl.model import Domain, Problem
from alica.prophet.planner import Done, Feature, Improved, Plan, Planner, PlanStatus, Progress, SearchEvent
from alica.prophet.protap.model import ProtapModel
from alica.prophet.protap.places import read_places
from alica.prophet.protap.planner import Budget, ProtapPlanner


class ProtapStepPlanner(Planner):
    """The next step of a ProTaP policy for a team's planning problem (see the module docstring).

    Args:
        trials: the search's trials for one step (deterministic for a seed).
        slice_trials: the trials between two ``Progress`` events.
        horizon: the look-ahead in steps.
        seed: seeds the sampled outcomes of the search.
        positions: object name -> position in metres (the world model's ``pos``);
            ``GOTO_COST`` is 1 between places whose positions are unknown.
    """

    name = "protap"
    features = frozenset(
        {Feature.STRIPS, Feature.TYPING, Feature.NEGATIVE_PRECONDITIONS, Feature.EQUALITY, Feature.ACTION_COSTS}
    )
    stepwise = True
    reads_positions = True

    def __init__(
        self,
        trials: int = 2000,
        slice_trials: int = 100,
        horizon: int = 10,
        seed: int = 0,
        positions: Mapping[str, Sequence[float]] | None = None,
    ) -> None:
        if trials < 0 or slice_trials < 1 or horizon < 1:
            raise ValueError("protap needs trials >= 0, slice_trials >= 1 and horizon >= 1")
        self.trials = trials
        self.slice_trials = slice_trials
        self.horizon = horizon
        self.seed = seed
        self.positions = dict(positions or {})

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        assert isinstance(domain, Domain) and isinstance(problem, Problem)
        places = read_places(domain, problem, self.positions, horizon=self.horizon)
        model = ProtapModel(places.spec)
        planner = ProtapPlanner(model)
        state = places.state
        rng = random.Random(self.seed)
        done = 0
        while done < self.trials:
            done += planner.search(state, Budget(trials=min(self.slice_trials, self.trials - done)), rng)
            yield Progress(done)
        joint = planner.best(state)
        steps = places.steps(model, joint)
        if not steps:
            yield Done(
                PlanStatus.UNSOLVABLE, done, "protap: no action is worth its cost (every goal is done or out of reach)"
            )
            return
        yield Improved(Plan(steps, float(len(steps))), done)
        yield Done(PlanStatus.SOLVED, done, "the next step")
