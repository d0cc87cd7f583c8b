"""Issue 37, findings 5 and 6: what an Inbox keeps of a sender is bounded and expires."""

from __future__ import annotations

from alica.comm.codec import encode
from alica.comm.reliable import Inbox

DATA = encode("x" * 100)


def frame(sender: str, rseq: int, incarnation: int = 1, topic: str = "news"):
    return (incarnation, sender, topic, rseq, rseq, rseq, 0.0, DATA)


def test_frames_after_a_gap_are_held_up_to_the_cap_per_sender_and_in_all():
    inbox = Inbox("me", max_held=10, max_held_total=25)
    inbox.subscribe("news", 0.0)
    for rseq in range(2, 100):  # 1 never comes: all after a gap
        inbox.receive(frame("fake", rseq), 1.0)
    assert inbox.held == 10 and inbox.dropped["held"] == 88
    for name in ("f1", "f2", "f3"):
        for rseq in range(2, 20):
            inbox.receive(frame(name, rseq), 1.0)
    assert inbox.held == 25


def test_a_quiet_sender_is_no_longer_asked_and_its_held_frames_go():
    inbox = Inbox("me", quiet=20.0)
    inbox.subscribe("news", 0.0)
    assert inbox.receive(frame("ghost", 5), 1.0) == "ghost"  # a gap: ask
    assert inbox.held == 1
    assert inbox.overdue(3.0, 1.0) == ["ghost"]  # no answer: asked again
    assert inbox.overdue(21.5, 1.0) == []  # unheard for 20 s: not asked any more
    assert inbox.held == 0 and inbox.dropped["quiet"] == 1
    assert inbox.overdue(100.0, 1.0) == []
    assert inbox.heard("ghost", 1, {"news": 5}, 101.0) == "ghost"  # heard again: asked again


def test_the_senders_remembered_are_bounded_never_answered_ones_forgotten_first():
    inbox = Inbox("me", max_senders=50)
    inbox.subscribe("news", 0.0)
    inbox.receive(frame("real", 1), 0.0)
    inbox.answered(1, "real", [frame("real", 1)], {"news": 2}, {"news": 1})
    [delivered] = inbox.take()
    assert delivered.sender == "real"
    for i in range(12_000):
        inbox.receive(frame(f"fake{i}", 3), float(i))
    assert len(inbox._senders) <= 50 and "real" in inbox._senders
    assert inbox.dropped["senders"] == 12_001 - 50
    inbox.receive(frame("real", 2), 12_000.0)
    assert [e.payload for e in inbox.take()] == ["x" * 100]  # no duplicate, no restart: number 2 only


def test_the_bytes_held_are_bounded_per_sender_and_in_all_and_freed_when_delivered():
    big = encode("y" * 1000)
    size = len(big)
    inbox = Inbox("me", max_held_bytes=10 * size, max_held_bytes_total=25 * size)
    inbox.subscribe("news", 0.0)
    for rseq in range(2, 40):  # few frames, but large ones (before: only their number was capped)
        inbox.receive((1, "fake", "news", rseq, rseq, rseq, 0.0, big), 1.0)
    assert inbox.held == 10 and inbox.dropped["held"] == 28
    for name in ("f1", "f2", "f3"):
        for rseq in range(2, 20):
            inbox.receive((1, name, "news", rseq, rseq, rseq, 0.0, big), 1.0)
    assert inbox.held == 25
    inbox.answered(1, "fake", [(1, "fake", "news", 1, 1, 1, 0.0, big)], {"news": 1}, {"news": 1})  # the gap filled
    assert len(inbox.take()) == 11 and inbox.held == 15
    inbox.receive((1, "f4", "news", 2, 2, 2, 0.0, big), 2.0)  # room again in all
    assert inbox.held == 16
