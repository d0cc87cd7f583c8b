"""Options shared by the commands that run skills: ``--skills MODULE`` and the lunar field's size and contents."""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING

from alica.app.options import add_field_options

if TYPE_CHECKING:
    from alica.lang.skills import SkillRegistry
    from alica.worldsim.world import World

#: Origin of the shipped catalogue's declarations (its entry point's module).
SHIPPED = "alica.skills.catalog"


def add_skills_option(parser: argparse._ActionsContainer) -> None:
    """Add the repeatable ``--skills MODULE`` option to a subcommand's parser."""
    parser.add_argument(
        "--skills",
        action="append",
        default=[],
        metavar="MODULE",
        help="load skill declarations from this module's register(registry), importable from the current folder "
        "(repeatable; installed packages' plug-ins of the entry-point group alica.skills are always loaded)",
    )


def add_lunar_options(parser: argparse._ActionsContainer) -> None:
    """Add ``--size``, ``--rocks`` and ``--samples``: the lunar field of ``--world lunar`` (shared defaults)."""
    add_field_options(parser)


def lunar_field(args: argparse.Namespace) -> World:
    """The lunar world of ``args`` (seed, rocks, samples, size).

    Raises:
        AlicaError: a count below zero or a field too small (the message says which option).
    """
    from alica.errors import AlicaError
    from alica.worldsim.errors import WorldError
    from alica.worldsim.scenarios import lunar

    for option in ("rocks", "samples"):
        if getattr(args, option) < 0:
            raise AlicaError(f"--{option} must be >= 0, got {getattr(args, option)}")
    try:
        return lunar(seed=args.seed, rocks=args.rocks, samples=args.samples, size=args.size)
    except WorldError as exc:
        raise AlicaError(
            f"--world lunar with --size {args.size:g}, --rocks {args.rocks}, --samples {args.samples}: {exc}"
        ) from None


def skill_registry(args: argparse.Namespace) -> SkillRegistry:
    """The shipped catalogue, the installed plug-ins and the ``--skills`` modules of ``args``.

    The current folder is put on the module search path first, as ``python -m`` does.

    Raises:
        SkillPluginError: a module cannot be loaded (the message names it).
    """
    from alica.lang.skill_plugins import default_registry  # here: the parser is built for every command

    modules = list(getattr(args, "skills", None) or [])
    if modules:
        here = os.getcwd()
        if here not in sys.path and "" not in sys.path:
            sys.path.insert(0, here)
    return default_registry(modules)
