"""The ``alica`` command: validate, show, render and convert plan files; list skills.

``main(argv)`` returns the exit code, so tests call it directly. Library code
raises; only this module turns errors into messages and exit codes.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from alica import __version__
from alica.app.plan_entry import EXIT_INVALID, EXIT_OK, EXIT_USAGE, load_entry, root_plans
from alica.app.skill_options import add_skills_option
from alica.errors import AlicaError, PlanFormatError
from alica.source import Diagnostic

if TYPE_CHECKING:
    from alica.model.library import Document

#: A command whose reader closed the pipe: 128 + SIGPIPE, the status a shell shows for it.
EXIT_BROKEN_PIPE = 141


def _quiet_stdout() -> None:
    """Point standard output at the null device: the interpreter's flush at exit finds no closed pipe."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor (a test's captured stream): nothing is flushed at exit
        pass


def _print_diagnostics(diagnostics: Sequence[Diagnostic]) -> None:
    for d in diagnostics:
        print(d.format(), file=sys.stderr)


def _cmd_validate(args: argparse.Namespace) -> int:
    from alica.app.skill_options import skill_registry
    from alica.io import Loader, plan_files, validate_paths

    files, _ = plan_files(args.paths)
    diagnostics = validate_paths(args.paths, Loader(skills=skill_registry(args)))
    _print_diagnostics(diagnostics)
    errors = sum(1 for d in diagnostics if d.severity == "error")
    if errors:
        bad = len({d.span.file for d in diagnostics})
        print(f"{errors} error(s) in {bad} file(s); {len(files)} file(s) checked", file=sys.stderr)
        return EXIT_INVALID
    if not args.quiet:
        print(f"ok: {len(files)} plan file(s) valid")
    return EXIT_OK


def _cmd_show(args: argparse.Namespace) -> int:
    from alica.app.render import dot_graph, svg, text_tree

    library, entry = load_entry(args.plan)
    try:
        roots = root_plans(library, entry, args.name)
    except KeyError as exc:
        raise AlicaError(str(exc.args[0])) from None
    if not roots:
        raise AlicaError(f"{args.plan} defines no plan, planning problem or behaviour to show")
    if args.format == "text":
        output = "\n\n".join(text_tree(library, r) for r in roots) + "\n"
    else:
        dots = [dot_graph(library, r) for r in roots]
        output = dots[0] if len(dots) == 1 else "".join(dots)
        if args.format == "svg":
            output = svg(dots[0])
    if args.output:
        Path(args.output).write_text(output, encoding="utf-8")
    else:
        sys.stdout.write(output)
    return EXIT_OK


def _output_names(files: Sequence[Path]) -> dict[Path, str]:
    """Each plan file's name in the output: its path below the files' common folder, extension kept.

    ``mission.yaml`` and ``mission.xml``, or ``lunar/mission.yaml`` and
    ``blocksworld/mission.yaml``, get different names, so no file overwrites another's.
    """
    resolved = [Path(os.path.abspath(f)) for f in files]
    if not resolved:
        return {}
    common = Path(os.path.commonpath([r.parent for r in resolved]))
    return {f: r.relative_to(common).as_posix() for f, r in zip(files, resolved, strict=True)}


def _cmd_render(args: argparse.Namespace) -> int:
    import shutil

    from alica.app.render import dot_graph, svg, text_tree
    from alica.io import Loader, plan_files

    found, problems = plan_files(args.paths)
    if problems:
        raise PlanFormatError(problems)
    files = list({Path(os.path.abspath(f)): f for f in found}.values())  # each file once
    names = _output_names(files)
    loader = Loader()
    out = Path(args.out)
    has_dot = shutil.which("dot") is not None
    count = 0
    for path in files:
        library, entry = load_entry(path, loader)
        for root in root_plans(library, entry, None):
            stem = out / f"{names[path]}.{root}"
            stem.parent.mkdir(parents=True, exist_ok=True)
            Path(f"{stem}.txt").write_text(text_tree(library, root) + "\n", encoding="utf-8")
            dot = dot_graph(library, root)
            Path(f"{stem}.dot").write_text(dot, encoding="utf-8")
            if has_dot:
                Path(f"{stem}.svg").write_text(svg(dot), encoding="utf-8")
            count += 1
    kinds = "text, dot and svg" if has_dot else "text and dot (install Graphviz for svg)"
    print(f"rendered {count} plan tree(s) from {len(files)} file(s) as {kinds} into {out}/")
    return EXIT_OK


def _relocated(imports: Sequence[str], source: Path, target: Path) -> list[str]:
    """The imports of a file at ``source`` rewritten for a copy at ``target``: the same files, found from there
    (a shipped plan as ``alica:plans/...``)."""
    from alica.io import import_reference
    from alica.io.plan_paths import is_shipped_name

    src, dst = Path(os.path.abspath(source)).parent, Path(os.path.abspath(target)).parent
    return [
        entry
        if is_shipped_name(entry) or Path(entry).is_absolute() or src == dst
        else import_reference(src / entry, dst)
        for entry in imports
    ]


def _states_named_twice(document: Document) -> list[Diagnostic]:
    """A diagnostic for every state whose plan has another state of its name (also with --no-validate)."""
    problems = []
    for plan in document.plans:
        seen: set[str] = set()
        for state in plan.states:
            if state.name in seen and state.span is not None:
                problems.append(
                    Diagnostic(
                        state.span,
                        f"plan '{plan.name}' has two states named '{state.name}'",
                        "give each state its own name",
                    )
                )
            seen.add(state.name)
    return problems


def _cmd_convert(args: argparse.Namespace) -> int:
    from alica.io import Loader, format_of, plan_path, read_text
    from alica.io.dump import document_data
    from alica.io.loader import parse_text
    from alica.io.xml_write import unwritable_text, write_xml
    from alica.io.yaml_format import write_yaml

    fmt, in_fmt = format_of(args.output), format_of(args.input)
    if fmt is None or in_fmt is None:
        raise AlicaError("convert needs files ending in .yaml, .yml or .xml, e.g. 'alica convert roles.yaml roles.xml'")
    source, target = plan_path(args.input), Path(args.output)
    loader = Loader()
    if not args.no_validate:
        loader.load(source)
    document = loader.document(source)
    twice = _states_named_twice(document)
    if twice:  # each state's transitions are written under it by name: two of one name cannot be written back
        raise PlanFormatError(twice)
    tree, _ = parse_text(source.read_bytes().decode("utf-8-sig"), str(source), in_fmt)
    if fmt == "xml" and tree is not None:
        unwritable = unwritable_text(tree)
        if unwritable:
            raise PlanFormatError(unwritable)
    data = document_data(document, tree)
    imports = _relocated(document.imports, source, target)
    if imports:
        data["imports"] = imports
    text = write_xml(data) if fmt == "xml" else write_yaml(data)
    again, problems = read_text(text, args.output, fmt)
    if problems or again != dataclasses.replace(document, imports=tuple(imports)):
        raise AlicaError(f"internal error: {args.output} would not read back as the same plans; please report this")
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(text, encoding="utf-8")
    moved = sum(a != b for a, b in zip(imports, document.imports, strict=True))
    note = f"; {moved} import(s) rewritten for its folder" if moved else ""
    print(f"wrote {args.output} ({fmt}){note}")
    return EXIT_OK


def _cmd_list_skills(args: argparse.Namespace) -> int:
    from alica.app.skill_options import SHIPPED, skill_registry

    for spec in skill_registry(args):
        caps = f"  [needs {', '.join(sorted(spec.capabilities))}]" if spec.capabilities else ""
        impl = (
            f"  (runs {spec.implementation_name})"
            if spec.implementation is not None
            else "  (no implementation yet: 'alica run --stand-ins' scripts it)"
        )
        origin = f"  (from {spec.origin})" if spec.origin and spec.origin != SHIPPED else ""
        print(f"{spec.name}: {spec.doc}{caps}{impl}{origin}")
        for p in spec.params:
            need = "required" if p.required else f"default {p.default!r}"
            print(f"    {p.name} ({p.type}, {need}){': ' + p.doc if p.doc else ''}")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``alica`` command."""
    parser = argparse.ArgumentParser(
        prog="alica", description="Teams of robots that carry out missions described as data."
    )
    parser.add_argument("--debug", action="store_true", help="show a traceback on internal errors")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    p = sub.add_parser(
        "validate",
        help="check plan files and everything they import",
        description="Check plan files (or every plan file in folders). Exit 0 if valid, 1 if not, 2 on wrong usage. Problems are printed as FILE:LINE:COL: error: message.",
    )
    p.add_argument("paths", nargs="+", metavar="PATH", help="plan files or folders")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing when everything is valid")
    add_skills_option(p)
    p.set_defaults(run=_cmd_validate)

    p = sub.add_parser(
        "show",
        help="print a plan tree",
        description="Print the plan tree of a plan file: plans, entry points, states, transitions, behaviours.",
    )
    p.add_argument("plan", metavar="PLAN", help="a plan file")
    p.add_argument(
        "--format",
        choices=("text", "dot", "svg"),
        default="text",
        help="text (default), Graphviz dot, or SVG (needs Graphviz)",
    )
    p.add_argument("--name", help="show this plan (default: the file's top-level plans)")
    p.add_argument("-o", "--output", help="write to this file instead of standard output")
    p.set_defaults(run=_cmd_show)

    p = sub.add_parser(
        "render",
        help="render every plan tree under folders to text, dot and svg files",
        description="Render the plan trees of every plan file to text and dot files (and SVG when Graphviz is installed): one set of files per plan tree, named FOLDER/FILE.ROOT.txt after the plan file (its folder below the common folder of the inputs, its extension kept) and the tree's root plan.",
    )
    p.add_argument("paths", nargs="+", metavar="PATH", help="plan files or folders")
    p.add_argument("--out", default="build/plans", help="output folder (default build/plans)")
    p.set_defaults(run=_cmd_render)

    p = sub.add_parser(
        "convert",
        help="convert a plan file between YAML and XML",
        description="Convert a plan file between YAML and XML, chosen by the file endings. The input is validated first. "
        "Every value the input wrote is kept (defaults included), and relative imports are rewritten for the output's "
        "folder, so the output imports the same files wherever it is written.",
    )
    p.add_argument("input", metavar="IN")
    p.add_argument("output", metavar="OUT")
    p.add_argument("--no-validate", action="store_true", help="convert without checking references to other files")
    p.set_defaults(run=_cmd_convert)

    p = sub.add_parser(
        "list-skills",
        help="list the registered skills and their parameters",
        description="List every declared skill: the shipped catalogue, installed plug-ins and --skills modules, "
        "with its parameters, where it came from and what implements it.",
    )
    add_skills_option(p)
    p.set_defaults(run=_cmd_list_skills)

    from alica.app.center.cli import add_parser as add_center_parser
    from alica.app.cli_agent import add_parser as add_agent_parser
    from alica.app.cli_demo import add_parser as add_demo_parser
    from alica.app.cli_import import add_parser as add_import_parser
    from alica.app.cli_plan import add_parser as add_plan_parser
    from alica.app.cli_protap import add_parser as add_protap_parser
    from alica.app.cli_run import add_parser as add_run_parser
    from alica.app.cli_skill import add_parser as add_skill_parser
    from alica.app.cli_solve import add_parser as add_solve_parser
    from alica.app.cli_team import add_parser as add_team_parser

    add_run_parser(sub)
    add_agent_parser(sub)
    add_skill_parser(sub)
    add_plan_parser(sub)
    add_solve_parser(sub)
    add_demo_parser(sub)
    add_protap_parser(sub)
    add_center_parser(sub)
    add_import_parser(sub)
    add_team_parser(sub)
    __import__("alica.app.cli_world", fromlist=["add_parser"]).add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``alica`` command; returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return int(exc.code) if isinstance(exc.code, int) else EXIT_USAGE
    try:
        code = int(args.run(args))
        sys.stdout.flush()  # here, so that a reader that went away is noticed below, not at exit
        return code
    except BrokenPipeError:  # `alica ... | head`: the reader has all it wanted; exit quietly, as SIGPIPE would
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except PlanFormatError as exc:
        _print_diagnostics(exc.diagnostics)
        print(f"{len(exc.diagnostics)} problem(s) found", file=sys.stderr)
        return EXIT_INVALID
    except AlicaError as exc:
        print(f"alica: error: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except OSError as exc:
        print(f"alica: error: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except KeyboardInterrupt:
        return 130
    except Exception as exc:  # a bug of ours, not bad input: say so in one line
        if args.debug:
            raise
        print(
            f"alica: internal error: {type(exc).__name__}: {exc} (rerun with --debug for details and please report it)",
            file=sys.stderr,
        )
        return 70


if __name__ == "__main__":
    sys.exit(main())
