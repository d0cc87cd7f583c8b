"""Saved states of a world: pybullet's ``saveState`` with the robots' and arms' kinematic state.

``world.snapshots`` (a :class:`Snapshots`) saves a state and goes back to it.
The clock and the world's random generator are not part of a state (time never
goes back). Adding or removing bodies drops every saved state: pybullet cannot
restore a state saved with other bodies.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any, Protocol

from alica.worldsim._quiet import quiet_stdout
from alica.worldsim.errors import WorldError
from alica.worldsim.objects import WorldObject

__all__ = ["SnapshotWorld", "Snapshots"]


class _SavedArm(Protocol):
    """An arm as a snapshot sees it: its own state, and what it holds (massless while held)."""

    @property
    def held(self) -> WorldObject | None: ...

    def _state(self) -> dict[str, Any]: ...

    def _restore(self, state: dict[str, Any]) -> None: ...

    def _grip_physics(self, obj: WorldObject, held: bool) -> None: ...


class _SavedRobot(Protocol):
    """A robot as a snapshot sees it: its kinematic state and its arm."""

    @property
    def arm(self) -> _SavedArm | None: ...

    def _state(self) -> dict[str, Any]: ...

    def _restore(self, state: dict[str, Any]) -> None: ...


class SnapshotWorld(Protocol):
    """What snapshots use of a world: its client, its robots, the names of its objects."""

    @property
    def client(self) -> Any:
        """The world's pybullet client."""
        ...

    @property
    def quiet(self) -> bool:
        """Whether pybullet's prints are hidden."""
        ...

    @property
    def robots(self) -> Mapping[str, _SavedRobot]:
        """Robots by name."""
        ...

    @property
    def objects(self) -> Collection[str]:
        """The names of the objects."""
        ...

    _version: int

    def _check_open(self) -> None:
        """Raise if the world is closed."""
        ...


class Snapshots:
    """The saved states of one world (``world.snapshots``)."""

    __slots__ = ("_states", "_world")

    def __init__(self, world: SnapshotWorld) -> None:
        self._world = world
        self._states: dict[int, dict[str, Any]] = {}

    def save(self) -> int:
        """Save physics (pybullet ``saveState``) and the kinematic state; returns the state id."""
        world = self._world
        world._check_open()
        state_id = int(world.client.saveState())
        self._states[state_id] = {
            "objects": set(world.objects),
            "robots": {n: r._state() for n, r in world.robots.items()},
            "arms": {n: r.arm._state() for n, r in world.robots.items() if r.arm is not None},
        }
        return state_id

    def restore(self, state_id: int) -> None:
        """Go back to a state of :meth:`save` (bodies and kinematic state).

        Raises:
            WorldError: an unknown id, or one saved before bodies were added or removed.
        """
        world = self._world
        world._check_open()
        saved = self._states.get(state_id)
        if saved is None:
            raise WorldError(
                f"snapshots.restore: unknown state id {state_id}; use an id returned by snapshots.save "
                f"(states are dropped when robots or objects are removed)"
            )
        if set(saved["robots"]) != set(world.robots) or saved["objects"] != set(world.objects):
            raise WorldError(
                f"snapshots.restore: state {state_id} was saved with other robots or objects; "
                f"save a new state after adding bodies"
            )
        # Held objects are massless; give them their mass back first so that the bodies match the saved ones.
        for robot in world.robots.values():
            if robot.arm is not None and robot.arm.held is not None:
                robot.arm._grip_physics(robot.arm.held, False)
        client = world.client
        try:
            with quiet_stdout(world.quiet):
                client.restoreState(stateId=state_id)
        except client.error as exc:
            raise WorldError(
                f"snapshots.restore: pybullet could not restore state {state_id} ({exc}); "
                f"it was probably saved before bodies were added; save a new state"
            ) from None
        for name, robot in world.robots.items():
            robot._restore(saved["robots"][name])
            if robot.arm is not None:
                robot.arm._restore(saved["arms"][name])
        world._version += 1

    def discard(self, state_id: int) -> None:
        """Free a saved state."""
        if self._states.pop(state_id, None) is not None:
            self._world.client.removeState(state_id)

    def discard_all(self) -> None:
        """Free every saved state (the world's bodies changed)."""
        for state_id in list(self._states):
            self.discard(state_id)

    def forget(self) -> None:
        """Drop every saved state without asking pybullet (the world is closing)."""
        self._states.clear()
