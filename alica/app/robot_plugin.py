"""``--robot PLUGIN``: a robot driver of one's own, for ``alica agent``, ``alica run`` and ``alica skill run``.

A robot driver is any object that offers the robot interface
(:mod:`alica.worldsim.interface`): a :class:`~alica.worldsim.interface.RobotWorld`
holding the agent's robot under the agent's name. The user names a *factory*
that makes one:

* ``--robot MODULE:FACTORY``: ``FACTORY`` of ``MODULE`` (importable from the
  current folder, as ``--skills`` modules are);
* ``--robot MODULE``: that module's ``make_robot``;
* ``--robot NAME``: an installed package's entry point ``NAME`` of the group
  :data:`ENTRY_POINT_GROUP` (the library ships ``unicycle``:
  :func:`alica.worldsim.unicycle.make_robot`).

The factory is called ``factory(name, role, options)``: the agent's name, its
role, and the ``--robot-option KEY=VALUE`` strings (``NAME.KEY=VALUE`` for one
agent only). It returns the world.

**Simulated or on the wall clock.** A world with a ``step(seconds)`` method is
simulated: the run moves it on once per tick (``alica run`` and ``alica skill
run`` by the tick's period in simulated time, ``alica agent`` by the wall
time that passed). A world without one is hardware: it runs on its own, and
the run only reads and commands it (``alica skill run`` then ticks on the wall
clock). An optional ``close()`` is called when the run ends; an optional
``crash()``/``recover()`` on a robot is what ``--crash``/``--recover`` do to
it in ``alica run`` (else the robot is stopped).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from alica.clock import Clock, ManualClock, SystemClock
from alica.errors import AlicaError

if TYPE_CHECKING:  # imported where used: every alica command builds the parsers of this module's options
    from alica.worldsim.interface import MobileRobot, RobotWorld

__all__ = [
    "ENTRY_POINT_GROUP",
    "PluggedRobots",
    "RobotFactory",
    "RobotPlugin",
    "WallPaced",
    "add_robot_options",
    "is_simulated",
    "robot_plugin",
]

#: The entry-point group under which installed packages offer robot factories.
ENTRY_POINT_GROUP = "alica.robots"

RobotFactory = Callable[[str, str, Mapping[str, str]], object]
"""``factory(name, role, options) -> world``: makes the world holding the robot named ``name``."""


def add_robot_options(parser: argparse._ActionsContainer) -> None:
    """Add ``--robot PLUGIN`` and the repeatable ``--robot-option KEY=VALUE`` to a subcommand's parser."""
    parser.add_argument(
        "--robot",
        metavar="MODULE[:FACTORY]",
        help="run the skills on a robot driver of your own: FACTORY (default make_robot) of MODULE, or an installed "
        f"plug-in of the entry-point group {ENTRY_POINT_GROUP} by name (shipped: unicycle, a kinematic unicycle with "
        "a simulated lidar on a 2-D map; ros2, a ROS 2 mobile base over rmw_zenoh, see docs/ros2.md)",
    )
    parser.add_argument(
        "--robot-option",
        action="append",
        default=[],
        metavar="[NAME.]KEY=VALUE",
        help="an option for the robot factory, e.g. pose=1,2,0; NAME.KEY=VALUE for the agent NAME only (repeatable)",
    )


def is_simulated(world: object) -> bool:
    """Whether the run moves ``world`` on (it has ``step(seconds)``); otherwise it runs on the wall clock."""
    return callable(getattr(world, "step", None))


@dataclass(frozen=True, slots=True)
class RobotPlugin:
    """A robot factory and the options given for it.

    Attributes:
        label: how the user named it (for messages).
        factory: the factory.
        options: ``KEY -> VALUE`` for every agent.
        per_agent: ``NAME -> KEY -> VALUE`` for one agent (these win).
    """

    label: str
    factory: RobotFactory
    options: Mapping[str, str]
    per_agent: Mapping[str, Mapping[str, str]]

    def options_for(self, name: str) -> dict[str, str]:
        """The options the factory gets for agent ``name``."""
        return {**self.options, **self.per_agent.get(name, {})}

    def make(self, name: str, role: str) -> RobotWorld:
        """Call the factory for agent ``name`` of ``role`` and check what it returns.

        Raises:
            AlicaError: the factory raised, returned no robot world, or one without a robot named ``name``
                (the message names the plug-in and what to do).
        """
        from alica.worldsim.interface import RobotWorld

        try:
            world = self.factory(name, role, self.options_for(name))
        except Exception as exc:  # the user's driver failed: say which, in one line
            raise AlicaError(
                f"--robot {self.label}: making robot '{name}' failed: {type(exc).__name__}: {exc}"
            ) from None
        if not isinstance(world, RobotWorld):
            raise AlicaError(
                f"--robot {self.label}: the factory returned a {type(world).__name__}, which does not offer the robot "
                "interface (alica.worldsim.interface.RobotWorld: robots, objects, bounds, seed, now, ...)"
            )
        if name not in world.robots:
            close_world(world)
            raise AlicaError(
                f"--robot {self.label}: the world it made has no robot named '{name}' "
                f"(robots: {', '.join(sorted(world.robots)) or 'none'}); the factory names the robot after the agent"
            )
        return world


def robot_plugin(args: argparse.Namespace, agents: Iterable[str]) -> RobotPlugin | None:
    """The plug-in of ``--robot`` with its ``--robot-option`` values; ``None`` without ``--robot``.

    Raises:
        AlicaError: the plug-in cannot be found or loaded, or an option is not ``KEY=VALUE``.
    """
    if not getattr(args, "robot", None):
        if getattr(args, "robot_option", None):
            raise AlicaError("--robot-option goes with --robot (the options are the robot factory's)")
        return None
    names = set(agents)
    common: dict[str, str] = {}
    per_agent: dict[str, dict[str, str]] = {}
    for item in args.robot_option:
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise AlicaError(f"--robot-option: '{item}' is not KEY=VALUE, e.g. pose=1,2,0")
        who, dot, rest = key.partition(".")
        if dot and who in names and rest:
            per_agent.setdefault(who, {})[rest] = value.strip()
        else:
            common[key] = value.strip()
    return RobotPlugin(args.robot, load_factory(args.robot), common, per_agent)


def load_factory(spec: str) -> RobotFactory:
    """The factory ``spec`` names: an entry point of :data:`ENTRY_POINT_GROUP`, ``MODULE:FACTORY`` or ``MODULE``.

    Raises:
        AlicaError: no such plug-in, module or factory, or the module failed while importing.
    """
    import importlib.metadata  # here: reading the installed metadata costs ~25 ms at start-up

    text = spec.strip()
    if not text:
        raise AlicaError("--robot needs a plug-in, e.g. --robot unicycle or --robot my_robot:make_robot")
    installed: Any = importlib.metadata.entry_points(group=ENTRY_POINT_GROUP)
    by_name = {entry.name: entry for entry in installed}
    if ":" not in text and text in by_name:
        entry = by_name[text]
        try:
            target = entry.load()
        except Exception as exc:
            raise AlicaError(f"--robot {text}: the installed plug-in '{entry.value}' cannot be loaded: {exc}") from None
        return _callable(target, text)
    module, _, attribute = text.partition(":")
    here = os.getcwd()
    if here not in sys.path and "" not in sys.path:
        sys.path.insert(0, here)
    try:
        imported = importlib.import_module(module)
    except ImportError as exc:
        known = ", ".join(sorted(by_name)) or "none"
        raise AlicaError(
            f"--robot {text}: no installed robot plug-in of that name (installed: {known}) and module '{module}' "
            f"cannot be imported: {exc} (is it on the Python path, or in the current folder?)"
        ) from None
    except Exception as exc:  # the module's own code failed while importing
        raise AlicaError(
            f"--robot {text}: module '{module}' failed while importing: {type(exc).__name__}: {exc}"
        ) from None
    name = attribute or "make_robot"
    target = getattr(imported, name, None)
    if target is None:
        raise AlicaError(f"--robot {text}: module '{module}' has no '{name}'; name the factory as MODULE:FACTORY")
    return _callable(target, text)


def _callable(target: object, label: str) -> RobotFactory:
    if not callable(target):
        raise AlicaError(f"--robot {label}: {target!r} is not callable; a factory is factory(name, role, options)")
    factory: RobotFactory = target
    return factory


def close_world(world: object) -> None:
    """Call the world's ``close()`` if it has one."""
    close = getattr(world, "close", None)
    if callable(close):
        close()


class _Powered:
    """A plug-in's robot as a fault sees it: its own ``crash``/``recover``, or a stop."""

    def __init__(self, robot: MobileRobot) -> None:
        self.robot = robot

    def crash(self) -> None:
        crash = getattr(self.robot, "crash", None)
        crash() if callable(crash) else self.robot.stop()

    def recover(self) -> None:
        recover = getattr(self.robot, "recover", None)
        if callable(recover):
            recover()


class PluggedRobots:
    """The robots of a simulated team run (``alica run --robot``): one plug-in world per agent, stepped together.

    It is the team's :class:`~alica.engine.sim_world.SimWorld`: one clock, every world stepped by the same
    period; each agent's skills get their own world (:attr:`worlds`).

    Raises:
        AlicaError: a world is not simulated (hardware runs with ``alica agent``, one process per robot).
    """

    def __init__(self, plugin: RobotPlugin, roles: Mapping[str, str]) -> None:
        self.worlds: dict[str, RobotWorld] = {}
        self.clock = ManualClock()
        try:
            for name, role in sorted(roles.items()):
                world = self.worlds[name] = plugin.make(name, role)
                if not is_simulated(world):
                    raise AlicaError(
                        f"--robot {plugin.label}: robot '{name}' runs on the wall clock (its world has no "
                        "step(seconds)); a simulated team needs simulated robots: run hardware with alica agent, "
                        "one process per robot"
                    )
        except BaseException:
            self.close()
            raise
        self._robots = {name: _Powered(world.robots[name]) for name, world in self.worlds.items()}

    @property
    def robots(self) -> Mapping[str, _Powered]:
        return self._robots

    def step(self, seconds: float) -> None:
        for world in self.worlds.values():
            step: Any = getattr(world, "step")  # noqa: B009  # checked by is_simulated
            step(seconds)
        self.clock.advance(seconds)

    def close(self) -> None:
        for world in self.worlds.values():
            close_world(world)


class WallPaced:
    """A hardware robot's world as :func:`alica.skills.testing.run_skill` wants one: ``step`` waits on the wall clock.

    ``alica skill run --robot`` with a driver that has no ``step(seconds)``: the skill is ticked in real time.
    """

    def __init__(self, world: RobotWorld, clock: Clock | None = None) -> None:
        self.world = world
        self.clock = clock or SystemClock()
        self._next = time.monotonic()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.world, name)

    @property
    def robots(self) -> Mapping[str, MobileRobot]:
        return self.world.robots

    def now(self) -> float:
        return self.clock.now()

    def step(self, seconds: float) -> None:
        self._next += seconds
        delay = self._next - time.monotonic()
        if delay > 0:
            time.sleep(delay)  # real time: the robot moves on its own meanwhile
        elif delay < -1.0:
            self._next = time.monotonic()  # far behind (a slow tick): do not try to catch up

    def close(self) -> None:
        close_world(self.world)


def wall_seconds(last: list[float]) -> float:
    """Wall seconds since the previous call (``last`` holds the previous monotonic time), at most 1 s."""
    now = time.monotonic()
    elapsed = now - last[0]
    last[0] = now
    return min(1.0, max(0.0, elapsed)) if math.isfinite(elapsed) else 0.0
