"""The world's keys under the team's credentials: TLS, and an access control that lets each agent reach only its robot.

With the team's credentials (``alica team keys --out DIR AGENT... world``:
the server is the member ``world``), the server's and each
:class:`~alica.app.world_server.RemoteWorld`'s zenoh sessions use the team's
TLS with mutual authentication
(:meth:`~alica.comm.credentials.TeamKeys.zenoh_settings`) and an access
control of the world's keys only (every other message is refused on arrival):

* the **server** takes from member ``m`` only queries on ``P/world/call`` and
  on ``P/world/robot/m/call`` (its own robot), and the liveliness token
  ``P/world/agent/m``: an agent cannot even ask another's robot;
* an **agent** takes only from ``world``: the state on ``P/world/state``, the
  token ``P/world/alive`` and the replies to its calls.

Declarations (subscribers, queryables, liveliness queries) under ``P/world/``
are taken from every member, as zenoh needs them to route. Everything may
leave (the egress is open, as for the team's sessions).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from alica.comm.credentials import ZENOH_MESSAGES

if TYPE_CHECKING:
    from alica.comm.credentials import TeamKeys

__all__ = ["WORLD", "world_settings"]

WORLD = "world"
"""The world server's name in the team's credentials."""

_DECLARATIONS = ("declare_subscriber", "declare_queryable", "declare_liveliness_subscriber", "liveliness_query")


def _rule(rule_id: str, messages: tuple[str, ...], keys: list[str], flow: str = "ingress") -> dict[str, object]:
    return {"id": rule_id, "permission": "allow", "flows": [flow], "messages": list(messages), "key_exprs": keys}


def world_settings(keys: TeamKeys, prefix: str) -> dict[str, object]:
    """zenoh settings of a world session of ``keys``'s holder: the server's when it is :data:`WORLD`, else an agent's.

    Returns:
        zenoh key path -> JSON-able value, for the ``settings`` of
        :class:`~alica.app.world_server.WorldServer` or :class:`~alica.app.world_server.RemoteWorld`
        (their endpoints must be ``tls/``).

    Raises:
        CredentialsError: ``prefix`` is not a key prefix.
    """
    settings = {k: v for k, v in keys.zenoh_settings(prefix).items() if k != "access_control"}
    p = prefix
    agents = sorted(keys.members - {WORLD})
    rules = [
        _rule("declarations", _DECLARATIONS, [f"{p}/world/**"]),
        _rule("egress", ZENOH_MESSAGES, ["**"], flow="egress"),
    ]
    subjects: list[dict[str, object]] = [
        {"id": "everyone"},
        {"id": "team", "cert_common_names": sorted(keys.members)},
    ]
    policies: list[dict[str, object]] = [
        {"id": "egress", "rules": ["egress"], "subjects": ["everyone"]},
        {"id": "declarations", "rules": ["declarations"], "subjects": ["team"]},
    ]
    if keys.name == WORLD:
        for i, m in enumerate(agents):  # (ids by number: a name need not suit zenoh's ids)
            own = [f"calls-{i}", f"token-{i}"]
            rules += [
                _rule(own[0], ("query",), [f"{p}/world/call", f"{p}/world/robot/{m}/call"]),
                _rule(own[1], ("liveliness_token",), [f"{p}/world/agent/{m}"]),
            ]
            subjects.append({"id": f"agent-{i}", "cert_common_names": [m]})
            policies.append({"id": f"agent-{i}", "rules": own, "subjects": [f"agent-{i}"]})
    else:
        rules += [
            _rule("state", ("put",), [f"{p}/world/state"]),
            _rule("alive", ("liveliness_token",), [f"{p}/world/alive"]),
            _rule("replies", ("reply",), [f"{p}/world/call", f"{p}/world/robot/{keys.name}/call"]),
        ]
        subjects.append({"id": "server", "cert_common_names": [WORLD]})
        policies.append({"id": "server", "rules": ["state", "alive", "replies"], "subjects": ["server"]})
    settings["access_control"] = {
        "enabled": True,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    }
    return settings
