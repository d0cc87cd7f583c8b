"""Collision-free joint-space paths for the arm: a direct segment if it is free, else OMPL RRTConnect.

Every returned path has been re-checked densely: each segment is sampled so
that no joint moves more than ``recheck_step`` (0.02 rad) between samples,
and every sample is collision free (:func:`path_is_free`). OMPL checks motions
at ``resolution`` (0.05 rad, a fraction of the space's maximum extent), so a
path that passes OMPL but fails the dense re-check is replaced by the
unsimplified path or planned again at a finer resolution.

Reproducibility: OMPL draws every planner's and simplifier's random seed from
one process-wide generator that can be seeded only before its first use
(``ompl.util.RNG.setSeed``). ``seed`` is therefore applied once per process, at
the first :func:`plan_arm` call that passes one; from a fresh process the same
sequence of calls with the same seed gives identical paths, while repeated
calls inside one process differ. Direct segments involve no randomness.
"""

from __future__ import annotations

import itertools
import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from alica.skills.manipulation.geometry import as_configuration
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.geometry import Box

log = logging.getLogger(__name__)

Status = Literal["exact", "invalid_start", "invalid_goal", "timeout"]

#: Motion-check step of the planner (joint-space distance, rad).
RESOLUTION = 0.05
#: Dense re-check step: the largest single-joint change between re-checked samples (rad).
RECHECK_STEP = 0.02


@dataclass(slots=True)
class _OmplSetup:
    """The guarded, process-wide OMPL configuration (logging level and the one-time seed)."""

    logging_configured: bool = False
    seed: int | None = None


_OMPL = _OmplSetup()


def _configure_ompl(seed: int | None) -> None:
    if not _OMPL.logging_configured:
        ou.setLogLevel(ou.LOG_WARN)
        _OMPL.logging_configured = True
    if seed is None:
        return
    if _OMPL.seed is None:
        ou.RNG.setSeed(max(1, int(seed)))  # OMPL rejects 0
        _OMPL.seed = int(seed)
    elif _OMPL.seed != int(seed):
        log.debug("OMPL is seeded once per process; keeping seed %d (asked for %d)", _OMPL.seed, seed)


@dataclass(frozen=True, slots=True, eq=False)
class ArmPath:
    """Result of :func:`plan_arm`.

    Attributes:
        status: ``"exact"`` (a path), ``"invalid_start"``, ``"invalid_goal"`` or ``"timeout"``.
        path: waypoints, shape (N, 7) (N >= 2 when exact, 0 otherwise); move linearly between rows.
        plan_time_s: wall time spent, seconds.
        reason: a human-readable explanation.
    """

    status: Status
    path: np.ndarray
    plan_time_s: float
    reason: str

    @property
    def ok(self) -> bool:
        """True for an exact path."""
        return self.status == "exact"


def interpolate_path(path: np.ndarray, step: float = RECHECK_STEP) -> np.ndarray:
    """Samples of a piecewise-linear joint path, no joint moving more than ``step`` between samples.

    Each segment ``a -> b`` is cut into ``ceil(max|b - a| / step)`` equal parts;
    all waypoints are included.
    """
    pts = np.asarray(path, dtype=float)
    if pts.ndim != 2 or len(pts) == 0:
        raise ValueError(f"path must be an (N, dof) array with N >= 1, got shape {pts.shape}")
    if not step > 0:
        raise ValueError(f"step must be > 0, got {step!r}")
    out = [pts[:1]]
    for a, b in itertools.pairwise(pts):
        n = max(1, math.ceil(float(np.max(np.abs(b - a))) / step - 1e-9))
        t = np.arange(1, n + 1, dtype=float)[:, None] / n
        out.append(a + (b - a) * t)
    return np.concatenate(out)


def path_is_free(
    scene: ArmPlanningScene, path: np.ndarray, held: Box | None = None, step: float = RECHECK_STEP
) -> bool:
    """True if every sample of :func:`interpolate_path` ``(path, step)`` is collision free."""
    return _samples_free(scene, interpolate_path(path, step), held)


def _samples_free(scene: ArmPlanningScene, samples: np.ndarray, held: Box | None) -> bool:
    collides = scene.collides
    return not any(collides(q, held) for q in samples.tolist())


def _check_endpoint(scene: ArmPlanningScene, q: np.ndarray, held: Box | None, which: str) -> str | None:
    lower, upper = scene.joint_limits
    bad = [i for i in range(7) if not lower[i] <= q[i] <= upper[i]]
    if bad:
        i = bad[0]
        return f"{which} outside the joint limits (joint {i}: {q[i]:.4f} not in [{lower[i]:.4f}, {upper[i]:.4f}])"
    if scene.collides(q, held):
        return f"{which} in collision" + (" (with the held object)" if held is not None else "")
    return None


def plan_arm(
    scene: ArmPlanningScene,
    q_start: Sequence[float] | np.ndarray,
    q_goal: Sequence[float] | np.ndarray,
    *,
    held: Box | None = None,
    time_limit: float = 1.0,
    seed: int | None = None,
    simplify: bool = True,
    resolution: float = RESOLUTION,
    recheck_step: float = RECHECK_STEP,
) -> ArmPath:
    """Plan a collision-free joint path from ``q_start`` to ``q_goal``.

    Args:
        scene: the arm scene (obstacles as they are now).
        q_start: start configuration (7 values).
        q_goal: goal configuration (7 values).
        held: object in the gripper as a tool-frame box; checked along the path.
        time_limit: planning budget in seconds (> 0); re-plans share it.
        seed: OMPL process seed, applied at the first call that passes one (see the module doc).
        simplify: shorten OMPL's path with OMPL's path simplifier.
        resolution: OMPL's motion-check step in rad (> 0).
        recheck_step: largest joint change between re-checked samples in rad (> 0).

    Raises:
        ValueError: malformed configurations or non-positive budgets/steps.
        TypeError: ``held`` is not a Box.
    """
    t0 = time.perf_counter()
    start = as_configuration(q_start, 7, "q_start")
    goal = as_configuration(q_goal, 7, "q_goal")
    if held is not None and not isinstance(held, Box):
        raise TypeError(f"held must be a Box or None, got {held!r}")
    for name, value in (("time_limit", time_limit), ("resolution", resolution), ("recheck_step", recheck_step)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")
    empty = np.zeros((0, 7))
    problem = _check_endpoint(scene, start, held, "start")
    if problem:
        return ArmPath("invalid_start", empty, time.perf_counter() - t0, problem)
    problem = _check_endpoint(scene, goal, held, "goal")
    if problem:
        return ArmPath("invalid_goal", empty, time.perf_counter() - t0, problem)
    direct = np.stack([start, goal])
    if _samples_free(scene, interpolate_path(direct, recheck_step)[1:-1], held):  # endpoints checked above
        return ArmPath("exact", direct, time.perf_counter() - t0, "direct segment is collision free")

    _configure_ompl(seed)
    step = float(resolution)
    reason = "no path found"
    while True:
        remaining = time_limit - (time.perf_counter() - t0)
        if remaining <= 0:
            break
        raw, simplified = _rrt_connect(scene, start, goal, held, remaining, step, simplify)
        if raw is None:
            reason = f"RRTConnect found no exact path in {time_limit:.3f} s"
            break
        for label, candidate in (("simplified", simplified), ("raw", raw)):
            if candidate is not None and path_is_free(scene, candidate, held, recheck_step):
                return ArmPath("exact", candidate, time.perf_counter() - t0, f"RRTConnect, {label} path")
        reason = f"RRTConnect paths failed the {recheck_step} rad re-check"
        step /= 2.0
        log.debug("plan_arm: re-planning at resolution %.4f rad", step)
    return ArmPath("timeout", empty, time.perf_counter() - t0, reason)


def _rrt_connect(
    scene: ArmPlanningScene,
    start: np.ndarray,
    goal: np.ndarray,
    held: Box | None,
    time_limit: float,
    step: float,
    simplify: bool,
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """One OMPL query; returns (raw path, simplified path or None). All OMPL objects stay local."""
    lower, upper = scene.joint_limits
    space = ob.RealVectorStateSpace(7)
    bounds = ob.RealVectorBounds(7)
    for i in range(7):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    collides = scene.collides

    def valid(state: ob.State) -> bool:
        return not collides(state[0:7], held)

    si.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(step / space.getMaximumExtent())
    si.setup()
    ss = og.SimpleSetup(si)
    s, g = si.allocState(), si.allocState()
    s[0:7] = [float(v) for v in start]
    g[0:7] = [float(v) for v in goal]
    ss.setStartAndGoalStates(s, g)
    ss.setPlanner(og.RRTConnect(si))
    status = ss.solve(time_limit)
    if status.getStatus() != ob.PlannerStatus.EXACT_SOLUTION:
        return None, None
    path = og.PathGeometric(ss.getSolutionPath())
    raw = np.array([st[0:7] for st in path.getStates()], dtype=float)
    simplified = None
    if simplify:
        simplifier = og.PathSimplifier(si)
        simplifier.reduceVertices(path)
        simplifier.collapseCloseVertices(path)
        simplifier.partialShortcutPath(path)
        simplified = np.array([st[0:7] for st in path.getStates()], dtype=float)
    ss.clear()
    return raw, simplified
