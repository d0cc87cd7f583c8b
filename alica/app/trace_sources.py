"""The skill modules and plan folders of a run: recorded in its trace header, used again by a viewer.

A run that loads its own skills (``--skills MODULE``) or reaches plan folders of
``ALICA_PLAN_PATH`` can only be shown by a viewer that loads the same: the plan
files validate against the skills they use, and their imports must lie in a
folder the loader may read. So the run records both in its trace header
(``skills``: its ``--skills`` modules; ``plan_path``: :func:`plan_path_names`), and the control center reads
them back (:func:`viewer_sources`) to load the plans of a replay or of a team of
processes, adding the modules given to it with ``--skills``.

A header is data from a file, so it is checked before use: a field that is not a
list of strings is left out with a note, a module that does not load or a folder
that is not there becomes a note, never an exception. Only the viewer's own
``--skills`` modules are errors.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from alica.io import Loader, plans_dir
from alica.io.loader import PLAN_PATH_VARIABLE, default_search_path
from alica.lang.skills import SkillRegistry

SHIPPED_PLANS = "alica:plans"
"""How a header's ``plan_path`` names the plans shipped with alica (found wherever alica is installed)."""


def _shipped() -> Path | None:
    try:
        return plans_dir().resolve()
    except FileNotFoundError:
        return None


def plan_path_names(extra: Iterable[str | os.PathLike[str]] = ()) -> list[str]:
    """The plan folders this run's imports may reach, as its header records them.

    ``extra`` (a loader's own ``search_path``) first, then
    :func:`alica.io.loader.default_search_path` (the shipped plans and ``ALICA_PLAN_PATH``);
    the shipped plans as ``alica:plans``, any other folder as an absolute path, each once.
    """
    shipped = _shipped()
    names: list[str] = []
    for folder in [*extra, *default_search_path()]:
        text = os.fspath(folder)
        if text.startswith("alica:"):
            name = SHIPPED_PLANS if text.rstrip("/") == SHIPPED_PLANS else text
        else:
            path = Path(text).resolve()
            name = SHIPPED_PLANS if shipped is not None and path == shipped else str(path)
        if name not in names:
            names.append(name)
    return names


@dataclass
class ViewerSources:
    """What a viewer loads a run's plans with.

    Attributes:
        registry: the installed plug-ins, the viewer's ``--skills`` and the header's modules that loaded.
        search_path: the header's plan folders that are there (the default search path is always added
            by :class:`~alica.io.Loader` itself).
        notes: what could not be used, one sentence each, for the page and the terminal.
    """

    registry: SkillRegistry
    search_path: list[Path] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def loader(self) -> Loader:
        """A new loader with these skills and folders (one per plan file: each file's set is its own)."""
        return Loader(skills=self.registry.copy(), search_path=list(self.search_path))


def _names(header: Mapping[str, Any], key: str, what: str, notes: list[str]) -> list[str]:
    value = header.get(key)
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        notes.append(f"the trace header's {key} is not a list of {what}: it is left out")
        return []
    return [v.strip() for v in value if v.strip()]


def viewer_sources(
    header: Mapping[str, Any],
    given: Sequence[str] = (),
    *,
    base: str | os.PathLike[str] | None = None,
    header_skills: bool = True,
) -> ViewerSources:
    """The skills and plan folders to load a recorded run's plans with.

    Args:
        header: the trace header's fields (``skills``, ``plan_path``; both optional).
        given: the viewer's own ``--skills`` modules: they load first and must load.
        base: the trace's folder: a relative plan folder is looked for from the current folder, then there.
        header_skills: import the header's modules too (``False``: only ``given``).

    Raises:
        SkillPluginError: a module of ``given`` cannot be loaded (the message names it).
    """
    from alica.app.skill_options import skill_registry
    from alica.lang.skill_plugins import SkillPluginError, load_skill_module

    notes: list[str] = []
    registry = skill_registry(argparse.Namespace(skills=list(given)))
    recorded = _names(header, "skills", "module names", notes)
    wanted = [m for m in dict.fromkeys(recorded) if m not in given]
    if wanted and not header_skills:
        notes.append(f"the run's skill modules {', '.join(wanted)} are not loaded (--no-trace-skills)")
        wanted = []
    if wanted:
        here = os.getcwd()
        if here not in sys.path and "" not in sys.path:
            sys.path.insert(0, here)  # as --skills: modules of the folder the center runs in
    for module in wanted:
        try:
            load_skill_module(registry, module)
        except SkillPluginError as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            notes.append(
                f"skill module {module} (recorded in the trace header) does not load: {first} "
                "(fix: run alica center from the folder the run started in, or pass --skills with where it is now)"
            )
    folders: list[Path] = []
    for name in dict.fromkeys(_names(header, "plan_path", "folders", notes)):
        if name.startswith("alica:"):
            continue  # the shipped plans: always on the search path
        path = Path(name)
        candidates = [path] if path.is_absolute() or base is None else [path, Path(base) / path]
        found = next((c for c in candidates if c.is_dir()), None)
        if found is None:
            notes.append(
                f"plan folder {name} (recorded in the trace header's plan_path) is not there: imports from it "
                f"will not load (fix: add where it is now to {PLAN_PATH_VARIABLE})"
            )
            continue
        folders.append(found.resolve())
    return ViewerSources(registry, folders, notes)
