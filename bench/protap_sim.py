"""The ProTaP simulator: steps per second, and the baselines' rewards on the two reference instances.

Speed: ``--steps`` steps of the simulator alone (joint actions drawn by the
random policy beforehand), and whole episodes with the random and greedy
policies (policy plus step), on 2 robots / 5x5 / 3 goals and 4 robots / 8x8 /
6 goals. Rewards: greedy and random, horizon 10, 20 episodes (mean and sample
standard deviation), on the paper's Appendix C instance (typos fixed) and on a
seeded 4 robots / 8x8 / 6 goals instance, next to the reference figures of the
project's ProTaP notes (greedy 2152.6 +- 73.6 and 4331.1 +- 59.3; random
84.5 +- 241.4 and 54.2 +- 291.5). Greedy is "go, then do" (a goto or a do per
robot and step); random draws a goto and a do per robot, as the domain allows
both in one step. The 8x8 layout of the notes is not known, so that row
compares a different layout; ``--layouts`` averages greedy and random over
several seeded 8x8 layouts as well.

Run: ``.venv/bin/python bench/protap_sim.py [--steps 200000] [--seed 0] [--layouts 20]``
"""

from __future__ import annotations

import argparse
import random
import statistics
import time

from alica.prophet.protap import (
    ProtapModel,
    appendix_c_spec,
    evaluate,
    greedy,
    random_policy,
    random_spec,
)
from alica.prophet.protap.policies import Policy, run_episode

REFERENCE = {
    ("appendix C, 2 robots 5x5 3 goals", "greedy"): "2152.6 +- 73.6",
    ("appendix C, 2 robots 5x5 3 goals", "random"): "84.5 +- 241.4",
    ("seeded 4 robots 8x8 6 goals", "greedy"): "4331.1 +- 59.3",
    ("seeded 4 robots 8x8 6 goals", "random"): "54.2 +- 291.5",
}


def _step_rate(model: ProtapModel, steps: int, seed: int) -> float:
    rng = random.Random(seed)
    state = model.initial
    joints = []
    for _ in range(1000):
        joint = random_policy(model, state, rng)
        joints.append(joint)
        state = model.step(state, joint, rng)[0]
    state = model.initial
    start = time.perf_counter()
    for i in range(steps):
        state = model.step(state, joints[i % 1000], rng)[0]
        if i % 10 == 9:
            state = model.initial
    return steps / (time.perf_counter() - start)


def _episode_rate(model: ProtapModel, policy: Policy, steps: int, seed: int) -> float:
    rng = random.Random(seed)
    episodes = max(1, steps // model.spec.horizon)
    start = time.perf_counter()
    for _ in range(episodes):
        run_episode(model, policy, rng)
    return episodes * model.spec.horizon / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--layouts", type=int, default=20)
    args = parser.parse_args()
    instances = {
        "appendix C, 2 robots 5x5 3 goals": appendix_c_spec(),
        "seeded 4 robots 8x8 6 goals": random_spec(robots=4, width=8, height=8, goals=6, seed=args.seed),
    }
    print("steps per second (step alone | random policy + step | greedy policy + step)")
    for name, spec in instances.items():
        model = ProtapModel(spec)
        print(
            f"  {name}: {_step_rate(model, args.steps, args.seed):,.0f} | "
            f"{_episode_rate(model, random_policy, args.steps // 2, args.seed):,.0f} | "
            f"{_episode_rate(model, greedy, args.steps // 4, args.seed):,.0f}"
        )
    print("total reward, horizon 10, 20 episodes (mean +- sample std) | the notes")
    for name, spec in instances.items():
        model = ProtapModel(spec)
        for label, policy in (("greedy", greedy), ("random", random_policy)):
            result = evaluate(model, policy, episodes=20, seed=args.seed)
            print(f"  {name}, {label}: {result.mean:.1f} +- {result.std:.1f} | {REFERENCE[(name, label)]}")
    if args.layouts:
        for label, policy in (("greedy", greedy), ("random", random_policy)):
            means = [
                evaluate(ProtapModel(random_spec(4, 8, 8, 6, seed=seed)), policy, episodes=20, seed=seed).mean
                for seed in range(args.layouts)
            ]
            print(
                f"  {label} over {args.layouts} seeded 4 robots 8x8 6 goals layouts: "
                f"{statistics.fmean(means):.1f} (layout means {min(means):.1f} to {max(means):.1f})"
            )
        for label, policy in (("greedy", greedy), ("random", random_policy)):
            c_means = [
                evaluate(ProtapModel(appendix_c_spec()), policy, episodes=20, seed=seed).mean for seed in range(50)
            ]
            print(
                f"  {label} on appendix C, 50 runs of 20 episodes: {statistics.fmean(c_means):.1f} "
                f"(run means {min(c_means):.1f} to {max(c_means):.1f})"
            )


if __name__ == "__main__":
    main()
