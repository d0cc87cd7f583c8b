"""Big plan files: validation time of one XML element with many attributes and of a YAML file with many tasks.

Two files the reliability review of issue 14 found slow or misleading:

* ``attributes``: ``<alica><task name="T" a0="v" ... /></alica>`` with ``--attributes``
  attributes (10^5 in the issue); every attribute is an unknown key, so every one is
  reported. lxml reads attribute values by walking the element's attribute list, so
  reading all values was quadratic.
* ``tasks``: ``tasks:`` with ``--tasks`` entries (300,000, about 50 MB, in the issue),
  no alias anywhere; it was refused as an alias bomb because the cap counted all values.

Each file is written to a temporary folder and checked with ``Loader().check``;
the table gives the size, the wall time, the number of problems and the first one.

Run: ``.venv/bin/python bench/big_files.py [--attributes 100000] [--tasks 300000]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from alica.io.loader import Loader


def attributes_file(folder: Path, count: int) -> Path:
    """One ``<task>`` with ``count`` attributes."""
    path = folder / "attributes.xml"
    attributes = " ".join(f'a{i}="v{i}"' for i in range(count))
    path.write_text(f'<alica version="1">\n<task name="T" {attributes}/>\n</alica>\n', encoding="utf-8")
    return path


def tasks_file(folder: Path, count: int) -> Path:
    """``count`` tasks with descriptions, no alias."""
    path = folder / "tasks.yaml"
    with path.open("w", encoding="utf-8") as out:
        out.write("alica: 1\ntasks:\n")
        for i in range(count):
            out.write(f"  - name: Task{i}\n    description: task number {i} of a very long task list for the bench\n")
    return path


def measure(path: Path) -> tuple[float, int, str]:
    """Seconds to check ``path``, the number of problems and the first one."""
    start = time.perf_counter()
    _, diagnostics = Loader().check(path)
    seconds = time.perf_counter() - start
    first = diagnostics[0].message if diagnostics else "-"
    return seconds, len(diagnostics), first[:70]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--attributes", type=int, default=100_000, help="attributes of the one XML element")
    parser.add_argument("--tasks", type=int, default=300_000, help="tasks of the YAML file")
    args = parser.parse_args()
    print(f"{'file':<12} {'size':>8} {'MB':>6} {'seconds':>8} {'problems':>9}  first problem")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, make, size in (
            ("attributes", attributes_file, args.attributes),
            ("tasks", tasks_file, args.tasks),
        ):
            path = make(folder, size)
            megabytes = path.stat().st_size / 1e6
            seconds, count, first = measure(path)
            print(f"{name:<12} {size:>8} {megabytes:>6.1f} {seconds:>8.1f} {count:>9}  {first}")
            path.unlink()


if __name__ == "__main__":
    main()
