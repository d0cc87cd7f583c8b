"""Issue 37, finding 3: with credentials, agents apply only operator's commands signed by the team's center.

Before: any JSON put on ``{prefix}/center/operator`` was applied by every agent. Now a command must carry
the center's fresh signature; a teammate (authenticated, but not the center) cannot forge nor replay one.
The center reaches the second agent through the first (a zenoh client session), as ``alica center --team`` does.
"""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest
import zenoh

from alica.comm.center_feed import OPERATOR, CenterFeed, CenterLink
from alica.comm.credentials import CENTER, TeamKeys, make_keys, tls_endpoint
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints
from tests.comm.test_zenoh import wait_for

PREFIX = "sec"


@pytest.fixture
def team(tmp_path) -> Iterator[tuple[dict[str, TeamKeys], list[ZenohTransport], list[CenterFeed], CenterLink]]:
    make_keys(tmp_path / "keys", ["a", "b"])
    keys = {name: TeamKeys.load(tmp_path / "keys", name) for name in ("a", "b", CENTER)}
    ea, eb = (tls_endpoint(e) for e in free_endpoints(2))
    a = ZenohTransport("a", listen=[ea], team=PREFIX, config=keys["a"].zenoh_settings(PREFIX), roster=["a", "b"])
    b = ZenohTransport(
        "b", listen=[eb], connect=[ea], team=PREFIX, config=keys["b"].zenoh_settings(PREFIX), roster=["a", "b"]
    )
    feeds = [CenterFeed(t, {}, 0.0, keys=keys[t.agent_id]) for t in (a, b)]
    histories: list[str] = []
    link = CenterLink(
        [ea],
        PREFIX,
        lambda answer: histories.append(answer["agent"]),
        lambda *_: None,
        config=keys[CENTER].zenoh_settings(PREFIX),
        keys=keys[CENTER],
    )
    try:
        # the center sees both agents and gets both histories, b's through a (queries and replies pass the ACL)
        assert wait_for(lambda: link.alive == {"a", "b"} and sorted(histories) == ["a", "b"], timeout=10.0)
        yield keys, [a, b], feeds, link
    finally:
        link.close()
        for feed in feeds:
            feed.close()
        b.close()
        a.close()


def _commands(feed: CenterFeed, count: int) -> list[dict]:
    got: list[dict] = []
    wait_for(lambda: bool(got.extend(feed.commands()) or len(got) >= count), timeout=5.0)
    return got


def test_the_centers_signed_command_reaches_every_agent_once(team):
    _, _, feeds, link = team
    link.send({"what": "goal", "problem": "p", "goal": "g"})
    for feed in feeds:  # b gets it through a
        assert _commands(feed, 1) == [{"what": "goal", "problem": "p", "goal": "g"}]
        assert feed.refused == 0


def test_a_teammate_cannot_forge_nor_replay_the_centers_commands(team):
    keys, (_, b), feeds, link = team
    heard: list[zenoh.Sample] = []
    spy = b.session.declare_subscriber(f"{PREFIX}/{OPERATOR}", heard.append)
    try:
        link.send({"what": "goal", "problem": "p", "goal": "real"})
        assert wait_for(lambda: bool(heard))
        assert _commands(feeds[0], 1) == [{"what": "goal", "problem": "p", "goal": "real"}]
        signed = heard[0]
        attachment = signed.attachment.to_bytes() if signed.attachment is not None else b""
        b.session.put(f"{PREFIX}/{OPERATOR}", json.dumps({"what": "goal", "problem": "p", "goal": "unsigned"}))
        _, at, _ = attachment.decode().split(" ")
        forged = json.dumps({"what": "goal", "problem": "p", "goal": "forged"}).encode()
        own = keys["b"].sign(forged)  # b's key, the center's name
        b.session.put(f"{PREFIX}/{OPERATOR}", forged, attachment=f"{CENTER} {at} {own.hex()}")
        b.session.put(f"{PREFIX}/{OPERATOR}", signed.payload.to_bytes(), attachment=attachment)  # a replay
        b.session.put(f"{PREFIX}/{OPERATOR}", b"{" * 100_000, attachment=attachment)  # not even JSON
        assert wait_for(lambda: feeds[0].refused >= 4)
        assert feeds[0].commands() == []
    finally:
        spy.undeclare()


def test_without_credentials_commands_are_taken_unsigned_as_before():
    [endpoint] = free_endpoints(1)
    with ZenohTransport("a", listen=[endpoint], team="plain") as a:
        feed = CenterFeed(a, {}, 0.0)
        link = CenterLink([endpoint], "plain", lambda _: None, lambda *_: None)
        try:
            assert wait_for(lambda: link.alive == {"a"})
            link.send({"what": "facts", "facts": []})
            assert _commands(feed, 1) == [{"what": "facts", "facts": []}]
        finally:
            link.close()
            feed.close()
