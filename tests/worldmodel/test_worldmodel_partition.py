"""A network partition: two groups work apart, then heal by exchanging digest answers."""

from __future__ import annotations

from itertools import permutations

from alica.worldmodel import Delta, Key, Stamp, WorldModel


def gossip(group: list[WorldModel]) -> None:
    """Deliver every pending delta of the group to the rest of the group, until quiet."""
    while True:
        moved = False
        for sender in group:
            delta = sender.take_delta()
            if delta is None:
                continue
            moved = True
            for receiver in group:
                if receiver is not sender:
                    receiver.merge(delta)
        if not moved:
            return


def test_partition_heals_with_missing_for_and_nothing_is_lost() -> None:
    scout, rover, lander, drone = (WorldModel(name) for name in ("scout", "rover", "lander", "drone"))
    team = [scout, rover, lander, drone]
    # Before the partition: a shared start.
    lander.add_object("s1", "Sample")
    lander.set("map", 0, 0, value="free")
    gossip(team)
    assert all(wm.objects("Sample") == ("s1",) for wm in team)

    # The partition: {scout, rover} and {lander, drone} write independently.
    west, east = [scout, rover], [lander, drone]
    scout.set("pos", "scout", value=(1.0, 1.0))
    scout.assert_fact("found", "s1")
    scout.add_to_set("invalid_candidates", "c1")
    rover.set("map", 0, 0, value="rock")  # conflicts with drone below
    rover.set("map", 0, 1, value="free")
    rover.add_object("s2", "Sample")
    lander.retract_fact("found", "s1")  # conflicts with scout above
    lander.add_to_set("invalid_candidates", "c2")
    drone.set("map", 0, 0, value="crater")
    drone.set("map", 0, 0, value="crater, steep")  # a later write of the same agent
    drone.set("pos", "drone", value=(9.0, 9.0))
    drone.add_object("s3", "Sample")
    drone.add_object("s2", "Sample")  # the same object found on both sides
    gossip(west)
    gossip(east)
    lost_in_the_partition = scout.take_delta(), drone.take_delta()
    assert lost_in_the_partition == (None, None)
    assert scout.dumps() == rover.dumps() and lander.dumps() == drone.dumps()
    assert scout.dumps() != lander.dumps()

    # Every write made anywhere, read back from the stamps the writers hold.
    writes = {
        ("map", (0, 0)): [rover.stamp_of("map", 0, 0), drone.stamp_of("map", 0, 0)],
        ("found", ("s1",)): [rover.stamp_of("found", "s1"), lander.stamp_of("found", "s1")],
    }
    expected_map = max(writes[("map", (0, 0))], key=_stamp)
    expected_found = max(writes[("found", ("s1",))], key=_stamp)

    # The heal: every agent sends its digest to every peer and merges the answer.
    sizes: list[int] = []
    for receiver, sender in permutations(team, 2):
        answer = sender.missing_for(receiver.digest())
        sizes.append(len(answer))
        receiver.merge(answer)

    dump = scout.dumps()
    assert all(wm.dumps() == dump for wm in team)
    for wm in team:
        assert wm.stamp_of("map", 0, 0) == expected_map
        assert wm.stamp_of("found", "s1") == expected_found
        assert wm.get("map", 0, 1) == "free"
        assert wm.get("pos", "scout") == (1.0, 1.0)
        assert wm.get("pos", "drone") == (9.0, 9.0)
        assert wm.members("invalid_candidates") == {"c1", "c2"}
        assert wm.objects("Sample") == ("s1", "s2", "s3")
    # The conflicting writes resolve by stamp: the drone wrote map(0, 0) twice, so its counter is larger.
    assert scout.get("map", 0, 0) == "crater, steep"
    assert max(sizes) <= len(scout.snapshot())  # never more than the whole state
    # Converged replicas answer each other with nothing.
    assert all(len(a.missing_for(b.digest())) == 0 for a, b in permutations(team, 2))


def test_a_writer_after_the_heal_wins_everywhere() -> None:
    west, east = WorldModel("west"), WorldModel("east")
    for step in range(5):
        east.set("map", 3, 3, value=f"east {step}")
    west.set("map", 3, 3, value="west")
    west.merge(east.missing_for(west.digest()))
    east.merge(west.missing_for(east.digest()))
    assert west.get("map", 3, 3) == east.get("map", 3, 3) == "east 4"
    stamp = west.set("map", 3, 3, value="west again")  # after the merge: larger than everything seen
    assert stamp == Stamp(6, "west")
    delta = west.take_delta()
    assert isinstance(delta, Delta)
    assert east.merge(delta) >= {Key("register", "map", (3, 3))}
    assert east.get("map", 3, 3) == "west again"


def _stamp(stamp: Stamp | None) -> Stamp:
    assert stamp is not None
    return stamp
