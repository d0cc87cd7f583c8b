"""Static role assignment: each agent gets one role of the role set.

An agent either declares its role, which must exist and whose required
capabilities the agent must have (if it lists capabilities), or lists only
capabilities, and gets the most specific role it can take: among the roles
whose ``requires`` it covers, the one requiring the most capabilities, ties
going to the role listed first in the role set.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from alica.errors import AlicaError
from alica.model.roles import Role, RoleSet


class RoleError(AlicaError, ValueError):
    """An agent whose role is unknown, or that lacks the capabilities of any (or its) role."""


@dataclass(frozen=True, slots=True)
class AgentSpec:
    """What an agent says about itself.

    Args:
        role: the role it declares, ``None`` to derive one from the capabilities.
        capabilities: what it can do, e.g. ``{"base", "arm", "lidar3d"}``; empty
            means "not given" for an agent with a declared role.
    """

    role: str | None = None
    capabilities: frozenset[str] = frozenset()


def _missing(role: Role, capabilities: frozenset[str]) -> list[str]:
    return sorted(role.requires - capabilities)


def _declared(agent: str, spec: AgentSpec, roleset: RoleSet) -> str:
    role = next((r for r in roleset.roles if r.name == spec.role), None)
    if role is None:
        available = ", ".join(r.name for r in roleset.roles) or "none"
        raise RoleError(
            f"agent '{agent}' declares role '{spec.role}', which role set '{roleset.name}' "
            f"does not define (roles: {available})"
        )
    if spec.capabilities:
        missing = _missing(role, spec.capabilities)
        if missing:
            raise RoleError(
                f"agent '{agent}' declares role '{role.name}' but lacks its required capabilities: {', '.join(missing)}"
            )
    return role.name


def _derived(agent: str, spec: AgentSpec, roleset: RoleSet) -> str:
    best: Role | None = None
    for role in roleset.roles:
        if role.requires <= spec.capabilities and (best is None or len(role.requires) > len(best.requires)):
            best = role
    if best is not None:
        return best.name
    have = ", ".join(sorted(spec.capabilities)) or "none"
    width = max((len(r.name) for r in roleset.roles), default=0)
    rows = "\n".join(
        f"  {r.name + ':':<{width + 1}} missing {', '.join(_missing(r, spec.capabilities))}" for r in roleset.roles
    )
    raise RoleError(
        f"agent '{agent}' fits no role of role set '{roleset.name}' (capabilities: {have}):\n"
        + (rows or "  the role set has no roles")
    )


def assign_roles(agents: Mapping[str, AgentSpec], roleset: RoleSet) -> dict[str, str]:
    """The role of every agent.

    Args:
        agents: agent name -> what it declares.
        roleset: the team's roles.

    Returns:
        Agent name -> role name, in agent order.

    Raises:
        RoleError: a declared role is unknown or its required capabilities are
            missing; an agent without a declared role fits no role.
    """
    roles: dict[str, str] = {}
    for agent in sorted(agents):
        spec = agents[agent]
        roles[agent] = _declared(agent, spec, roleset) if spec.role is not None else _derived(agent, spec, roleset)
    return roles
