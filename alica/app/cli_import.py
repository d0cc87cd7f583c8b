"""``alica import-designer``: ALICA Plan Designer files (the C++ engine's JSON) as our plan files.

The library (:mod:`alica.io.designer`) reads, maps and renders; this module
checks the arguments, writes the files and prints the summary or the JSON
report. Exit 0 when every file was imported (notes allowed), 1 when a file
was refused, 2 on wrong usage.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from alica.app.plan_entry import EXIT_INVALID, EXIT_OK, EXIT_USAGE

if TYPE_CHECKING:
    from alica.io.designer import ImportResult, Note

#: Notes shown per construct in the summary without --verbose.
SHOWN_PER_CONSTRUCT = 3


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Add the ``import-designer`` subcommand to the ``alica`` parser."""
    p = sub.add_parser(
        "import-designer",
        help="import ALICA Plan Designer files (the C++ engine's .pml, .beh, .pty, .rst, .tsk, .cnd) as plan files",
        description="Read every ALICA Plan Designer file under SRC_DIR (the C++ ALICA engine's JSON format) and write "
        "our YAML plan files under OUT_DIR, in the designer's folders, with a generated skill catalogue "
        "(skills.yaml) and one predicate per condition written in C++. What has no counterpart is reported as a "
        "note; a file that cannot be imported (bad JSON, a reference to nothing, a cycle) is reported as an error "
        "and not written. Exit 0 when every file was imported (notes allowed), 1 when some file was not, "
        "2 on wrong usage.",
    )
    p.add_argument("src", metavar="SRC_DIR", help="the folder of the designer files (e.g. a package's etc/)")
    p.add_argument("--out", required=True, metavar="OUT_DIR", help="where to write the plan files (created if needed)")
    p.add_argument(
        "--json",
        action="store_true",
        help='print {"files": N, "written": [...], "notes": [...], "errors": [...]} instead of the summary',
    )
    p.add_argument("-v", "--verbose", action="store_true", help="list every note in the summary")
    p.set_defaults(run=_cmd_import)


def _usage(message: str) -> int:
    print(f"alica import-designer: error: {message}", file=sys.stderr)
    return EXIT_USAGE


def _cmd_import(args: argparse.Namespace) -> int:
    from alica.io.designer import discover, import_designer, write_result
    from alica.lang.skill_plugins import default_registry

    src, out = Path(args.src), Path(args.out)
    if not src.exists():
        return _usage(f"SRC_DIR '{src}' does not exist")
    if not src.is_dir():
        return _usage(f"SRC_DIR '{src}' is not a folder")
    if out.exists() and not out.is_dir():
        return _usage(f"OUT_DIR '{out}' is a file, not a folder")
    designer, configs, _ = discover(src)
    if not designer and not configs:
        return _usage(f"no ALICA Plan Designer files (.pml, .beh, .pty, .rst, .tsk, .cnd, .plh) under '{src}'")
    result = import_designer(src, reserved_skills=default_registry().names())
    written = write_result(result, out)
    if args.json:
        report = {
            "files": result.files,
            "written": written,
            "notes": [n.as_json() for n in result.notes],
            "errors": [e.as_json() for e in result.errors],
        }
        print(json.dumps(report, indent=2))
    else:
        _summary(result, src, out, written, verbose=args.verbose)
    return EXIT_OK if result.complete else EXIT_INVALID


def _summary(result: ImportResult, src: Path, out: Path, written: Sequence[str], *, verbose: bool) -> None:
    from alica.io.designer import discover

    designer, configs, others = discover(src)
    refused = {e.file for e in result.errors}
    noted = {n.file for n in result.notes}
    clean = [f for f in designer if f not in refused and f not in noted]
    with_notes = [f for f in designer if f not in refused and f in noted]
    extra = f" and {len(configs) + len(others)} config file(s)" if configs or others else ""
    print(f"read {result.files} designer file(s){extra} from {src}")
    print(
        f"imported {len(clean) + len(with_notes)}: {len(clean)} without notes, {len(with_notes)} with notes; "
        f"refused {len([f for f in designer if f in refused])}"
    )
    print(f"wrote {len(written)} plan file(s) to {out}/ (the skill catalogue is {out}/skills.yaml)")
    groups: dict[str, list[Note]] = {}
    for note in result.notes:
        groups.setdefault(note.construct.value, []).append(note)
    if groups:
        print(f"\n{len(result.notes)} note(s), by construct (each output file's header lists its own):")
    for construct, notes in sorted(groups.items(), key=lambda g: (-len(g[1]), g[0])):
        print(f"  {construct}: {len(notes)}")
        shown = notes if verbose else notes[:SHOWN_PER_CONSTRUCT]
        for note in shown:
            print(f"    {note.format()}")
        if len(shown) < len(notes):
            print(f"    ... and {len(notes) - len(shown)} more (--verbose or --json lists them)")
    if result.errors:
        print(f"\n{len(result.errors)} error(s); these files were not written:", file=sys.stderr)
        for error in result.errors:
            print(f"  {error.format()}", file=sys.stderr)
    if written:
        _validate_hint(out)


def _validate_hint(out: Path) -> None:
    """How to validate the output (a project of its own: its files import each other across its folders)."""
    print(f"\ncheck it with: alica validate {out}")
