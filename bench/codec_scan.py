"""The cost of the codec's opcode scan (issue 37, finding 1): team frames, and adversarial pickles up to 16 MB.

:func:`alica.comm.codec.decode` scans a pickle's opcodes (:func:`~alica.comm.codec.scan`)
before unpickling it, following the unpickler's stack to refuse nesting deeper
than 64. This measures the scan alone beside the whole ``decode``:

* **team frames**: what the zenoh transport receives, an encoded frame tuple
  (``ZenohTransport.publish``: incarnation, sender, topic, numbers, time, the
  encoded payload) whose payload is decoded in its turn; both decodes count.
  A world delta of 2 entries and a team message of 2 claims (a few hundred
  bytes), and a world snapshot of 1,000 writes.
* **adversarial**: a pickle of 1 MB and of 16 MB (the largest frame taken,
  ``frames.MAX_FRAME_BYTES``) made of one short opcode pattern repeated, each
  shallow (so the scan reads it all): pushes, memo writes, marks, pops, tuple
  wraps, duplicates. The deep one (a tuple a million deep, which crashed
  CPython's unpickler before the scan) is refused after 65 opcodes.

Columns: bytes, opcodes, seconds of the scan (best of ``--repeat``), ns per
opcode, µs per frame (team frames), and seconds of the whole ``decode`` (scan
and unpickling; "refused" when the codec refuses the bytes, as it does every
adversarial pickle but the plain pushes).

Run: ``.venv/bin/python bench/codec_scan.py [--repeat 3] [--no-16mb]``
"""

from __future__ import annotations

import argparse
import pickletools
import sys
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from alica.comm.codec import CodecError, decode, encode, scan
from alica.engine.team import AuthorityClaim, Claim, TeamMessage
from alica.worldmodel.delta import Add, Delta, Write
from alica.worldmodel.stamp import Stamp

MB = 1 << 20

#: Adversarial patterns: (name, head, unit repeated, opcodes per unit). Each pickle is PROTO 5, the head, the
#: unit repeated to the size, then NONE and STOP.
PATTERNS: tuple[tuple[str, bytes, bytes, int], ...] = (
    ("NONE (push)", b"", b"N", 1),
    ("NONE, POP", b"", b"N0", 2),
    ("NONE, MEMOIZE", b"", b"N\x94", 2),
    ("MARK, POP_MARK", b"", b"(1", 2),
    ("DUP, POP", b"N", b"20", 2),
    ("READONLY_BUFFER", b"N", b"\x98", 1),
    ("NONE, TUPLE1, POP", b"", b"N\x850", 3),
    ("NONE, NONE, TUPLE2, POP", b"", b"NN\x860", 4),
    ("EMPTY_LIST, NONE, APPEND, POP", b"", b"]Na0", 4),
    ("BINGET (a memoized list)", b"]\x94", b"h\x00", 1),
    ("deep TUPLE1 (refused at 65)", b")", b"\x85", 1),
)


def frame(payload: object, topic: str = "alica/world") -> bytes:
    """The bytes the zenoh transport sends for ``payload`` (see ``ZenohTransport.publish``)."""
    return encode((1_733_000_000_000_000_000, "r1", topic, 7, 3, 3, 12.5, encode(payload)))


def team_frames() -> list[tuple[str, bytes]]:
    stamp = Stamp(3, "r1")
    key = ("root", "Serve", "0")
    delta = Delta(
        writes=(Write("at", ("r1",), (1.0, 2.0), stamp), Write("holding", ("r2", "box"), None, stamp, 9.5)),
        adds=(Add("set", "seen", ("box", 1), Stamp(4, "r2")),),
    )
    team = TeamMessage(
        "r1",
        12.5,
        "carrier",
        (Claim(key, "Serve", "serve", "Walk", ("a",)), Claim(("root",), "Main", None, None)),
        (AuthorityClaim(key, "Serve", (("serve", "r1"), ("fetch", None)), 20.0),),
    )
    snapshot = Delta(writes=tuple(Write("at", (f"r{i}",), (float(i), 2.0), Stamp(i + 1, "r1")) for i in range(1000)))
    return [
        ("frame: world delta, 3 entries", frame(delta)),
        ("frame: team message, 2 claims", frame(team, "alica/team")),
        ("frame: world snapshot, 1,000 writes", frame(snapshot)),
    ]


def best(run: Callable[[], object], repeat: int, loops: int = 1) -> float:
    """The shortest time of ``repeat`` runs of ``loops`` calls, per call, in seconds."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(loops):
            run()
        times.append((time.perf_counter() - start) / loops)
    return min(times)


def both(data: bytes) -> None:
    """What the transport does with a received frame: decode it, then decode its payload."""
    inner = decode(data)
    decode(inner[7])  # type: ignore[index]


def scan_both(data: bytes) -> None:
    scan(data)
    inner = decode(data)
    scan(inner[7])  # type: ignore[index]


def attempt(data: bytes) -> float | None:
    """The seconds of ``decode(data)``, or ``None`` when it is refused."""
    start = time.perf_counter()
    try:
        decode(data)
    except CodecError:
        return None
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each measurement; the best counts")
    parser.add_argument("--no-16mb", action="store_true", help="only the 1 MB adversarial pickles")
    args = parser.parse_args(argv)
    header = f"{'case':38} {'bytes':>10} {'ops':>10} {'scan s':>9} {'ns/op':>6} {'us/frame':>9} {'decode s':>9}"
    print(header)
    print("-" * len(header))
    for name, data in team_frames():
        inner = decode(data)[7]  # type: ignore[index]
        ops = sum(1 for _ in pickletools.genops(data)) + sum(1 for _ in pickletools.genops(inner))
        loops = max(1, 200_000 // (len(data) + 1000))
        scanned = best(lambda data=data: scan_both(data), args.repeat, loops) - best(
            lambda data=data: decode(data), args.repeat, loops
        )  # the two scans (the outer decode is needed to find the payload)
        whole = best(lambda data=data: both(data), args.repeat, loops)
        print(
            f"{name:38} {len(data) + len(inner):>10,} {ops:>10,} {scanned:>9.6f} "
            f"{scanned / ops * 1e9:>6.0f} {scanned * 1e6:>9.1f} {whole:>9.6f}"
        )
    sizes = (MB,) if args.no_16mb else (MB, 16 * MB)
    for size in sizes:
        for name, head, unit, per_unit in PATTERNS:
            units = (size - len(head) - 4) // len(unit)
            data = b"\x80\x05" + head + unit * units + b"N."  # (NONE: something on the stack for STOP)
            ops = 3 + len(head) + units * per_unit
            try:
                scan(data)
                refused_after = None
            except CodecError as exc:
                refused_after = str(exc)
            seconds = best(lambda data=data: _quiet_scan(data), args.repeat if size == MB else min(args.repeat, 2))
            decoded = attempt(data)
            shown = "refused" if decoded is None else f"{decoded:.3f}"
            print(
                f"{name:38} {len(data):>10,} {ops:>10,} {seconds:>9.3f} {seconds / ops * 1e9:>6.0f} {'':>9} {shown:>9}"
            )
            if refused_after and "deep" not in name and "BINGET" not in name:
                print(f"  (scan refused: {refused_after})")
    return 0


def _quiet_scan(data: bytes) -> None:
    try:
        scan(data)
    except CodecError:
        pass


if __name__ == "__main__":
    sys.exit(main())
