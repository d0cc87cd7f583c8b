"""What the leader's search starts from (alica.prophet.leader_search); MAGiC rounds: tests/prophet/test_magic_team.py."""

from __future__ import annotations

from alica.prophet.leader_search import positions


def test_positions_are_read_from_the_pos_values_only():
    values = [
        ("pos", ("s1",), (1.0, 2.0)),
        ("pos", ("r1",), [3, 4, 0.5]),
        ("pos", ("bad",), ("x", "y")),  # not numbers: left out
        ("pos", ("short",), (1.0,)),  # not a position
        ("pos", ("a", "b"), (1.0, 2.0)),  # two arguments: not an object's position
        ("battery", ("r1",), (1.0, 2.0)),
    ]
    assert positions(values) == {"s1": (1.0, 2.0), "r1": (3.0, 4.0, 0.5)}
