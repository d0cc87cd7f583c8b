"""Issue 37: ``alica agent`` without credentials stays on loopback and says so; a second agent with a live name refuses."""

from __future__ import annotations

import pytest

from alica.app.cli import main
from alica.comm.zenoh_transport import ZenohTransport, free_endpoints
from tests.conftest import PLANS

LUNAR = str(PLANS / "lunar" / "mission.yaml")


@pytest.mark.parametrize(
    "endpoint", ["--listen=tcp/0.0.0.0:7447", "--connect=tcp/192.0.2.7:7447", "--listen=tcp/[::]:0"]
)
def test_without_credentials_an_agent_refuses_endpoints_beyond_loopback(capsys, endpoint):
    assert main(["agent", LUNAR, "--stand-ins", "--name", "scout", endpoint, "--time-limit", "0.3"]) == 1
    err = capsys.readouterr().err
    assert "reaches beyond this machine" in err and "alica team keys" in err and "--insecure" in err
    assert "Traceback" not in err


def test_without_credentials_an_agent_says_it_runs_unauthenticated_on_loopback(capsys):
    [endpoint] = free_endpoints(1)
    argv = ["--name", "scout", "--listen", endpoint, "--time-limit", "0.3", "--key-prefix", "loopback-note"]
    main(["agent", LUNAR, "--stand-ins", *argv])
    assert (
        "no team credentials (--team-keys): unauthenticated and unencrypted, on loopback only"
        in capsys.readouterr().err
    )


def test_an_agent_whose_name_is_live_in_the_team_refuses_to_start(capsys):
    [endpoint] = free_endpoints(1)
    with ZenohTransport("scout", listen=[endpoint], team="names-test"):
        argv = ["--name", "scout", "--connect", endpoint, "--time-limit", "5", "--key-prefix", "names-test"]
        assert main(["agent", LUNAR, "--stand-ins", *argv]) == 1
    err = capsys.readouterr().err
    assert "another agent named 'scout' has been in team 'names-test'" in err and "Traceback" not in err


def test_team_keys_go_with_processes(capsys):
    argv = ["run", LUNAR, "--stand-ins", "--agents", "scout", "--team-keys", "keys"]
    assert main(argv) == 1
    assert "--team-keys goes with --processes" in capsys.readouterr().err
