"""Planning the way back to the transport pose from wherever the arm is, as data.

A pick-up or put-down plan (:mod:`alica.skills.manipulation.pickup`) already
ends in the transport pose. When the arm got somewhere else (a grasp whose
plan was not followed to its end, a step skill run on its own), it plans::

    paths[0]  q_start -> q_lifted       straight up by ``lift`` (when the tool points down), holding ``held``
    paths[1]  q_lifted -> q_transport   a free motion holding ``held``

Either path is left out when it is not needed (the tool is not pointing
down, or the arm is in the transport pose already).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from alica.skills.manipulation.arm_paths import path_is_free, plan_arm
from alica.skills.manipulation.cartesian import straight_line
from alica.skills.manipulation.geometry import as_configuration, quat_rotate
from alica.skills.manipulation.grasps import APPROACH_HEIGHT
from alica.skills.manipulation.pickup import _lift_is_free
from alica.worldsim.arm_interface import ArmPlanningScene
from alica.worldsim.geometry import Box

#: Joint distance (rad, largest joint) within which the arm counts as in the transport pose.
AT_TRANSPORT = 1e-3


@dataclass(frozen=True, slots=True, eq=False)
class TransportPlan:
    """Result of :func:`plan_transport`.

    Attributes:
        ok: a plan was found (``paths`` is empty when the arm is in the transport pose already).
        paths: up to two (N, 7) joint paths, the lift and the free motion, to follow in order.
        reason: ``"ok"`` or why planning failed.
        plan_time_s: wall time of the planning, seconds.
    """

    ok: bool
    paths: list[np.ndarray]
    reason: str
    plan_time_s: float = 0.0


def plan_transport(
    scene: ArmPlanningScene,
    q_start: Sequence[float] | np.ndarray,
    *,
    rng: np.random.Generator,
    held: Box | None = None,
    q_transport: Sequence[float] | np.ndarray | None = None,
    lift: float = APPROACH_HEIGHT,
    time_limit: float = 1.0,
    seed: int | None = None,
) -> TransportPlan:
    """Plan from ``q_start`` to the transport pose: straight up by ``lift`` first when the tool points down.

    The lift is checked with ``held`` (a tool-frame box, e.g. from
    :func:`~alica.skills.manipulation.held_box`) only from
    :data:`~alica.skills.manipulation.pickup.LIFT_CLEARANCE` above the start,
    where the object leaves its support; a lift that collides is left out and
    the free motion starts at ``q_start``.

    Args:
        scene: the arm scene (the held object must not be among its obstacles).
        q_start: the arm's current configuration.
        rng: passed to the inverse kinematics of the lift.
        held: the object held, as a box in the tool frame, or None.
        q_transport: the transport configuration (default ``scene.home_q``).
        lift: height of the straight lift in metres (>= 0; 0: none).
        time_limit: budget of the free-motion query, seconds.
        seed: OMPL seed (see :func:`~alica.skills.manipulation.plan_arm`).

    Raises:
        ValueError: malformed configurations or a negative ``lift``.
    """
    t0 = time.perf_counter()
    start = as_configuration(q_start, 7, "q_start")
    transport = scene.home_q if q_transport is None else as_configuration(q_transport, 7, "q_transport")
    if not lift >= 0.0:
        raise ValueError(f"lift must be >= 0 metres, got {lift!r}")
    if float(np.abs(start - transport).max()) <= AT_TRANSPORT:
        return TransportPlan(True, [], "ok", time.perf_counter() - t0)
    paths: list[np.ndarray] = []
    (x, y, z), quat = scene.fk(start)
    pointing_down = quat_rotate(quat, (0.0, 0.0, 1.0))[2] < -0.95
    if lift > 0.0 and pointing_down:
        up, _ = straight_line(scene, start, ((x, y, z + lift), quat), rng=rng)
        free = up is not None and (path_is_free(scene, up) if held is None else _lift_is_free(scene, up[::-1], held, z))
        if up is not None and free:
            paths.append(up)
            start = up[-1]
    carry = plan_arm(scene, start, transport, held=held, time_limit=time_limit, seed=seed)
    if not carry.ok:
        return TransportPlan(False, [], f"to the transport pose: {carry.reason}", time.perf_counter() - t0)
    paths.append(carry.path)
    return TransportPlan(True, paths, "ok", time.perf_counter() - t0)
