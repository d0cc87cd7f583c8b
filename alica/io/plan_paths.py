"""Where plan files are: the shipped plans by name, the plan search path, a file's project.

Three rules a user can predict, none of which depends on the working folder:

- ``alica:plans/<path>`` names a plan file shipped with alica (the package data
  ``alica.plans``), from any folder, on the command line, in ``imports`` and in
  ``ALICA_PLAN_PATH``; ``alica:plans`` is the whole folder.
- An import may reach the entry file's folder tree, its *project* (the nearest
  folder above the entry file holding ``.alica-project``, ``pyproject.toml``,
  ``.git`` or ``.hg``), the folders of ``ALICA_PLAN_PATH`` and the shipped plans; nothing else
  is read (:class:`alica.io.Loader`).
- A written plan file names what it imports relative to where it is written, and
  a shipped plan as ``alica:plans/<path>`` (:func:`import_reference`), so the
  file stays valid when its folder moves.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path, PurePosixPath

from alica.errors import AlicaError

#: How a path names the plans shipped with alica: ``alica:plans/lunar/mission.yaml``.
SHIPPED = "alica:plans"

#: Environment variable with more plan folders imports may reach (separated by ``os.pathsep``).
PLAN_PATH_VARIABLE = "ALICA_PLAN_PATH"

#: Files or folders that mark a project's root folder (its plans may import each other).
PROJECT_MARKERS = (".alica-project", "pyproject.toml", ".git", ".hg")

#: The marker file a folder of plans gets to make it a project of its own.
PROJECT_MARKER = PROJECT_MARKERS[0]


def plans_dir() -> Path:
    """The shipped plans: the package data ``alica.plans`` (the checkout's ``plans/`` in an editable install).

    Raises:
        FileNotFoundError: the package was installed without its plans.
    """
    spec = importlib.util.find_spec("alica.plans")
    locations = list(spec.submodule_search_locations or ()) if spec is not None else []
    for location in locations:
        folder = Path(location)
        if (folder / "roles.yaml").is_file():
            return folder.resolve()
    raise FileNotFoundError(
        f"the shipped plans are missing from the installed package (looked in {locations or 'alica.plans'}); reinstall alica-teams"
    )


class PlanPathError(AlicaError, ValueError):
    """A plan path that names nothing: an ``alica:`` path outside the shipped plans."""


def is_shipped_name(text: str) -> bool:
    """Whether ``text`` is in the ``alica:`` form (it may still be a bad one)."""
    return text.startswith("alica:")


def plan_path(raw: str | os.PathLike[str]) -> Path:
    """A plan path as given (a file, a folder, or ``alica:plans/...``) as a file system path.

    Raises:
        PlanPathError: an ``alica:`` path that is not under ``alica:plans``, climbs out of
            it with ``..``, or the shipped plans are not installed.
    """
    text = os.fspath(raw)
    if not is_shipped_name(text):
        return Path(text)
    parts = PurePosixPath(text[len("alica:") :].replace("\\", "/")).parts
    if not parts or parts[0] != "plans" or ".." in parts or PurePosixPath(*parts).is_absolute():
        raise PlanPathError(
            f"'{text}' names no shipped plan: write alica:plans/<path>, e.g. alica:plans/lunar/mission.yaml"
        )
    try:
        return plans_dir().joinpath(*parts[1:])
    except FileNotFoundError as exc:
        raise PlanPathError(str(exc)) from None


def import_target(importer: str | os.PathLike[str], name: str) -> Path:
    """The file an import names, not resolved: a shipped plan by name, anything else relative
    to the importing file (``importer``, itself possibly ``alica:plans/...``).

    Raises:
        PlanPathError: a bad ``alica:`` name.
    """
    return plan_path(name) if is_shipped_name(name) else plan_path(importer).parent / name


def shipped_name(path: Path) -> str | None:
    """``alica:plans/<path>`` for a file or folder of the shipped plans, else ``None``."""
    try:
        root = plans_dir()
    except FileNotFoundError:
        return None
    resolved = path.resolve()
    if not resolved.is_relative_to(root):
        return None
    rest = resolved.relative_to(root).as_posix()
    return SHIPPED if rest == "." else f"{SHIPPED}/{rest}"


def shown(path: Path) -> str:
    """A path as messages show it: relative to the working folder when inside it, a shipped
    plan as ``alica:plans/...``, anything else as it is."""
    here = Path.cwd().resolve()
    resolved = path.resolve()
    if resolved.is_relative_to(here):
        return os.path.relpath(resolved, here)
    return shipped_name(resolved) or str(path)


def import_reference(target: str | os.PathLike[str], folder: Path) -> str:
    """How a plan file written into ``folder`` names ``target`` in its ``imports``.

    A shipped plan as ``alica:plans/...`` (unless ``folder`` lies among the shipped plans
    too), anything else relative to ``folder``: the file stays valid wherever its folder
    and the files beside it are moved, and wherever alica is installed.
    """
    target_path = plan_path(target).resolve()
    where = folder.resolve()
    name = shipped_name(target_path)
    if name is not None and shipped_name(where) is None:
        return name
    try:
        return Path(os.path.relpath(target_path, where)).as_posix()
    except ValueError:  # another drive: no relative path exists
        return target_path.as_posix()


def project_root(entry: Path) -> Path | None:
    """The nearest folder above ``entry`` that holds a project marker (:data:`PROJECT_MARKERS`).

    Never the file system's root or the home folder itself: a marker there does not make
    every file below it a plan of one project.
    """
    stops = {Path(entry.anchor), Path.home().resolve()}
    for folder in entry.resolve().parents:
        if folder in stops:
            return None
        if any((folder / marker).exists() for marker in PROJECT_MARKERS):
            return folder
    return None


def default_search_path() -> list[Path]:
    """The plan folders every import may reach: the shipped plans and ``ALICA_PLAN_PATH``.

    Entries of ``ALICA_PLAN_PATH`` may use the ``alica:plans`` form.

    Raises:
        PlanPathError: an entry of ``ALICA_PLAN_PATH`` names no shipped plan.
    """
    folders: list[Path] = []
    try:
        folders.append(plans_dir())
    except FileNotFoundError:
        pass
    for entry in _plan_path_entries(os.environ.get(PLAN_PATH_VARIABLE, "")):
        if entry.strip():
            try:
                folders.append(plan_path(entry.strip()))
            except PlanPathError as exc:
                raise PlanPathError(f"{PLAN_PATH_VARIABLE}: {exc}") from None
    return folders


def _plan_path_entries(value: str) -> list[str]:
    """The entries of ``ALICA_PLAN_PATH``: split at ``os.pathsep``, where ``alica:plans/...``
    stays one entry although ``:`` is the separator on POSIX."""
    pieces = value.split(os.pathsep)
    entries: list[str] = []
    while pieces:
        piece = pieces.pop(0)
        if os.pathsep == ":" and piece.strip() == "alica" and pieces:
            piece = f"alica:{pieces.pop(0)}"
        entries.append(piece)
    return entries
