"""Issue 37: a team of processes with credentials runs its mission over TLS, and a rogue without them cannot connect.

Before: anyone who reached one agent's listen port read all team traffic and spoke for any agent. Now
(``--team-keys``) every link is TLS with mutual authentication: a session without the team's keys, or
with keys of another team, gets no link, so nothing it sends reaches an agent.
"""

from __future__ import annotations

import threading

import zenoh

from alica.app.processes import ProcessTeam
from alica.comm.codec import encode
from alica.comm.credentials import TeamKeys, make_keys
from alica.comm.zenoh_transport import zenoh_config
from alica.engine.team import WORLD_TOPIC
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")
NAMES = ["scout", "stummel", "amparo"]


def _rogues(endpoint: str, other_team: TeamKeys) -> list[zenoh.Session]:
    plain = zenoh.open(zenoh_config((endpoint.replace("tls/", "tcp/"),), (), "peer", 2.0, None))
    foreign = zenoh.open(zenoh_config((endpoint,), (), "peer", 2.0, other_team.zenoh_settings("alica")))
    return [plain, foreign]


def test_a_team_with_credentials_succeeds_and_a_rogue_without_them_gets_no_link(tmp_path):
    make_keys(tmp_path / "keys", NAMES)
    make_keys(tmp_path / "other", NAMES)  # the same names, another team's CA
    team = ProcessTeam(
        LUNAR,
        ",".join(NAMES),
        NAMES,
        ["--stand-ins", "--time-limit", "60", "--team-keys", str(tmp_path / "keys")],
        tmp_path,
        own={"scout": ["--fact", "found(a) and found(b)@3"]},
        deadline=60,
        tls=True,
    )
    rogues: list[zenoh.Session] = []
    linked: list[int] = []
    try:
        team.launch()
        started = threading.Event()

        def attack(count: int, at: float) -> None:
            endpoint = team.agents["scout"].listen
            assert endpoint.startswith("tls/")
            rogues.extend(_rogues(endpoint, TeamKeys.load(tmp_path / "other", "stummel")))
            forged = encode((1, "stummel", WORLD_TOPIC, 1, 0, 0, 0.0, encode("forged")))
            for rogue in rogues:
                rogue.put(f"alica/m/stummel/{WORLD_TOPIC}", forged)
                rogue.put("alica/center/operator", b'{"what": "goal", "problem": "p", "goal": "g"}')
            started.set()

        team.run([], 60, on_started=attack)
        assert started.is_set()
        linked.extend(len(list(rogue.info.peers_zid())) for rogue in rogues)
    finally:
        for rogue in rogues:
            rogue.close()
        team.stop()
    summary = team.summary("LunarMission", 0)
    assert summary["success"], summary
    assert summary["world_models_agree"]
    assert linked == [0, 0]
    for agent in summary["agents"].values():
        assert {"found(a)", "found(b)"} <= set(agent["world_facts"])
