"""Run a command and write its processes' largest resident set (KB) and its wall seconds to a file.

``python bench/peak_rss.py REPORT -- COMMAND...``: the exit code is the command's. The peak is
``ru_maxrss`` of this process's waited-for descendants (the command, and the processes it waited
for, such as Fast Downward's translator and search), the same measure for every planner.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import time
from pathlib import Path


def main(argv: list[str]) -> int:
    if len(argv) < 3 or argv[1] != "--":
        print("usage: peak_rss.py REPORT -- COMMAND...", file=sys.stderr)
        return 2
    start = time.perf_counter()
    code = subprocess.run(argv[2:], check=False).returncode
    wall = time.perf_counter() - start
    peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    Path(argv[0]).write_text(f"{peak_kb} {wall:.6f}\n", encoding="utf-8")
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
