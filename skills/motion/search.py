"""The OMPL side of :func:`alica.skills.motion.plan_path`: one SE2 RRTConnect query (plus AORRTC), all objects local.

Also the one module flag of the package: OMPL logging silenced and the process seed set
(see :func:`configure_ompl` and :mod:`alica.skills.motion.base_paths` on reproducibility).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from alica.skills.motion.reach import coarse_reachable
from alica.skills.motion.validity import GridChecker, SegmentValidator
from alica.worldsim.grid import OccupancyGrid

__all__ = ["Query", "SearchResult", "configure_ompl", "search", "xy_length"]

_log = logging.getLogger(__name__)

_OMPL_CONFIGURED = False
"""The one module flag: OMPL logging silenced and (if asked) the process seed set."""

FIRST_SLICE_S = 0.1
"""Seconds of RRTConnect before the reachability test runs."""


def xy_length(path: np.ndarray) -> float:
    """Planar length of an (N, >=2) polyline."""
    if len(path) < 2:
        return 0.0
    d = np.diff(path[:, :2], axis=0)
    return float(np.hypot(d[:, 0], d[:, 1]).sum())


def configure_ompl(seed: int | None = None) -> bool:
    """Silence OMPL logging (errors only) and set the process seed, once (see :mod:`alica.skills.motion.base_paths`).

    Args:
        seed: Seed to use (>= 0), or None.

    Returns:
        Whether OMPL's seed now equals this seed (always False for None).
    """
    global _OMPL_CONFIGURED
    if not _OMPL_CONFIGURED:
        # LOG_ERROR rather than LOG_WARN: RRTConnect warns for every goal-region sample that
        # falls next to an obstacle ("Skipping invalid goal state"), which is expected here.
        ou.setLogLevel(ou.LOG_ERROR)
        if seed is not None:
            ou.RNG.setSeed(int(seed) + 1)
        _OMPL_CONFIGURED = True
    if seed is None:
        return False
    if ou.RNG.getSeed() != int(seed) + 1:
        _log.debug("OMPL seed is fixed per process; seed %s cannot take effect now", seed)
        return False
    return True


def _to_array(path: og.PathGeometric) -> np.ndarray:
    return np.array([(s.getX(), s.getY(), s.getYaw()) for s in path.getStates()], dtype=float).reshape(-1, 3)


@dataclass(frozen=True, slots=True)
class Query:
    """One planning query (goal yaw None = any heading)."""

    sx: float
    sy: float
    syaw: float
    gx: float
    gy: float
    gyaw: float | None
    tolerance: float


@dataclass(frozen=True, slots=True)
class SearchResult:
    """The outcome of :func:`search`."""

    status: str
    path: np.ndarray
    reason: str
    first_solution_s: float
    first_solution_cpu_s: float


def _space(grid: OccupancyGrid) -> ob.SE2StateSpace:
    xmin, ymin, xmax, ymax = grid.bounds
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, xmin)
    bounds.setHigh(0, xmax)
    bounds.setLow(1, ymin)
    bounds.setHigh(1, ymax)
    space.setBounds(bounds)
    return space


def search(
    checker: GridChecker,
    q: Query,
    deadline: float,
    *,
    simplify: bool,
    optimize_time: float,
    check_reachability: bool,
) -> SearchResult:
    """One OMPL query on the given checker; all OMPL objects are local."""
    space = _space(checker.grid)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(checker)
    si.setMotionValidator(SegmentValidator(si, checker))
    si.setStateValidityCheckingResolution(checker.step / space.getMaximumExtent())
    si.setup()
    ss = og.SimpleSetup(si)
    start = si.allocState()
    start.setXY(q.sx, q.sy)
    start.setYaw(q.syaw)
    if q.gyaw is None:
        half = q.tolerance / math.sqrt(2.0)
        region = ob.SE2StateSpace()
        rb = ob.RealVectorBounds(2)
        rb.setLow(0, q.gx - half)
        rb.setHigh(0, q.gx + half)
        rb.setLow(1, q.gy - half)
        rb.setHigh(1, q.gy + half)
        region.setBounds(rb)
        goal = ob.GoalSpace(si)
        goal.setSpace(region)
        ss.setStartState(start)
        ss.setGoal(goal)
    else:
        goal_state = si.allocState()
        goal_state.setXY(q.gx, q.gy)
        goal_state.setYaw(q.gyaw)
        ss.setStartAndGoalStates(start, goal_state, q.tolerance)
    ss.setPlanner(og.RRTConnect(si))

    t0 = time.perf_counter()
    c0 = time.process_time()
    budget = max(0.0, deadline - t0)
    ss.solve(min(budget, FIRST_SLICE_S) if check_reachability else budget)
    if not ss.haveExactSolutionPath() and check_reachability:
        blocked = checker.blocked
        si_, sj_ = checker.grid.world_to_cell(q.sx, q.sy)
        gi_, gj_ = checker.grid.world_to_cell(q.gx, q.gy)
        if not coarse_reachable(blocked, (si_, sj_), (gi_, gj_)):
            return SearchResult(
                "unreachable",
                np.empty((0, 3)),
                "start and goal are not connected on the grid inflated by the robot radius + margin "
                "(coarse flood fill): the goal (or the start) is enclosed by obstacles",
                time.perf_counter() - t0,
                time.process_time() - c0,
            )
        remaining = deadline - time.perf_counter()
        if remaining > 0.0:
            ss.solve(remaining)
    first_s = time.perf_counter() - t0
    first_cpu = time.process_time() - c0
    if not ss.haveSolutionPath():
        return SearchResult("timeout", np.empty((0, 3)), "no path found within the time limit", first_s, first_cpu)
    exact = ss.haveExactSolutionPath()
    path = og.PathGeometric(ss.getSolutionPath())
    ps = og.PathSimplifier(si, ss.getGoal()) if q.gyaw is None else og.PathSimplifier(si)
    if simplify or optimize_time > 0.0:
        ps.simplifyMax(path)
    best = _to_array(path)
    if not exact:
        end = best[-1]
        gap = math.hypot(end[0] - q.gx, end[1] - q.gy)
        return SearchResult(
            "approximate",
            best,
            f"no exact path within the time limit; the best valid path ends {gap:.2f} m from the goal",
            first_s,
            first_cpu,
        )
    if optimize_time > 0.0:
        best = _optimize(si, best, q, optimize_time, ps)
    return SearchResult("exact", best, "exact path", first_s, first_cpu)


def _optimize(si: ob.SpaceInformation, first: np.ndarray, q: Query, budget: float, ps: og.PathSimplifier) -> np.ndarray:
    """AORRTC for ``budget`` seconds towards the goal point (arrival yaw of the first path for any-yaw goals)."""
    ss = og.SimpleSetup(si)
    start = si.allocState()
    start.setXY(q.sx, q.sy)
    start.setYaw(q.syaw)
    goal = si.allocState()
    goal.setXY(q.gx, q.gy)
    goal.setYaw(float(first[-1, 2]) if q.gyaw is None else q.gyaw)
    # GoalSpace goals made AORRTC exhaust memory in OMPL 2.0.1; a single goal state works.
    ss.setStartAndGoalStates(start, goal, 1e-6)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    ss.setPlanner(og.AORRTC(si))
    ss.solve(budget)
    if not ss.haveExactSolutionPath():
        return first
    path = og.PathGeometric(ss.getSolutionPath())
    ps.simplifyMax(path)
    candidate = _to_array(path)
    return candidate if xy_length(candidate) < xy_length(first) else first
