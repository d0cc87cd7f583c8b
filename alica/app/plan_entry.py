"""The plan a command runs: its library and entry file, its root plans, and the agents' roles.

Shared by ``alica run``, ``alica agent``, ``alica solve``, ``alica show``, ``alica render`` and the
control center, so none of them imports another command's module.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from alica.app.options import did_you_mean
from alica.errors import AlicaError

if TYPE_CHECKING:
    from alica.allocation import AgentSpec
    from alica.io import Loader
    from alica.model import AbstractPlan, Document, PlanLibrary

#: Exit codes of every command: valid or done, invalid input or a failed run, a usage error.
EXIT_OK, EXIT_INVALID, EXIT_USAGE = 0, 1, 2


def load_entry(path: str | Path, loader: Loader | None = None) -> tuple[PlanLibrary, Document]:
    """The library of a plan file's set and the file's own document, each file read once."""
    from alica.io import Loader

    loader = loader or Loader()
    return loader.load(path), loader.document(path)


def root_plans(library: PlanLibrary, entry: Document, name: str | None) -> list[str]:
    """The plans to start from: ``name`` if given, else the entry file's plans (and problems) no other uses."""
    if name is not None:
        library.abstract(name)
        return [name]
    own = (
        [p.name for p in entry.plans]
        + [p.name for p in entry.problems]
        + [b.name for b in entry.behaviours if not entry.plans]
    )
    parents: list[AbstractPlan] = [*entry.plans, *entry.plantypes, *entry.problems]
    used = {c for e in parents for c in library.children(e)}
    roots = [n for n in own if n not in used]
    return roots or own


def agent_roles(
    library: PlanLibrary,
    agents: dict[str, str | frozenset[str] | None],
    roleset: str | None,
    options: dict[str, str] | None = None,
) -> dict[str, str | AgentSpec]:
    """Each agent's role (or capabilities); ``options`` names the option that gave an agent its role (``--agents``).

    Raises:
        AlicaError: a role no role set has (with the closest role's name), or no role set holding them all.
    """
    from alica.allocation import AgentSpec
    from alica.engine import pick_roleset

    sets = [library.rolesets[roleset]] if roleset in library.rolesets else list(library.rolesets.values())
    known = sorted({r.name for rs in sets for r in rs.roles})
    names = {r.name.lower(): r.name for rs in library.rolesets.values() for r in rs.roles}
    out: dict[str, str | AgentSpec] = {}
    for name, role in agents.items():
        option = (options or {}).get(name, "--agents")
        if isinstance(role, frozenset):
            out[name] = AgentSpec(capabilities=role)
            continue
        if role is None:
            if name.lower() not in names:
                raise AlicaError(
                    f"{option}: agent '{name}' has no role and no role is called like it{did_you_mean(name, known)}; "
                    f"write {name}:ROLE (roles: {', '.join(known) or 'none'})"
                )
            role = names[name.lower()]
        elif role not in known:
            where = f"role set '{roleset}' does not have" if roleset in library.rolesets else "no role set has"
            raise AlicaError(
                f"{option}: agent '{name}' has role '{role}', which {where}{did_you_mean(role, known)}; "
                f"roles: {', '.join(known) or 'none'}"
            )
        out[name] = role
    pick_roleset(library, [r for r in out.values() if isinstance(r, str)], roleset)
    return out
