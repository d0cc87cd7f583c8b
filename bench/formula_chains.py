"""Parse, evaluate and unparse time of long operator chains: ``python bench/formula_chains.py [N]``."""

from __future__ import annotations

import sys
import time

from alica.lang import FactBase, holds, parse, unparse


def main(count: int = 10_000) -> None:
    """Print the seconds each stage takes on a chain of ``count`` operands per operator."""
    texts = {
        "+": " + ".join(["1"] * count) + " > 0",
        ".attr": "p" + ".x" * count + " == p",
        "<->": " <-> ".join(["true"] * count),
        "not": "not " * count + "true",
    }
    loop: dict[str, object] = {}
    loop["x"] = loop
    for op, text in texts.items():
        start = time.perf_counter()
        node = parse(text)
        parsed = time.perf_counter()
        holds(node, FactBase(), {"p": loop})
        evaluated = time.perf_counter()
        unparse(node)
        done = time.perf_counter()
        print(
            f"{op:6} {count} operands: parse {parsed - start:.3f} s, evaluate {evaluated - parsed:.3f} s, unparse {done - evaluated:.3f} s"
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
