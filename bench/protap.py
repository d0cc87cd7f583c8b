"""The ProTaP planner against greedy and random: total reward, constraint breaks, time and trials per step.

Three instances, horizon 10: (a) the paper's Appendix C (2 robots, 5x5, 3
goals), (b) 4 robots on 8x8 with 6 goals and (c) 8 robots on 12x12 with 12
goals (both placed by ``random_spec`` with ``--seed``). Every policy runs the
same ``--episodes`` episodes (one seeded ``random.Random`` each, as
:func:`evaluate` does); the planner replans every step from the observed
state with ``--time-per-step`` seconds, its search drawing from a random
source of its own, so that the episodes' draws go to the outcomes alone. A
state with every goal done needs no search; the planner's time and trials
per step are over the steps that searched. Constraint breaks count the
limits :meth:`ProtapModel.violations` reports over every joint action chosen
(must be 0). The second table gives the planner's reward on (a) and (b) as
the time per step grows; at 0 s it runs no trial and plays its heuristic's
"do, then go" joint actions.

Run: ``.venv/bin/python bench/protap.py [--episodes 20] [--time-per-step 0.5] [--seed 0] [--quick]``
(``--quick``: 3 episodes, 0.1 s per step, two budgets in the second table.)
"""

from __future__ import annotations

import argparse
import random
import statistics

from alica.prophet.protap import (
    Budget,
    PlannerPolicy,
    ProblemSpec,
    ProtapModel,
    ProtapPlanner,
    Recorder,
    appendix_c_spec,
    evaluate,
    greedy,
    random_policy,
    random_spec,
)


def _median(values: list[float]) -> float:
    return statistics.median(values) if values else 0.0


def _instances(seed: int) -> dict[str, ProblemSpec]:
    return {
        "(a) Appendix C, 2 robots 5x5, 3 goals": appendix_c_spec(),
        "(b) 4 robots 8x8, 6 goals": random_spec(robots=4, width=8, height=8, goals=6, seed=seed),
        "(c) 8 robots 12x12, 12 goals": random_spec(robots=8, width=12, height=12, goals=12, seed=seed),
    }


def _planner_policy(model: ProtapModel, seconds: float, seed: int) -> Recorder:
    planner = ProtapPlanner(model)
    return Recorder(PlannerPolicy(planner, Budget(seconds=seconds), rng=random.Random(seed)), planner)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--time-per-step", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    episodes = 3 if args.quick else args.episodes
    per_step = 0.1 if args.quick else args.time_per_step
    budgets = (0.0, 0.05, 0.25) if args.quick else (0.0, 0.05, 0.1, 0.25, 0.5, 1.0)
    instances = _instances(args.seed)

    print(f"Total reward, horizon 10, {episodes} episodes (seed {args.seed}), planner at {per_step} s per step\n")
    print(
        "| instance | policy | reward mean | std | constraint breaks | median s/step | max s/step | trials/step (median) |"
    )
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, spec in instances.items():
        model = ProtapModel(spec)
        runs = {
            "planner": _planner_policy(model, per_step, args.seed),
            "greedy": Recorder(greedy),
            "random": Recorder(random_policy),
        }
        for label, recorder in runs.items():
            result = evaluate(model, recorder, episodes=episodes, seed=args.seed)
            trials = f"{statistics.median(recorder.trials):,.0f}" if recorder.trials else "-"
            print(
                f"| {name} | {label} | {result.mean:.1f} | {result.std:.1f} | {recorder.breaks} | "
                f"{_median(recorder.seconds):.4f} | {max(recorder.seconds, default=0.0):.4f} | {trials} |",
                flush=True,
            )

    print(f"\nPlanner reward (mean +- std, {episodes} episodes) against the time per step\n")
    print("| instance | " + " | ".join(f"{b} s" for b in budgets) + " |")
    print("| --- | " + " | ".join("---:" for _ in budgets) + " |")
    for name, spec in list(instances.items())[:2]:
        model = ProtapModel(spec)
        cells = []
        for seconds in budgets:
            recorder = _planner_policy(model, seconds, args.seed)
            result = evaluate(model, recorder, episodes=episodes, seed=args.seed)
            trials = statistics.median(recorder.trials) if recorder.trials else 0
            cells.append(f"{result.mean:.1f} +- {result.std:.1f} ({trials:,.0f} trials)")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
