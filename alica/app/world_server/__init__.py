"""A world server for robots in other processes, and the remote robot an agent drives through it.

``alica world serve --world lunar|blocks --listen tcp/127.0.0.1:7447`` runs one
pybullet world and serves each robot over zenoh (:mod:`.server`); an agent in
another process opens the world with :class:`RemoteWorld` (:mod:`.client`) and
hands it to its skills, which cannot tell it from a local
:class:`~alica.worldsim.world.World`. The message format and its checks are in
:mod:`.wire`; the robots, arms and objects of a remote world in :mod:`.remote`.

The client's public API::

    from alica.app.world_server import RemoteWorld

    world = RemoteWorld(["tcp/127.0.0.1:7447"], "scout", prefix="alica")  # waits up to 5 s for the server
    try:
        robot = world.robots["scout"]      # only the agent's own robot takes its commands
        robot.drive(0.3, 0.0)
        scan = robot.lidar(360)
        clock = world.clock                # an alica.clock.Clock reading the server's simulated time
        if world.lockstep:
            world.tick_done()              # after each engine tick: returns once the server stepped
    finally:
        world.close()                      # the agent's liveliness token goes: its robot crashes in the world

* ``RemoteWorld(connect, name, *, prefix="alica", listen=(), mode="peer",
  settings=None, timeout=2.0, step_timeout=10.0, wait=5.0)``: ``settings`` are
  extra zenoh settings (the team's credentials), ``timeout`` bounds each call,
  ``step_timeout`` each :meth:`~RemoteWorld.tick_done`, ``wait`` the opening.
* ``world.clock`` (``now()``), ``world.lockstep``, ``world.period``,
  ``world.tick_done(timeout=None) -> float`` (the new simulated time), ``world.close()``;
  usable as a context manager.
* With the team's credentials, pass ``settings=world_settings(TeamKeys.load(DIR, NAME), prefix)``
  (:func:`alica.app.world_server.access.world_settings`) and ``tls/`` endpoints; the server runs
  as the member ``world`` (``alica world serve --team-keys DIR``).
* **Exceptions**: every call and read raises
  :class:`~alica.worldsim.errors.WorldError` with the reason: no server when
  opening ("no world server at ... answered within 5 s"), a server that is gone
  or does not answer in time ("the world server at ... does not answer ..."), a
  call the server refused (someone else's robot, bad arguments), a malformed
  reply. The session reconnects by itself: once a server answers again, calls
  work again.
"""

from __future__ import annotations

from alica.app.world_server.access import world_settings
from alica.app.world_server.client import RemoteClock, RemoteWorld
from alica.app.world_server.remote import RemoteArm, RemoteRobot, RemoteThing
from alica.app.world_server.server import ServerStats, WorldServer

__all__ = [
    "RemoteArm",
    "RemoteClock",
    "RemoteRobot",
    "RemoteThing",
    "RemoteWorld",
    "ServerStats",
    "WorldServer",
    "world_settings",
]
