"""The sender's history of reliable messages (:class:`alica.comm.reliable.History`), without zenoh."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from alica.comm.reliable import History

TOPICS = ("a", "b", "c")


@given(st.lists(st.tuples(st.sampled_from(TOPICS), st.integers(1, 400)), max_size=200))
def test_a_flood_keeps_the_history_within_its_bytes_and_each_topic_its_newest(sends):
    history = History(1, seconds=1e9, max_bytes=1000)
    sizes: dict[tuple[str, int], int] = {}
    for now, (topic, size) in enumerate(sends):
        rseq, _ = history.next_numbers(topic)
        history.keep(topic, rseq, float(now), b"x" * size)
        sizes[(topic, rseq)] = size
        kept = {t: history.kept(t) for t in TOPICS}
        assert history.kept_bytes == sum(sizes[(t, n)] for t in TOPICS for n in kept[t])
        assert kept[topic][-1] == rseq  # the newest always stays
        assert history.kept_bytes <= 1000 or len(kept[topic]) == 1  # the flooding topic gave way first
        assert history.kept_bytes <= 1000 + len(TOPICS) * 400
        for numbers in kept.values():
            assert numbers == list(range(numbers[0], numbers[0] + len(numbers))) if numbers else True


@given(st.lists(st.sampled_from(TOPICS), min_size=1, max_size=60), st.integers(0, 60), st.integers(0, 60))
def test_an_answer_gives_what_the_receiver_lacks_in_order(topics, since, first):
    history = History(7, seconds=1e9, max_bytes=1e9)
    sent: dict[str, list[tuple[int, float, bytes]]] = {}
    for now, topic in enumerate(topics):
        rseq, gseq = history.next_numbers(topic)
        data = f"{topic}{rseq}/{gseq}".encode()
        history.keep(topic, rseq, float(now), data)
        history.put(topic, rseq)
        sent.setdefault(topic, []).append((rseq, float(now), data))
    assert history.announced() == {t: len(kept) for t, kept in sent.items()}
    wanted = {t: (None if t == "a" else first, float(since)) for t in TOPICS}
    frames, start, oldest = history.answer(7, wanted)
    expected = []
    for t in TOPICS:
        kept = sent.get(t, [])
        if t == "a":
            expected += [data for _, at, data in kept if at >= since]
        else:
            expected += [data for number, _, data in kept if number >= first]
        assert start[t] == len(kept) + 1 and oldest[t] == 1 if kept else start[t] == oldest[t] == 1
    assert list(frames) == expected
    # about an earlier life of this sender: everything since the receiver subscribed
    frames, _, _ = history.answer(6, {t: (1, float(since)) for t in TOPICS})
    assert list(frames) == [data for t in TOPICS for _, at, data in sent.get(t, []) if at >= since]


def test_old_messages_go_and_the_announced_numbers_stay():
    history = History(1, seconds=10.0, max_bytes=1e9)
    for now in range(5):
        rseq, _ = history.next_numbers("a")
        history.keep("a", rseq, float(now), b"m")
        history.put("a", rseq)
    history.trim(13.5)
    assert history.kept("a") == [5] and history.kept_bytes == 1
    assert history.announced() == {"a": 5}
    history.trim(100.0)
    assert history.kept("a") == [] and history.kept_bytes == 0
    assert history.answer(1, {"a": (3, 0.0)}) == ((), {"a": 6}, {"a": 6})
