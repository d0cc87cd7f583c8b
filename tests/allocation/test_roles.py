"""Static role assignment: declared roles, derived roles, and the errors."""

from __future__ import annotations

import pytest

from alica.allocation import AgentSpec, RoleError, assign_roles
from alica.errors import AlicaError
from alica.model import Role, RoleSet

ROLESET = RoleSet(
    "Team",
    (
        Role("Walker", requires=frozenset({"legs"})),
        Role("Grabber", requires=frozenset({"legs", "arm"})),
        Role("Looker", requires=frozenset({"legs", "eye"})),
        Role("Anyone"),
    ),
)


def test_declared_role_is_kept() -> None:
    assert assign_roles({"x": AgentSpec(role="Grabber")}, ROLESET) == {"x": "Grabber"}
    assert assign_roles({"x": AgentSpec("Grabber", frozenset({"legs", "arm", "eye"}))}, ROLESET) == {"x": "Grabber"}


def test_unknown_declared_role_names_agent_role_and_choices() -> None:
    with pytest.raises(RoleError) as error:
        assign_roles({"x": AgentSpec(role="Flyer")}, ROLESET)
    message = str(error.value)
    assert "'x'" in message and "'Flyer'" in message
    assert "Walker, Grabber, Looker, Anyone" in message
    assert isinstance(error.value, AlicaError) and isinstance(error.value, ValueError)


def test_declared_role_needs_its_capabilities() -> None:
    with pytest.raises(RoleError, match="lacks its required capabilities: arm"):
        assign_roles({"x": AgentSpec("Grabber", frozenset({"legs", "eye"}))}, ROLESET)


def test_derived_role_is_the_most_specific() -> None:
    agents = {
        "a": AgentSpec(capabilities=frozenset({"legs", "arm"})),
        "b": AgentSpec(capabilities=frozenset({"legs"})),
        "c": AgentSpec(capabilities=frozenset({"wheels"})),
        "d": AgentSpec(capabilities=frozenset({"legs", "arm", "eye"})),  # tie: Grabber is listed first
    }
    assert assign_roles(agents, ROLESET) == {"a": "Grabber", "b": "Walker", "c": "Anyone", "d": "Grabber"}


def test_no_fitting_role_lists_what_is_missing() -> None:
    roleset = RoleSet("Team", tuple(r for r in ROLESET.roles if r.requires))
    with pytest.raises(RoleError) as error:
        assign_roles({"x": AgentSpec(capabilities=frozenset({"wheels"}))}, roleset)
    assert str(error.value) == (
        "agent 'x' fits no role of role set 'Team' (capabilities: wheels):\n"
        "  Walker:  missing legs\n"
        "  Grabber: missing arm, legs\n"
        "  Looker:  missing eye, legs"
    )


def test_result_is_in_agent_order() -> None:
    agents = {name: AgentSpec(role="Walker") for name in ("z", "a", "m")}
    assert list(assign_roles(agents, ROLESET)) == ["a", "m", "z"]
