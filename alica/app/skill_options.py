"""The ``--skills MODULE`` option of the commands that read skill declarations."""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from alica.lang.skills import SkillRegistry

#: Origin of the shipped catalogue's declarations (its entry point's module).
SHIPPED = "alica.skills.catalog"


def add_skills_option(parser: Any) -> None:
    """Add the repeatable ``--skills MODULE`` option to a subcommand's parser."""
    parser.add_argument(
        "--skills",
        action="append",
        default=[],
        metavar="MODULE",
        help="load skill declarations from this module's register(registry), importable from the current folder "
        "(repeatable; installed packages' plug-ins of the entry-point group alica.skills are always loaded)",
    )


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
