"""First-solution planning time of the base planner (grid + segment validator) against an FCL-only peer.

40 x 40 m field, 60 and 150 circular rocks (radius 0.2-1.0 m), a round robot of radius
0.5 m. Per density: several field seeds, random start/goal pairs at least ``--min-distance``
apart in free space, the same queries for every planner. Goals for ours: median first
solution at most 1 ms (60 rocks) and 15 ms (150 rocks).

* ours: :func:`alica.skills.motion.plan_path` on a prepared :class:`GridChecker` (grid inflated
  by radius + margin), SE2 RRTConnect with the numpy :class:`SegmentValidator`;
  ``first`` is its RRTConnect search alone, ``total`` the whole call with simplification.
* peer: the same RRTConnect set-up with an :class:`FclChecker` as the state validity
  checker and OMPL's discrete motion checking at the same step (half a cell, 2.5 cm), no
  grid; and, for comparison with the reference notes, at a 0.1 m step.

Wall time (``time.perf_counter``) and CPU time (``time.process_time``); the machine may be
shared, so CPU time is the steadier figure. Lengths are the planar length of the first
solution (ours also after simplification).

Run: ``.venv/bin/python bench/motion_planning.py [--queries 10] [--seeds 3] [--time-limit 5]``
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from alica.skills.motion import FclChecker, GridChecker, configure_ompl, plan_path
from alica.worldsim.grid import Obstacle2D, OccupancyGrid

BOUNDS = (-20.0, -20.0, 20.0, 20.0)
RADIUS = 0.5
RESOLUTION = 0.05
TOLERANCE = 0.1


@dataclass(frozen=True, slots=True)
class Run:
    """One query's outcome for one planner."""

    solved: bool
    wall_s: float
    cpu_s: float
    length: float
    total_wall_s: float = math.nan
    simplified_length: float = math.nan


def rock_field(seed: int, count: int) -> list[Obstacle2D]:
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        x, y = rng.uniform(-20.0, 20.0, 2)
        out.append(Obstacle2D("circle", float(x), float(y), radius=float(rng.uniform(0.2, 1.0)), name=f"rock{k}"))
    return out


def queries(checker: GridChecker, exact: FclChecker, seed: int, n: int, min_distance: float) -> list[tuple]:
    """Random start/goal pairs valid in both checkers, at least ``min_distance`` apart."""
    rng = np.random.default_rng(10_000 + seed)
    out: list[tuple] = []
    while len(out) < n:
        s = rng.uniform(-19.5, 19.5, 2)
        g = rng.uniform(-19.5, 19.5, 2)
        if math.dist(s, g) < min_distance:
            continue
        if all(checker.valid_xy(*p) and exact.valid_xy(*p) for p in (s, g)):
            out.append(((float(s[0]), float(s[1]), float(rng.uniform(-math.pi, math.pi))), (float(g[0]), float(g[1]))))
    return out


def planar_length(xy: list[tuple[float, float]]) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(xy))


def run_ours(checker: GridChecker, start: tuple, goal: tuple, time_limit: float) -> Run:
    raw = plan_path(start, goal, checker, RADIUS, time_limit=time_limit, simplify=False, goal_tolerance=TOLERANCE)
    simp = plan_path(start, goal, checker, RADIUS, time_limit=time_limit, goal_tolerance=TOLERANCE)
    return Run(
        raw.status == "exact",
        raw.first_solution_s,
        raw.first_solution_cpu_s,
        raw.length,
        simp.plan_time_s,
        simp.length if simp.ok else math.nan,
    )


def run_fcl_peer(exact: FclChecker, start: tuple, goal: tuple, time_limit: float, step: float) -> Run:
    """The same SE2 RRTConnect query with FCL state checks every ``step`` metres and no grid."""
    xmin, ymin, xmax, ymax = BOUNDS
    space = ob.SE2StateSpace()
    b = ob.RealVectorBounds(2)
    b.setLow(0, xmin)
    b.setHigh(0, xmax)
    b.setLow(1, ymin)
    b.setHigh(1, ymax)
    space.setBounds(b)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(exact)
    si.setStateValidityCheckingResolution(step / space.getMaximumExtent())
    si.setup()
    ss = og.SimpleSetup(si)
    s = si.allocState()
    s.setXY(start[0], start[1])
    s.setYaw(start[2])
    half = TOLERANCE / math.sqrt(2.0)
    region = ob.SE2StateSpace()
    rb = ob.RealVectorBounds(2)
    rb.setLow(0, goal[0] - half)
    rb.setHigh(0, goal[0] + half)
    rb.setLow(1, goal[1] - half)
    rb.setHigh(1, goal[1] + half)
    region.setBounds(rb)
    g = ob.GoalSpace(si)
    g.setSpace(region)
    ss.setStartState(s)
    ss.setGoal(g)
    ss.setPlanner(og.RRTConnect(si))
    w0, c0 = time.perf_counter(), time.process_time()
    ss.solve(time_limit)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    solved = ss.haveExactSolutionPath()
    length = math.nan
    if solved:
        length = planar_length([(q.getX(), q.getY()) for q in ss.getSolutionPath().getStates()])
    return Run(solved, wall, cpu, length)


def summary(name: str, runs: list[Run]) -> str:
    solved = [r for r in runs if r.solved]
    wall = np.array([r.wall_s for r in runs]) * 1e3
    cpu = np.array([r.cpu_s for r in runs]) * 1e3
    lengths = np.array([r.length for r in solved])
    total = np.array([r.total_wall_s for r in runs if not math.isnan(r.total_wall_s)]) * 1e3
    simp = np.array([r.simplified_length for r in runs if not math.isnan(r.simplified_length)])
    total_s = f"{np.median(total):.1f}" if total.size else "-"
    simp_s = f"{np.median(simp):.1f}" if simp.size else "-"
    return (
        f"| {name} | {np.median(wall):.2f} | {np.percentile(wall, 95):.2f} | {np.median(cpu):.2f} | "
        f"{np.percentile(cpu, 95):.2f} | {np.median(lengths) if lengths.size else math.nan:.1f} | {simp_s} | "
        f"{total_s} | {len(solved)}/{len(runs)} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queries", type=int, default=10, help="queries per field seed")
    parser.add_argument("--seeds", type=int, default=3, help="field seeds per rock count")
    parser.add_argument("--time-limit", type=float, default=5.0, help="seconds per query")
    parser.add_argument("--min-distance", type=float, default=30.0, help="least start-goal distance, metres")
    parser.add_argument("--seed", type=int, default=1, help="OMPL process seed")
    args = parser.parse_args()
    configure_ompl(args.seed)

    print(
        f"Robot radius {RADIUS} m, grid {RESOLUTION} m, {args.seeds} fields x {args.queries} queries per row, "
        f"start-goal >= {args.min_distance} m, time limit {args.time_limit} s.\n"
    )
    header = (
        "| rocks | planner | first wall median ms | wall p95 ms | first CPU median ms | CPU p95 ms | "
        "first length m (median) | simplified length m | plan_path total ms | solved |"
    )
    lines = [header, "| --- " * 10 + "|"]
    verdicts = []
    for count, goal_ms in ((60, 1.0), (150, 15.0)):
        ours: list[Run] = []
        peer: list[Run] = []
        peer_coarse: list[Run] = []
        straight: list[float] = []
        build_s: list[float] = []
        for field_seed in range(args.seeds):
            obstacles = rock_field(1000 * count + field_seed, count)
            t0 = time.perf_counter()
            grid = OccupancyGrid.from_obstacles(obstacles, BOUNDS, RESOLUTION)
            checker = GridChecker(grid, RADIUS)
            build_s.append(time.perf_counter() - t0)
            exact = FclChecker(obstacles, RADIUS)
            for start, goal in queries(checker, exact, field_seed, args.queries, args.min_distance):
                straight.append(math.dist(start[:2], goal))
                ours.append(run_ours(checker, start, goal, args.time_limit))
                peer.append(run_fcl_peer(exact, start, goal, args.time_limit, checker.step))
                peer_coarse.append(run_fcl_peer(exact, start, goal, args.time_limit, 0.1))
        lines.append(summary(f"{count} | ours: grid + segment validator", ours))
        lines.append(summary(f"{count} | peer: FCL-only, {checker.step * 100:.1f} cm step", peer))
        lines.append(summary(f"{count} | peer: FCL-only, 10 cm step", peer_coarse))
        median = float(np.median([r.wall_s for r in ours]) * 1e3)
        median_cpu = float(np.median([r.cpu_s for r in ours]) * 1e3)
        verdicts.append(
            f"- {count} rocks: ours median {median:.2f} ms wall ({'met' if median <= goal_ms else 'NOT met'}), "
            f"{median_cpu:.2f} ms CPU ({'met' if median_cpu <= goal_ms else 'NOT met'}), goal <= {goal_ms:g} ms; "
            f"straight-line distance median "
            f"{np.median(straight):.1f} m; grid build + inflation {np.median(build_s) * 1e3:.0f} ms per field."
        )
    print("\n".join(lines))
    print()
    print("\n".join(verdicts))


if __name__ == "__main__":
    main()
