"""Issue 37: a team's credentials (``alica team keys``, :mod:`alica.comm.credentials`) are made, checked and used.

Every check of :meth:`TeamKeys.load` fires with a message naming the file and what to do; signatures verify
only for the team's members, and :meth:`TeamKeys.verifies` never raises, whatever it is given.
"""

from __future__ import annotations

import datetime
import json
import shutil
import stat
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from alica.app.cli import main
from alica.comm import credentials
from alica.comm.credentials import CENTER, CredentialsError, TeamKeys, make_keys, tls_endpoint
from alica.errors import AlicaError


@pytest.fixture(scope="module")
def team(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Credentials of agents a, b, c (read only: tests that break files copy them first)."""
    folder = tmp_path_factory.mktemp("team") / "keys"
    make_keys(folder, ["a", "b", "c"])
    return folder


@pytest.fixture
def copy(team: Path, tmp_path: Path) -> Path:
    """A copy of the team's credentials to break."""
    return Path(shutil.copytree(team, tmp_path / "keys"))


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


# ---------------------------------------------------------------------------------------------- making keys


def test_make_keys_writes_the_ca_a_pair_per_agent_and_the_center_and_the_roster(tmp_path):
    folder = tmp_path / "keys"
    written = make_keys(folder, ["b", "a"], days=30)
    names = {p.name for p in written}
    assert names == {"ca.pem", "ca.key", "a.pem", "a.key", "b.pem", "b.key", "center.pem", "center.key", "roster.json"}
    assert json.loads((folder / "roster.json").read_text()) == {"members": ["a", "b"], "center": CENTER}
    assert _mode(folder) == 0o700
    assert all(_mode(p) == 0o600 for p in written if p.suffix == ".key")
    keys = TeamKeys.load(folder, "a")
    assert (keys.name, keys.members, keys.center) == ("a", frozenset({"a", "b"}), CENTER)
    assert (keys.ca, keys.cert, keys.key) == (folder / "ca.pem", folder / "a.pem", folder / "a.key")
    assert TeamKeys.load(str(folder), CENTER).members == frozenset({"a", "b"})


def test_make_keys_takes_an_empty_folder_and_refuses_one_with_files(tmp_path):
    (tmp_path / "empty").mkdir()
    make_keys(tmp_path / "empty", ["a"])
    with pytest.raises(CredentialsError, match=r"exists and is not empty.*--add a"):
        make_keys(tmp_path / "empty", ["a"])
    (tmp_path / "file").write_text("x")
    with pytest.raises(CredentialsError, match="is a file, not a folder"):
        make_keys(tmp_path / "file", ["a"])


def test_add_reuses_the_ca_and_adds_to_the_roster(tmp_path):
    folder = tmp_path / "keys"
    make_keys(folder, ["a"])
    ca, center = (folder / "ca.pem").read_bytes(), (folder / "center.pem").read_bytes()
    written = make_keys(folder, ["c", "b"], add=True)
    assert {p.name for p in written} == {"b.pem", "b.key", "c.pem", "c.key", "roster.json"}
    assert (folder / "ca.pem").read_bytes() == ca and (folder / "center.pem").read_bytes() == center
    assert json.loads((folder / "roster.json").read_text())["members"] == ["a", "b", "c"]
    assert TeamKeys.load(folder, "c").members == frozenset({"a", "b", "c"})
    with pytest.raises(CredentialsError, match=r"already hold.*delete a\.pem and a\.key there first"):
        make_keys(folder, ["a"], add=True)


def test_add_renews_the_keys_of_a_member_whose_certificate_was_deleted(tmp_path):
    folder = tmp_path / "keys"
    make_keys(folder, ["a", "b"])
    old = (folder / "a.pem").read_bytes()
    (folder / "a.pem").unlink()
    (folder / "a.key").unlink()
    assert {p.name for p in make_keys(folder, ["a"], add=True)} == {"a.pem", "a.key", "roster.json"}
    assert (folder / "a.pem").read_bytes() != old
    assert TeamKeys.load(folder, "a").members == frozenset({"a", "b"})


def test_add_needs_the_ca_key(tmp_path, team):
    with pytest.raises(CredentialsError, match=r"no team's credentials to add to"):
        make_keys(tmp_path / "none", ["a"], add=True)
    folder = Path(shutil.copytree(team, tmp_path / "keys"))
    (folder / "ca.key").unlink()
    with pytest.raises(CredentialsError, match="ca.key"):
        make_keys(folder, ["d"], add=True)


@pytest.mark.parametrize(
    ("names", "message"),
    [
        ([""], "non-empty name"),
        (["a/b"], "without '/'"),
        (["a*"], "non-empty name"),
        (["a b"], "non-empty name"),
        (["a\x00"], "printable"),
        (["x" * 65], "at most 64"),
        ([CENTER], "names the control center"),
        (["ca"], "certificate authority"),
        (["a", "a"], "named twice"),
        ([], "at least one agent"),
    ],
)
def test_make_keys_refuses_bad_names(tmp_path, names, message):
    with pytest.raises(CredentialsError, match=message):
        make_keys(tmp_path / "keys", names)
    assert not (tmp_path / "keys").exists()


@pytest.mark.parametrize("days", [0, -3, True, 1.5])
def test_make_keys_refuses_bad_days(tmp_path, days):
    with pytest.raises(CredentialsError, match="days"):
        make_keys(tmp_path / "keys", ["a"], days=days)


def test_credentials_error_is_an_alica_error_and_a_value_error():
    assert issubclass(CredentialsError, AlicaError) and issubclass(CredentialsError, ValueError)


# ---------------------------------------------------------------------------------------------- loading keys


def test_load_refuses_a_missing_folder(tmp_path):
    with pytest.raises(CredentialsError, match=r"no folder .*missing.*alica team keys --out"):
        TeamKeys.load(tmp_path / "missing", "a")


def test_load_refuses_a_name_outside_the_roster(team):
    with pytest.raises(CredentialsError, match=r"'d' is not in the team's roster .*a, b, c.*--add d"):
        TeamKeys.load(team, "d")


@pytest.mark.parametrize("text", ["{", "[]", '{"members": "a", "center": "center"}', '{"members": ["a/b"]}'])
def test_load_refuses_a_broken_roster(copy, text):
    (copy / "roster.json").write_text(text)
    with pytest.raises(CredentialsError, match="roster.json"):
        TeamKeys.load(copy, "a")


@pytest.mark.parametrize("missing", ["roster.json", "ca.pem"])
def test_load_refuses_a_missing_team_file(copy, missing):
    (copy / missing).unlink()
    with pytest.raises(CredentialsError, match=rf"no .*{missing}"):
        TeamKeys.load(copy, "a")


def test_load_names_the_missing_certificate_and_how_to_make_it(copy):
    (copy / "c.pem").unlink()
    with pytest.raises(CredentialsError) as caught:
        TeamKeys.load(copy, "c")
    assert str(caught.value) == (
        f"no certificate for agent 'c' in {copy}/ ({copy}/c.pem); make one with: alica team keys --out {copy} --add c"
    )


def test_load_refuses_a_missing_private_key(copy):
    (copy / "b.key").unlink()
    with pytest.raises(CredentialsError, match=r"no private key for agent 'b' .*b\.key"):
        TeamKeys.load(copy, "b")


def test_load_refuses_a_file_that_is_no_certificate(copy):
    (copy / "a.pem").write_text("not a certificate")
    with pytest.raises(CredentialsError, match=r"a\.pem .* is not a PEM certificate"):
        TeamKeys.load(copy, "a")


def test_load_refuses_a_certificate_of_another_name(copy):
    shutil.copy(copy / "b.pem", copy / "a.pem")
    shutil.copy(copy / "b.key", copy / "a.key")
    with pytest.raises(CredentialsError, match=r"a\.pem is the certificate of 'b', not of 'a'"):
        TeamKeys.load(copy, "a")


def test_load_refuses_a_certificate_of_another_ca(copy, tmp_path):
    other = tmp_path / "other"
    make_keys(other, ["a"])
    shutil.copy(other / "a.pem", copy / "a.pem")
    shutil.copy(other / "a.key", copy / "a.key")
    with pytest.raises(CredentialsError, match=r"a\.pem is not signed by the team's CA"):
        TeamKeys.load(copy, "a")


def test_load_refuses_an_expired_certificate(copy):
    past = datetime.datetime(2020, 1, 1, tzinfo=datetime.UTC)
    credentials._issue(copy, "a", not_before=past, not_after=past + datetime.timedelta(days=1))
    with pytest.raises(CredentialsError) as caught:
        TeamKeys.load(copy, "a")
    assert str(caught.value) == (
        f"{copy}/a.pem expired on 2020-01-02 00:00 UTC; renew it where the team's ca.key is: delete a.pem and a.key "
        f"there, then run alica team keys --out {copy} --add a"
    )


def test_load_refuses_a_certificate_valid_only_later(copy):
    future = datetime.datetime.now(datetime.UTC) + datetime.timedelta(days=2)
    credentials._issue(copy, "a", not_before=future, not_after=future + datetime.timedelta(days=1))
    with pytest.raises(CredentialsError, match=r"a\.pem is valid only from .*is this host's clock right"):
        TeamKeys.load(copy, "a")


def test_load_refuses_a_certificate_that_expired(tmp_path, monkeypatch):
    folder = tmp_path / "keys"
    make_keys(folder, ["a"], days=2)
    later = datetime.datetime.now(datetime.UTC) + datetime.timedelta(days=3)
    monkeypatch.setattr(credentials, "_now", lambda: later)
    with pytest.raises(CredentialsError, match=r"ca\.pem expired on \d{4}-\d\d-\d\d \d\d:\d\d UTC"):
        TeamKeys.load(folder, "a")


def test_load_refuses_a_member_certificate_that_expired_before_the_ca(tmp_path, monkeypatch):
    folder = tmp_path / "keys"
    make_keys(folder, ["a"], days=30)
    make_keys(folder, ["b"], days=1, add=True)
    later = datetime.datetime.now(datetime.UTC) + datetime.timedelta(days=2)
    monkeypatch.setattr(credentials, "_now", lambda: later)
    TeamKeys.load(folder, "a")
    with pytest.raises(CredentialsError, match=r"b\.pem expired on \d{4}-\d\d-\d\d .*--add b$"):
        TeamKeys.load(folder, "b")


def test_load_refuses_a_key_that_is_not_the_certificate_s(copy):
    shutil.copy(copy / "b.key", copy / "a.key")
    with pytest.raises(CredentialsError, match=r"a\.key is not the key of .*a\.pem"):
        TeamKeys.load(copy, "a")


def test_load_refuses_a_key_file_that_is_no_key(copy):
    (copy / "a.key").write_text("-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n")
    with pytest.raises(CredentialsError, match=r"a\.key is not a PEM private key"):
        TeamKeys.load(copy, "a")


# ---------------------------------------------------------------------------------------------- signatures


def test_a_signature_verifies_for_its_signer_and_data_only(team):
    a, b, center = (TeamKeys.load(team, n) for n in ("a", "b", CENTER))
    data = b"alica\n1\n{}"
    signature = center.sign(data)
    assert a.verifies(CENTER, data, signature) and b.verifies(CENTER, bytearray(data), signature)
    assert not a.verifies(CENTER, data + b"!", signature)
    assert not a.verifies("b", data, signature)
    assert b.verifies("a", data, a.sign(data))
    assert not b.verifies("a", data, signature[:-1] + bytes([signature[-1] ^ 1]))


def test_verifies_refuses_names_outside_the_roster_and_certificates_of_another_ca(copy, tmp_path):
    other = tmp_path / "other"
    make_keys(other, ["a", "b"])
    intruder = TeamKeys.load(other, "b")
    shutil.copy(other / "b.pem", copy / "b.pem")  # b's certificate in the folder is now another team's
    a = TeamKeys.load(copy, "a")
    data = b"command"
    assert not a.verifies("b", data, intruder.sign(data))
    assert not a.verifies("../other/b", data, intruder.sign(data))
    assert not a.verifies("d", data, intruder.sign(data))


@pytest.mark.parametrize(
    ("signer", "data", "signature"),
    [
        (None, b"x", b"y"),
        (CENTER, "text", b"y"),
        (CENTER, b"x", "30"),
        (CENTER, b"x", b""),
        (CENTER, b"x", b"\x30" * 100_000),
        (CENTER, None, None),
        (["center"], b"x", b"y"),
        ("a" * 10_000, b"x", b"y"),
        ("\x00", b"x", b"y"),
    ],
)
def test_verifies_is_false_for_hostile_input(team, signer, data, signature):
    assert TeamKeys.load(team, "a").verifies(signer, data, signature) is False


@given(
    signer=st.sampled_from(["a", "b", "c", CENTER, "d", ""]) | st.text(max_size=20),
    data=st.binary(max_size=300),
    signature=st.binary(max_size=300) | st.none() | st.integers() | st.text(max_size=10),
)
def test_verifies_never_raises_and_random_bytes_never_verify(team, signer, data, signature):
    keys = _loaded(team)
    assert keys.verifies(signer, data, signature) is False


@given(data=st.binary(max_size=2000), flip=st.integers(min_value=0))
def test_a_signature_of_any_data_verifies_and_one_flipped_bit_does_not(team, data, flip):
    keys = _loaded(team)
    signature = keys.sign(data)
    assert keys.verifies("a", data, signature)
    if data:
        i = flip % len(data)
        assert not keys.verifies("a", data[:i] + bytes([data[i] ^ 1]) + data[i + 1 :], signature)


_LOADED: dict[Path, TeamKeys] = {}


def _loaded(team: Path) -> TeamKeys:
    return _LOADED.setdefault(team, TeamKeys.load(team, "a"))


# ---------------------------------------------------------------------------------------------- zenoh settings


def test_zenoh_settings_turn_on_mutual_tls_and_a_deny_by_default_acl(team):
    settings = TeamKeys.load(team, "a").zenoh_settings("alica")
    assert settings["transport/link/tls/enable_mtls"] is True
    assert settings["transport/link/tls/root_ca_certificate"] == str((team / "ca.pem").resolve())
    assert settings["transport/link/tls/connect_certificate"] == str((team / "a.pem").resolve())
    acl = settings["access_control"]
    assert isinstance(acl, dict) and acl["enabled"] is True and acl["default_permission"] == "deny"
    assert json.loads(json.dumps(settings)) == settings  # JSON-able
    keys = {k for rule in acl["rules"] if "ingress" in rule["flows"] for k in rule["key_exprs"]}
    assert {"alica/m/b/**", "alica/hb/b", "alica/alive/b/*", "alica/center/events/c", "alica/center/operator"} <= keys


def test_the_center_s_acl_is_a_viewer_s(team):
    acl = TeamKeys.load(team, CENTER).zenoh_settings("p")["access_control"]
    assert isinstance(acl, dict)
    ingress = {(m, k) for r in acl["rules"] if r["flows"] == ["ingress"] for m in r["messages"] for k in r["key_exprs"]}
    assert ("put", "p/center/events/*") in ingress
    assert not any(m == "put" and k != "p/center/events/*" for m, k in ingress)
    assert not any(m in ("query", "liveliness_query") for m, _ in ingress)


@pytest.mark.parametrize("prefix", ["", "a/b", "a*", "a b", None])
def test_zenoh_settings_refuse_a_bad_prefix(team, prefix):
    with pytest.raises(CredentialsError, match="key prefix"):
        TeamKeys.load(team, "a").zenoh_settings(prefix)


@pytest.mark.parametrize(
    ("endpoint", "expected"),
    [
        ("tcp/127.0.0.1:7447", "tls/127.0.0.1:7447"),
        ("tcp/[::1]:7447", "tls/[::1]:7447"),
        ("tls/robot-1.local:7447", "tls/robot-1.local:7447"),
    ],
)
def test_tls_endpoint(endpoint, expected):
    assert tls_endpoint(endpoint) == expected


@pytest.mark.parametrize("endpoint", ["udp/127.0.0.1:7447", "unixsock-stream//tmp/s", "127.0.0.1:7447", 7447])
def test_tls_endpoint_refuses_other_protocols(endpoint):
    with pytest.raises(ValueError, match="tls"):
        tls_endpoint(endpoint)


# ---------------------------------------------------------------------------------------------- alica team keys


def test_alica_team_keys_makes_the_folder_and_says_what_to_copy_where(tmp_path, capsys):
    out = tmp_path / "keys"
    assert main(["team", "keys", "--out", str(out), "a", "b", "--days", "10"]) == 0
    printed = capsys.readouterr().out
    assert f"{out}/a.key" in printed and f"{out}/roster.json" in printed
    assert "ca.pem, roster.json, center.pem" in printed and "ca.key" in printed
    assert TeamKeys.load(out, "b").members == frozenset({"a", "b"})
    assert main(["team", "keys", "--out", str(out), "--add", "c"]) == 0
    assert "Copy the new roster.json to every host" in capsys.readouterr().out
    assert TeamKeys.load(out, "c").members == frozenset({"a", "b", "c"})


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["a"], "exists and is not empty"),
        (["--add", "a"], "already hold(s) keys"),
        (["--add", "x/y"], "without '/'"),
        (["--add", CENTER], "names the control center"),
        (["--add", "d", "--days", "0"], "days must be"),
    ],
)
def test_alica_team_keys_says_what_is_wrong_with_exit_code_2(team, capsys, argv, message):
    assert main(["team", "keys", "--out", str(team), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("alica team keys: error: ") and message in err and "Traceback" not in err
