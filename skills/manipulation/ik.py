"""Inverse kinematics of the tool frame: pybullet's IK, verified, with random restarts.

Each attempt starts from a seed configuration (first the caller's ``q_seed`` or
the scene's rest pose, then uniformly random configurations inside the limits)
and repeats short rounds of ``calculateInverseKinematics`` (damped least
squares, small damping). Between rounds the iterate is projected into the
joint limits, so the search stays inside them; pybullet's limit-aware
null-space variant converged far less often (see ``docs/manipulation.md``).

Nothing is clipped silently: a result is returned only after forward
kinematics of the final configuration confirms the position and orientation
errors, the configuration is checked against the limits, and it is collision
free.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from alica.skills.manipulation.geometry import as_configuration, as_quat, as_vec3, quat_angle
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.geometry import Box

log = logging.getLogger(__name__)

#: pybullet IK iterations per round; rounds are separated by the limit projection.
_ITERATIONS_PER_ROUND = 3
#: Joint damping of pybullet's damped least squares (its default converges slowly).
_DAMPING = 0.003


@dataclass(frozen=True, slots=True, eq=False)
class IKResult:
    """Outcome of :func:`solve_ik`.

    Attributes:
        ok: a configuration was found.
        q: the 7 joint values (``None`` if not ok).
        error: position error in metres of ``q`` (or of the best attempt if not ok; ``inf`` if none ran).
        attempts: IK attempts made (the first one plus restarts; 0 if rejected up front).
        reason: ``"ok"`` or why no configuration was found.
        angle_error: orientation error in radians, same convention as ``error``.
    """

    ok: bool
    q: np.ndarray | None
    error: float
    attempts: int
    reason: str
    angle_error: float = field(default=math.inf)


def solve_ik(
    scene: ArmPlanningScene,
    target_pos: Sequence[float],
    target_quat: Sequence[float],
    *,
    restarts: int = 10,
    tolerance: float = 0.005,
    rng: np.random.Generator,
    angle_tolerance: float = 0.02,
    q_seed: Sequence[float] | np.ndarray | None = None,
    held: Box | None = None,
    check_collision: bool = True,
    rounds: int = 20,
) -> IKResult:
    """Find joint values putting the scene's tool frame at a pose.

    Args:
        scene: the arm scene (its client is used; joint values are left changed).
        target_pos: world position (x, y, z) of the tool frame.
        target_quat: world orientation (x, y, z, w) of the tool frame.
        restarts: random restarts after the first attempt (>= 0).
        tolerance: accepted position error in metres (> 0).
        rng: source of the restart configurations; equal generators give equal results.
        angle_tolerance: accepted orientation error in radians (> 0).
        q_seed: seed of the first attempt (default ``scene.rest_q``).
        held: object in the gripper (tool-frame box), included in the collision check.
        check_collision: reject colliding configurations (default True).
        rounds: limit-projected rounds of pybullet IK per attempt (>= 1).

    Returns:
        An :class:`IKResult`; never raises for unreachable targets.

    Raises:
        ValueError: malformed target, ``tolerance``/``angle_tolerance`` <= 0, negative
            ``restarts``, ``rounds`` < 1, or a bad ``q_seed``.
        TypeError: ``rng`` is not a numpy Generator.
    """
    pos = as_vec3(target_pos, "target_pos")
    quat = as_quat(target_quat, "target_quat")
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance must be a positive number of metres, got {tolerance!r}")
    if not (math.isfinite(angle_tolerance) and angle_tolerance > 0):
        raise ValueError(f"angle_tolerance must be a positive number of radians, got {angle_tolerance!r}")
    if int(restarts) != restarts or restarts < 0:
        raise ValueError(f"restarts must be a non-negative integer, got {restarts!r}")
    if int(rounds) != rounds or rounds < 1:
        raise ValueError(f"rounds must be a positive integer, got {rounds!r}")
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng must be a numpy Generator, got {rng!r}")
    seed = scene.rest_q if q_seed is None else as_configuration(q_seed, 7, "q_seed")

    shoulder = np.array(scene.shoulder_position())
    distance = float(np.linalg.norm(np.array(pos) - shoulder))
    if distance > scene.reach + tolerance:
        return IKResult(
            False,
            None,
            math.inf,
            0,
            f"unreachable: target is {distance:.3f} m from the shoulder, beyond the arm's reach of {scene.reach:.3f} m",
        )

    lower, upper = scene.joint_limits
    best = (math.inf, math.inf)
    counts = {"not converged": 0, "outside joint limits": 0, "in collision": 0}
    attempts = 0
    for attempt in range(int(restarts) + 1):
        start = seed if attempt == 0 else scene.random_configuration(rng)
        attempts += 1
        q, pe, ae = _descend(scene, pos, quat, start, lower, upper, tolerance, angle_tolerance, int(rounds))
        if pe + ae < best[0] + best[1]:
            best = (pe, ae)
        if pe > tolerance or ae > angle_tolerance:
            counts["not converged"] += 1
            continue
        if np.any(q < lower) or np.any(q > upper):  # defensive: the projection keeps q inside
            counts["outside joint limits"] += 1
            continue
        if check_collision and scene.collides(q, held):
            counts["in collision"] += 1
            continue
        return IKResult(True, q, pe, attempts, "ok", ae)
    detail = ", ".join(f"{n} {k}" for k, n in counts.items() if n)
    reason = (
        f"no IK solution in {attempts} attempts ({detail}); best error {best[0]:.4f} m, {best[1]:.3f} rad "
        f"(tolerance {tolerance} m, {angle_tolerance} rad)"
    )
    log.debug("solve_ik failed for %s: %s", pos, reason)
    return IKResult(False, None, best[0], attempts, reason, best[1])


def _descend(
    scene: ArmPlanningScene,
    pos: tuple[float, float, float],
    quat: tuple[float, float, float, float],
    start: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    tolerance: float,
    angle_tolerance: float,
    rounds: int,
) -> tuple[np.ndarray, float, float]:
    """One attempt: rounds of pybullet IK, each result projected into the limits; returns (q, pos err, ang err)."""
    target = np.array(pos)
    q = np.clip(np.asarray(start, dtype=float), lower, upper)
    pe = ae = math.inf
    stalled = 0
    for _ in range(rounds):
        scene.set_joints(q)
        solution = scene.ik_round(pos, quat, damping=_DAMPING, iterations=_ITERATIONS_PER_ROUND)
        q = np.clip(solution, lower, upper)
        scene.set_joints(q)
        p_now, q_now = scene.current_tool_pose()
        new_pe = float(np.linalg.norm(np.array(p_now) - target))
        new_ae = quat_angle(q_now, quat)
        if new_pe < 0.1 * tolerance and new_ae < 0.1 * angle_tolerance:
            return q, new_pe, new_ae
        # Stop an attempt that no longer improves (stuck at a limit or a local minimum).
        stalled = stalled + 1 if new_pe > 0.98 * pe and new_ae > 0.98 * ae else 0
        pe, ae = new_pe, new_ae
        if stalled >= 3:
            break
    return q, pe, ae
