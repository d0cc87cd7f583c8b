"""Bad arguments give a ValueError that says what is wrong and what to do."""

from __future__ import annotations

import math

import pytest

from alica.clock import ManualClock
from alica.comm import Delay, Link, PartitionHandle, SimNetwork


@pytest.fixture
def network() -> SimNetwork:
    net = SimNetwork(ManualClock(10.0))
    for name in ("a", "b", "c"):
        net.attach(name)
    return net


@pytest.mark.parametrize(
    "args, message",
    [
        ((-0.1,), "Delay base must be a finite number of seconds >= 0"),
        ((math.inf,), "Delay base must be a finite number of seconds >= 0"),
        (("1",), "Delay base must be a number of seconds"),
        ((0.1, -0.01), "Delay jitter must be a finite number of seconds >= 0"),
        ((0.1, math.nan), "Delay jitter must be a finite number"),
        ((0.1, 0.1, "normal"), "Delay kind must be one of uniform, exponential"),
    ],
)
def test_bad_delays(args: tuple, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Delay(*args)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"clock": None}, "clock must have a now"),
        ({"seed": 1.5}, "seed must be an int"),
        ({"loss": 1.0}, r"loss must be a probability in \[0, 1\).*partition\(\)"),
        ({"loss": -0.5}, r"loss must be a probability in \[0, 1\)"),
        ({"loss": True}, "loss must be a probability"),
        ({"delay": 0.1}, "delay must be a Delay"),
        ({"lease": 0}, "lease must be a finite number of seconds > 0"),
        ({"retransmit": -1.0}, "retransmit must be a finite number of seconds > 0"),
        ({"observer": "print"}, "observer must be a function"),
    ],
)
def test_bad_network_options(options: dict, message: str) -> None:
    arguments = {"clock": ManualClock(), **options}
    with pytest.raises(ValueError, match=message):
        SimNetwork(**arguments)


def test_bad_link() -> None:
    with pytest.raises(ValueError, match="delay must be a Delay"):
        Link(0.0, 0.1)  # type: ignore[arg-type]


def test_attaching_twice(network: SimNetwork) -> None:
    with pytest.raises(ValueError, match="'a' is already attached.*attach a different id"):
        network.attach("a")
    with pytest.raises(ValueError, match="non-empty string"):
        network.attach("")


def test_bad_set_link(network: SimNetwork) -> None:
    with pytest.raises(ValueError, match="unknown agent 'z'; attach it"):
        network.set_link("a", "z", loss=0.1)
    with pytest.raises(ValueError, match="two different agents"):
        network.set_link("a", "a", loss=0.1)
    with pytest.raises(ValueError, match="needs loss=... or delay="):
        network.set_link("a", "b")
    with pytest.raises(ValueError, match=r"loss must be a probability in \[0, 1\)"):
        network.set_link("a", "b", loss=2.0)


@pytest.mark.parametrize(
    "groups, message",
    [
        ([], "at least one group"),
        ("ab", "list of groups"),
        (["a", "b"], "is a string; give each group as a list"),
        ([["a"], ["a", "b"]], "'a' is in two partition groups"),
        ([["a", "zed"]], "unknown agent 'zed'; attach it"),
        ([["a", 3]], r"agent ids \(strings\)"),
    ],
)
def test_bad_partition_groups(network: SimNetwork, groups: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        network.partition(groups)  # type: ignore[arg-type]


def test_bad_partition_times(network: SimNetwork) -> None:
    with pytest.raises(ValueError, match=r"start=9.0 lies in the past \(now is 10.0\)"):
        network.partition([["a"]], start=9.0)
    with pytest.raises(ValueError, match="end=11 must come after its start=12"):
        network.partition([["a"]], start=12.0, end=11)
    with pytest.raises(ValueError, match="finite time"):
        network.partition([["a"]], end=math.inf)


def test_bad_heal(network: SimNetwork) -> None:
    with pytest.raises(ValueError, match="not a partition of this network"):
        network.heal(PartitionHandle(3))
    with pytest.raises(ValueError, match="not a partition of this network"):
        network.heal(1)  # type: ignore[arg-type]


def test_bad_crash_and_recover(network: SimNetwork) -> None:
    with pytest.raises(ValueError, match="unknown agent 'z'"):
        network.crash("z")
    with pytest.raises(ValueError, match="lies in the past"):
        network.crash("a", at=1.0)
    with pytest.raises(ValueError, match="'a' is not crashed"):
        network.recover("a")
    network.crash("a", at=20.0)
    with pytest.raises(ValueError, match="crash at t=20.0; recover"):
        network.crash("a")
    with pytest.raises(ValueError, match="unknown agent"):
        network.crashed("nobody")
