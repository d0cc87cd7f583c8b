"""Issue 37: with the team's credentials, zenoh's mTLS keeps strangers out and its access control keeps members honest.

Real zenoh sessions on free loopback ports, opened as the team's processes open them
(:func:`alica.comm.zenoh_transport.zenoh_config` with :meth:`TeamKeys.zenoh_settings`). A forbidden message
is sent just before an allowed one on the same link, and the test waits for the allowed one: links keep
their order, so by then the forbidden one would have arrived too, had zenoh let it through.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import zenoh

from alica.comm.credentials import CENTER, TeamKeys, make_keys, tls_endpoint
from alica.comm.transport import QoS
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints, zenoh_config
from tests.comm.test_zenoh import drain, wait_for

P = "acl"
WAIT = 15.0
"""The most any test waits for something to arrive or a link to come up, in seconds."""


@pytest.fixture(scope="module")
def team(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("tls") / "keys"
    make_keys(folder, ["a", "b"])
    return folder


@pytest.fixture(scope="module")
def stranger(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Another team's credentials, with the same names: a certificate of the wrong CA."""
    folder = tmp_path_factory.mktemp("tls") / "other"
    make_keys(folder, ["a", "b"])
    return folder


@pytest.fixture
def sessions() -> Iterator[Callable[..., zenoh.Session]]:
    """Open zenoh sessions (closed at the end): ``open(keys, listen=..., connect=..., mode=...)``."""
    with contextlib.ExitStack() as stack:

        def open_session(
            keys: TeamKeys | None, *, listen: tuple[str, ...] = (), connect: tuple[str, ...] = (), mode: str = "peer"
        ) -> zenoh.Session:
            extra = keys.zenoh_settings(P) if keys is not None else {}
            session = zenoh.open(zenoh_config(connect, listen, mode, 2.0, extra))
            stack.callback(session.close)
            return session

        yield open_session


class Seen:
    """The keys of the samples a subscriber got; :attr:`arrived` is set when ``marker`` comes."""

    def __init__(self, marker: str) -> None:
        self.marker = marker
        self.keys: list[str] = []
        self.arrived = threading.Event()
        self._lock = threading.Lock()

    def __call__(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        with self._lock:
            self.keys.append(key)
        if key == self.marker:
            self.arrived.set()

    def snapshot(self) -> list[str]:
        with self._lock:
            return list(self.keys)


def _linked(*sessions: zenoh.Session, count: int = 1) -> bool:
    """Wait (at most :data:`WAIT`) until each session has ``count`` peers or routers."""
    return wait_for(
        lambda: all(len(list(s.info.peers_zid())) + len(list(s.info.routers_zid())) >= count for s in sessions), WAIT
    )


def _until(seen: Seen, send: Callable[[], None]) -> bool:
    """Send until ``seen``'s marker arrives (the subscriber's declaration may still be on its way); at most WAIT s."""
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        send()
        if seen.arrived.wait(0.1):
            return True
    return False


def _endpoints(count: int) -> list[str]:
    return [tls_endpoint(e) for e in free_endpoints(count)]


# ---------------------------------------------------------------------------------------------- who connects


def test_a_member_connects_and_its_own_puts_arrive(team, sessions):
    [ea] = _endpoints(1)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    seen = Seen(f"{P}/center/events/b")
    a.declare_subscriber(f"{P}/**", seen)
    b = sessions(TeamKeys.load(team, "b"), connect=(ea,))
    assert _linked(a, b)

    def send() -> None:
        b.put(f"{P}/m/b/plan/x", b"1")
        b.put(f"{P}/hb/b", b"2")
        b.put(f"{P}/center/events/b", b"3")

    assert _until(seen, send)
    assert {f"{P}/m/b/plan/x", f"{P}/hb/b"} <= set(seen.snapshot())


def test_a_peer_without_the_team_s_certificate_does_not_connect(team, stranger, sessions):
    tcp, listen = free_endpoints(2)
    ea = tls_endpoint(tcp)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    seen = Seen(f"{P}/m/b/marker")
    a.declare_subscriber(f"{P}/**", seen)
    # a client session fails to open when it cannot connect: plain TCP to the TLS port, TLS with another CA's
    # certificate, TLS with no certificate
    with pytest.raises(zenoh.ZError, match="Unable to connect"):
        sessions(None, connect=(tcp,), mode="client")
    with pytest.raises(zenoh.ZError, match="Unable to connect"):
        sessions(TeamKeys.load(stranger, "b"), connect=(ea,), mode="client")
    with pytest.raises(zenoh.ZError, match="Unable to connect"):
        no_cert = {"transport/link/tls/root_ca_certificate": str(team / "ca.pem")}
        zenoh.open(zenoh_config((ea,), (), "client", 2.0, no_cert)).close()
    # peers keep trying: they start before the member, which connects, and its marker arrives; theirs never do
    plain = sessions(None, connect=(tcp,), listen=(listen,))
    other = sessions(TeamKeys.load(stranger, "b"), connect=(ea,))
    member = sessions(TeamKeys.load(team, "b"), connect=(ea,))
    assert _linked(member)

    def send() -> None:
        plain.put(f"{P}/m/b/plain", b"x")
        other.put(f"{P}/m/b/other", b"x")
        member.put(f"{P}/m/b/marker", b"x")

    assert _until(seen, send)
    assert set(seen.snapshot()) == {f"{P}/m/b/marker"}
    assert list(a.info.peers_zid()) == [member.info.zid()]
    assert list(plain.info.peers_zid()) == [] and list(other.info.peers_zid()) == []


def test_a_member_does_not_connect_to_a_listener_of_another_ca(team, stranger, sessions):
    [ea] = _endpoints(1)
    sessions(TeamKeys.load(stranger, "a"), listen=(ea,))
    with pytest.raises(zenoh.ZError, match="Unable to connect"):
        sessions(TeamKeys.load(team, "b"), connect=(ea,), mode="client")


# ---------------------------------------------------------------------------------------------- who says what


def test_a_member_s_puts_under_another_member_s_keys_are_dropped(team, sessions):
    [ea] = _endpoints(1)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    seen = Seen(f"{P}/m/b/marker")
    a.declare_subscriber(f"{P}/**", seen)
    b = sessions(TeamKeys.load(team, "b"), connect=(ea,))
    assert _linked(a, b)
    forged = [f"{P}/m/a/x", f"{P}/hb/a", f"{P}/center/events/a", f"{P}/hist/a", f"{P}/alive/b/1", f"{P}/x"]

    def send() -> None:
        for key in forged:
            b.put(key, b"forged")
        b.put(f"{P}/m/b/marker", b"x")

    assert _until(seen, send)
    assert set(seen.snapshot()) == {f"{P}/m/b/marker"}


def test_a_member_s_liveliness_token_in_another_s_name_is_dropped(team, sessions):
    [ea] = _endpoints(1)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    seen = Seen(f"{P}/alive/b/2")
    a.liveliness().declare_subscriber(f"{P}/alive/**", seen, history=True)
    b = sessions(TeamKeys.load(team, "b"), connect=(ea,))
    assert _linked(a, b)
    tokens = [b.liveliness().declare_token(f"{P}/alive/a/1"), b.liveliness().declare_token(f"{P}/alive/b/2")]
    assert seen.arrived.wait(WAIT)
    assert set(seen.snapshot()) == {f"{P}/alive/b/2"}
    for token in tokens:
        token.undeclare()


def test_the_center_s_commands_reach_every_agent_through_the_one_it_is_connected_to(team, sessions):
    ea, eb = _endpoints(2)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    b = sessions(TeamKeys.load(team, "b"), listen=(eb,), connect=(ea,))
    at_a, at_b = Seen(f"{P}/center/operator"), Seen(f"{P}/center/operator")
    a.declare_subscriber(f"{P}/**", at_a)
    b.declare_subscriber(f"{P}/**", at_b)
    assert _linked(a, b)
    center = sessions(TeamKeys.load(team, CENTER), connect=(ea,), mode="client")

    def send() -> None:
        center.put(f"{P}/m/a/x", b"forged")  # the center speaks for no agent
        center.put(f"{P}/center/operator", b"{}")

    assert _until(at_a, send) and _until(at_b, send)
    assert set(at_a.snapshot()) == {f"{P}/center/operator"} and set(at_b.snapshot()) == {f"{P}/center/operator"}


def test_the_center_sees_each_member_s_events_but_none_forged_by_another(team, sessions):
    ea, eb = _endpoints(2)
    a = sessions(TeamKeys.load(team, "a"), listen=(ea,))
    b = sessions(TeamKeys.load(team, "b"), listen=(eb,), connect=(ea,))
    assert _linked(a, b)
    center = sessions(TeamKeys.load(team, CENTER), connect=(ea,), mode="client")
    seen = Seen(f"{P}/center/events/b")
    center.declare_subscriber(f"{P}/center/events/*", seen)

    def send() -> None:
        b.put(f"{P}/center/events/a", b"forged")
        b.put(f"{P}/center/events/b", b"{}")

    assert _until(seen, send)
    assert set(seen.snapshot()) == {f"{P}/center/events/b"}


def test_agents_with_credentials_talk_and_see_each_other(team):
    """The agents' transport works under the ACL: reliable messages, history queries, liveliness tokens."""
    ea, eb = _endpoints(2)
    settings = {n: TeamKeys.load(team, n).zenoh_settings(P) for n in ("a", "b")}
    with (
        ZenohTransport("a", listen=[ea], team=P, config=settings["a"]) as a,
        ZenohTransport("b", listen=[eb], connect=[ea], team=P, config=settings["b"]) as b,
    ):
        b.subscribe("news")
        a.publish("news", "hello", QoS.RELIABLE)
        got = [e.payload for e in drain(b, 1, WAIT)]
        assert wait_for(lambda: a.peers() == {"b"} and b.peers() == {"a"}, WAIT)
        assert got == ["hello"]
        assert a.peers() == {"b"} and b.peers() == {"a"}
