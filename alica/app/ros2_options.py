"""The ROS 2 options of ``alica run``, ``alica agent``, ``alica world serve`` and the demos.

``--ros2`` puts the agents (and the world) in a ROS 2 graph over rmw_zenoh's wire
format; ``--record DIR`` writes the same topics to a rosbag2 folder. See
:mod:`alica.app.ros2_bridge` for the topics and docs/ros2.md for how to use them.
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.app.ros2_output import Ros2Output

#: ROS 2 distributions whose message definitions and key form the library knows.
DISTROS = ("humble", "jazzy")
#: rmw_zenohd's own endpoint on every host: the router an outside process joins as a client.
ROUTER = "tcp/127.0.0.1:7447"
#: The largest ROS 2 domain id (DDS's limit, which rmw_zenoh keeps).
MAX_DOMAIN = 232


def add_ros2_options(parser: Any, *, live: bool = True, record: bool = True) -> None:
    """Add the ROS 2 options to ``parser``: ``--ros2`` and its settings (``live``), ``--record DIR`` (``record``)."""
    group = parser.add_argument_group("ROS 2 (rmw_zenoh's wire format, no ROS installation needed)")
    if live:
        group.add_argument(
            "--ros2",
            action="store_true",
            help="appear in a ROS 2 graph: poses, /tf, the team map, markers and diagnostics under each robot's "
            "namespace, as rmw_zenoh nodes do (ros2 topic echo, rviz2 and Foxglove see them)",
        )
        group.add_argument(
            "--ros2-router",
            default=ROUTER,
            metavar="ENDPOINT",
            help=f"the host's zenoh router, rmw_zenohd (default {ROUTER}); the process joins it as a client",
        )
    group.add_argument(
        "--ros2-domain", type=int, default=0, metavar="N", help=f"the ROS 2 domain id, 0 to {MAX_DOMAIN} (default 0)"
    )
    group.add_argument(
        "--ros2-distro",
        choices=DISTROS,
        default="jazzy",
        help="the ROS 2 distribution to match: its message definitions and its key form (Humble's keys carry "
        "no type hash) (default jazzy)",
    )
    if record:
        group.add_argument(
            "--record",
            metavar="DIR",
            help="write the same topics to a rosbag2 folder DIR (metadata.yaml and an MCAP file) for ros2 bag play, "
            "Foxglove and rviz2; DIR must not exist or be empty",
        )


def check_ros2(args: argparse.Namespace) -> None:
    """Check the ROS 2 options.

    Raises:
        AlicaError: a domain out of range.
    """
    domain = getattr(args, "ros2_domain", 0)
    if not 0 <= domain <= MAX_DOMAIN:
        raise AlicaError(f"--ros2-domain must be a ROS 2 domain id from 0 to {MAX_DOMAIN}, got {domain}")


@contextlib.contextmanager
def ros2_output(args: argparse.Namespace, *, live: bool = True) -> Iterator[Ros2Output | None]:
    """The run's :class:`~alica.app.ros2_output.Ros2Output` from ``--ros2``/``--record`` (``None``: neither), closed after.

    Raises:
        AlicaError: the bag folder exists and is not empty.
    """
    check_ros2(args)
    if not (getattr(args, "record", None) or (live and getattr(args, "ros2", False))):
        yield None
        return
    from alica.app.ros2_output import Ros2Output

    output = Ros2Output.from_args(args, live=live)
    try:
        yield output
    finally:
        if output is not None:
            output.close()


@dataclass(frozen=True, slots=True)
class Ros2Arguments:
    """What a team of processes passes on to its agents: the live options, and where each records."""

    options: tuple[str, ...]
    """``--ros2 --ros2-router ... --ros2-domain N --ros2-distro D`` (empty without ``--ros2``)."""
    record: Path | None
    """The folder under which each agent records its own rosbag2 folder (``<robot>``, ``<robot>.2`` once
    restarted), or ``None``."""

    def for_agent(self, name: str, incarnation: int) -> list[str]:
        """The options of agent ``name``'s ``incarnation``-th process."""
        own = list(self.options)
        if self.record is not None:
            folder = self.record / (name if incarnation <= 1 else f"{name}.{incarnation}")
            own += ["--record", str(folder)]
        return own


def ros2_arguments(args: argparse.Namespace) -> Ros2Arguments | None:
    """The ROS 2 options a team of processes gives its agents (``None``: neither ``--ros2`` nor ``--record``).

    Raises:
        AlicaError: a domain out of range, or a recording folder that exists and is not empty.
    """
    check_ros2(args)
    record = getattr(args, "record", None)
    live = bool(getattr(args, "ros2", False))
    if record is None and not live:
        return None
    options: tuple[str, ...] = ()
    if live:
        options = ("--ros2", "--ros2-router", args.ros2_router)
    options += ("--ros2-domain", str(args.ros2_domain), "--ros2-distro", args.ros2_distro)
    folder = Path(record) if record is not None else None
    if folder is not None:
        from alica.comm.ros2.bag import check_bag_folder

        check_bag_folder(folder)
        folder.mkdir(parents=True, exist_ok=True)
    return Ros2Arguments(options, folder)
