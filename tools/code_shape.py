"""The shape of the library code: the figures a maintainer's review looks at (issue 36).

Prints, for the library's packages (``alica/``, ``prophet/``, ``skills/``, ``worldsim/``;
not tests, bench or tools):

- lines, and the largest modules;
- classes with more than 25 methods, and the largest classes;
- functions longer than 80 lines;
- ``Any`` per 1000 lines (the name ``Any`` used in code, imports not counted);
- ``getattr(`` calls;
- import cycles among the modules of one package longer than a pair.

Usage: ``python tools/code_shape.py [ROOT] [--top N]`` (ROOT: a checkout, default this one).
"""

from __future__ import annotations

import argparse
import ast
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

PACKAGES = {"alica": "alica", "prophet": "alica.prophet", "skills": "alica.skills", "worldsim": "alica.worldsim"}


@dataclass
class Shape:
    lines: dict[str, int] = field(default_factory=dict)
    classes: list[tuple[int, str]] = field(default_factory=list)
    functions: list[tuple[int, str]] = field(default_factory=list)
    any_uses: int = 0
    getattrs: int = 0
    imports: dict[str, set[str]] = field(default_factory=lambda: defaultdict(set))


def _module_name(root: Path, path: Path) -> str:
    top, *rest = path.relative_to(root).with_suffix("").parts
    parts = [PACKAGES[top], *rest]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _measure(root: Path, path: Path, shape: Shape) -> None:
    text = path.read_text(encoding="utf-8")
    tree = ast.parse(text)
    name = _module_name(root, path)
    shape.lines[name] = len(text.splitlines())
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef):
            methods = [n for n in node.body if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]
            shape.classes.append((len(methods), f"{name}.{node.name}"))
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = (node.end_lineno or node.lineno) - node.lineno + 1
            shape.functions.append((length, f"{name}:{node.name}"))
        elif isinstance(node, ast.Name) and node.id == "Any":
            shape.any_uses += 1
        elif isinstance(node, ast.Attribute) and node.attr == "Any":
            shape.any_uses += 1
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr":
            shape.getattrs += 1
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            shape.imports[name].add(node.module)
        elif isinstance(node, ast.Import):
            shape.imports[name].update(a.name for a in node.names)


def measure(root: Path) -> Shape:
    shape = Shape()
    for top in PACKAGES:
        for path in sorted((root / top).rglob("*.py")):
            if "__pycache__" not in path.parts:
                _measure(root, path, shape)
    return shape


def cycles(shape: Shape) -> list[list[str]]:
    """Strongly connected groups of more than two modules that import each other within one package."""
    modules = set(shape.lines)
    edges = {
        m: {t for t in shape.imports.get(m, ()) if t in modules and t.rpartition(".")[0] == m.rpartition(".")[0]}
        for m in modules
    }
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    groups: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 2:
                groups.append(sorted(group))

    for v in sorted(modules):
        if v not in index:
            visit(v)
    return groups


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default=str(Path(__file__).resolve().parent.parent))
    parser.add_argument("--top", type=int, default=5)
    args = parser.parse_args()
    shape = measure(Path(args.root))
    total = sum(shape.lines.values())
    print(f"{'figure':48} value")
    print(f"{'lines of library code':48} {total}")
    print(f"{'modules':48} {len(shape.lines)}")
    print(f"{'largest module (lines)':48} {max(shape.lines.values())}")
    print(f"{'modules over 800 lines':48} {sum(n > 800 for n in shape.lines.values())}")
    print(f"{'classes over 25 methods':48} {sum(n > 25 for n, _ in shape.classes)}")
    print(f"{'classes over 30 methods':48} {sum(n > 30 for n, _ in shape.classes)}")
    print(f"{'functions over 80 lines':48} {sum(n > 80 for n, _ in shape.functions)}")
    print(f"{'Any uses':48} {shape.any_uses} ({1000 * shape.any_uses / total:.1f} per 1000 lines)")
    print(f"{'getattr( calls':48} {shape.getattrs}")
    groups = cycles(shape)
    print(f"{'import cycles of more than two modules':48} {len(groups)}")
    print(f"\nlargest modules (top {args.top}):")
    for name, n in sorted(shape.lines.items(), key=lambda kv: -kv[1])[: args.top]:
        print(f"  {n:6d}  {name}")
    print(f"largest classes by methods (top {args.top}):")
    for n, name in sorted(shape.classes, reverse=True)[: args.top]:
        print(f"  {n:6d}  {name}")
    for group in groups:
        print(f"cycle: {' <-> '.join(group)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
