"""Load plan files: read, follow imports, validate the set, build the library.

A *document set* is an entry file and everything it imports, directly or
not. Names must be unique within a set; different sets may reuse names (the
lunar and blocks-world missions both have a ``Pickup``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from alica.errors import PlanFormatError
from alica.io.build import build_document
from alica.io.fields import Problems
from alica.io.plan_paths import (
    PLAN_PATH_VARIABLE,
    PlanPathError,
    default_search_path,
    import_target,
    plan_path,
    project_root,
    shown,
)
from alica.io.plan_paths import plans_dir as plans_dir  # re-exported: older imports name it here
from alica.io.skill_declarations import declare_skills
from alica.io.tree import Node
from alica.lang import Registry, default_registry
from alica.lang.skill_plugins import default_registry as default_skills
from alica.lang.skills import SkillRegistry
from alica.model import Document, PlanLibrary
from alica.source import Diagnostic, SourceSpan, byte_place

#: File name endings the loader reads, with their format.
FORMATS = {".yaml": "yaml", ".yml": "yaml", ".xml": "xml"}


def format_of(path: str | os.PathLike[str]) -> str | None:
    """``yaml`` or ``xml`` by the file's ending, ``None`` for anything else."""
    return FORMATS.get(Path(path).suffix.lower())


def parse_text(text: str, name: str, fmt: str) -> tuple[Node | None, list[Diagnostic]]:
    """Read plan text of format ``fmt`` (``yaml`` or ``xml``) into a located tree."""
    if fmt == "xml":
        from alica.io.xml_format import read_xml

        return read_xml(text, name)
    from alica.io.yaml_format import read_yaml

    return read_yaml(text, name)


def _build(text: str, name: str, fmt: str) -> tuple[Node | None, Document, list[Diagnostic]]:
    tree, diagnostics = parse_text(text, name, fmt)
    problems = Problems()
    problems.items.extend(diagnostics)
    if tree is None:
        return None, Document(path=name), problems.items
    return tree, build_document(tree, name, problems), problems.items


def read_text(text: str, name: str, fmt: str = "yaml") -> tuple[Document, list[Diagnostic]]:
    """Build one document from text, without following imports or validating the set."""
    _, document, diagnostics = _build(text, name, fmt)
    return document, diagnostics


def _import_nodes(tree: Node | None) -> list[Node]:
    """The entries of a file's ``imports`` section, with their places."""
    section = tree.value.get("imports") if tree is not None and isinstance(tree.value, dict) else None
    if section is None:
        return []
    return section.value if isinstance(section.value, list) else [section]


@dataclass
class _Read:
    document: Document
    diagnostics: list[Diagnostic]
    imports: list[tuple[str, SourceSpan]]


def _inside(path: Path, roots: Iterable[Path]) -> bool:
    return any(path == root or path.is_relative_to(root) for root in roots)


def _bad_character(text: str) -> str | None:
    """The first control character of an import path, shown as ``U+XXXX``."""
    for char in text:
        if ord(char) < 0x20 or 0x7F <= ord(char) < 0xA0:
            return f"U+{ord(char):04X}"
    return None


@dataclass
class Loader:
    """Reads plan files once each and validates document sets.

    Imports are confined: a file may import only files inside the folder of the
    entry file given to :meth:`check` or :meth:`load` (and its subfolders), the
    entry file's project (the nearest folder above it holding ``.alica-project``,
    ``pyproject.toml``, ``.git`` or ``.hg``: ``plans/lunar/mission.yaml`` may import
    ``plans/tasks.yaml``), or a folder of the plan search path (the shipped plans,
    ``alica:plans/...``, among them); anything else is reported at the import,
    without being read. The working folder plays no part.

    Args:
        skills: skill declarations behaviours are checked against, besides the
            skills the plan files declare (:mod:`alica.io.skill_declarations`);
            :meth:`load` adds those to it.
        functions: predicates and functions formulas may call.
        search_path: more folders imports may reach, besides the entry's folder,
            the shipped plans (:func:`plans_dir`) and the folders of the
            ``ALICA_PLAN_PATH`` environment variable (read when the loader is made).
    """

    skills: SkillRegistry = field(default_factory=default_skills)
    functions: Registry = field(default_factory=default_registry)
    search_path: Sequence[str | os.PathLike[str]] = ()
    _cache: dict[Path, _Read] = field(default_factory=dict)
    _roots: list[Path] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._roots = [Path(p).resolve() for p in [*self.search_path, *default_search_path()]]

    def read(self, path: Path) -> _Read:
        """Read and build one file (cached)."""
        path = path.resolve()
        if path in self._cache:
            return self._cache[path]
        name = shown(path)
        fmt = format_of(path)

        def failed(message: str, hint: str) -> _Read:
            result = _Read(Document(path=name), [Diagnostic(SourceSpan(name, 1, 1), message, hint)], [])
            self._cache[path] = result
            return result

        if fmt is None:
            return failed(f"unknown plan file type '{path.suffix}'", "use .yaml, .yml or .xml")
        try:
            text = path.read_bytes().decode("utf-8-sig")
        except OSError as exc:
            return failed(f"cannot read the file: {exc.strerror or exc}", "check the path and its permissions")
        except UnicodeDecodeError as exc:
            data = exc.object if isinstance(exc.object, bytes) else b""
            place = byte_place(data, exc.start, name)
            result = _Read(
                Document(path=name),
                [Diagnostic(place, f"the file is not UTF-8 text (byte 0x{data[exc.start]:02x})", "save it as UTF-8")],
                [],
            )
            self._cache[path] = result
            return result
        tree, document, diagnostics = _build(text, name, fmt)
        imports = [
            (node.value.strip(), node.span)
            for node in _import_nodes(tree)
            if isinstance(node.value, str) and node.value.strip()
        ]
        result = _Read(document, diagnostics, imports)
        self._cache[path] = result
        return result

    def document_set(self, entry: Path) -> tuple[list[Document], list[Diagnostic]]:
        """The entry file's document and every document it imports, with read problems."""
        documents: list[Document] = []
        diagnostics: list[Diagnostic] = []
        seen: set[Path] = set()
        todo = [entry.resolve()]
        project = project_root(todo[0])
        roots = [todo[0].parent, *([project] if project is not None else []), *self._roots]
        while todo:
            path = todo.pop(0)
            if path in seen:
                continue
            seen.add(path)
            read = self.read(path)
            documents.append(read.document)
            diagnostics.extend(read.diagnostics)
            for raw, span in read.imports:
                target, problem = self._target(path, raw, span, roots)
                if target is None:
                    if problem is not None:
                        diagnostics.append(problem)
                    continue
                if not target.is_file():
                    diagnostics.append(
                        Diagnostic(
                            span,
                            f"imported file '{shown(target)}' does not exist",
                            "fix the path; imports are relative to the importing file",
                        )
                    )
                    seen.add(target.resolve())
                elif format_of(target) is None:
                    diagnostics.append(
                        Diagnostic(
                            span,
                            f"imported file '{shown(target)}' is not a plan file",
                            "import .yaml, .yml or .xml files",
                        )
                    )
                else:
                    todo.append(target.resolve())
        return documents, diagnostics

    def _target(
        self, importer: Path, raw: str, span: SourceSpan, roots: list[Path]
    ) -> tuple[Path | None, Diagnostic | None]:
        """The file an import names, or the problem with it (a bad path, or one outside ``roots``)."""
        shown_raw = raw if len(raw) <= 60 else raw[:57] + "..."
        bad = _bad_character(raw)
        if bad is not None:
            return None, Diagnostic(
                span, f"import path holds the control character {bad}", "write the file's path as plain text"
            )
        try:
            target = import_target(importer, raw).resolve()
            target.is_file()
        except PlanPathError as exc:
            return None, Diagnostic(span, f"cannot use import path: {exc}", "fix the path")
        except (OSError, ValueError) as exc:
            reason = (exc.strerror if isinstance(exc, OSError) else None) or str(exc)
            return None, Diagnostic(span, f"cannot use import path '{shown_raw}': {reason}", "fix the path")
        if not _inside(target, roots):
            return None, Diagnostic(
                span,
                f"import '{shown_raw}' is outside the plan folders",
                "import files under the entry file's folder or its project (the folder holding .alica-project, "
                f"pyproject.toml or .git), shipped plans as alica:plans/..., or add a folder to {PLAN_PATH_VARIABLE}",
            )
        return target, None

    def check(self, *entries: str | os.PathLike[str]) -> tuple[list[Document], list[Diagnostic]]:
        """Read and validate the document set of one or more entry files.

        Returns:
            The set's documents (each once) and every problem found.
        """
        from alica.io.validate import Validator

        documents: dict[str, Document] = {}
        diagnostics: list[Diagnostic] = []
        for entry in entries:
            docs, diags = self.document_set(plan_path(entry))
            diagnostics.extend(diags)
            for doc in docs:
                documents.setdefault(doc.path, doc)
        problems = Problems()
        Validator(list(documents.values()), self.skills, self.functions, problems, vocabulary=self.skills.facts).run()
        return list(documents.values()), _unique(diagnostics + problems.items)

    def load(self, *entries: str | os.PathLike[str]) -> PlanLibrary:
        """Load and validate the document set of one or more entry files.

        The skills the set's files declare (``skills:``) are added to
        :attr:`skills`, the registry this loader was given, except names it
        declares in Python: a run that builds its skills from that registry then
        knows them as declared skills without an implementation.

        Raises:
            PlanFormatError: with every problem found, if any.
        """
        documents, diagnostics = self.check(*entries)
        if diagnostics:
            raise PlanFormatError(diagnostics)
        library = PlanLibrary(tuple(documents))
        declare_skills(self.skills, library.skills.values())
        return library

    def document(self, path: str | os.PathLike[str]) -> Document:
        """One file's document, without validating references.

        Raises:
            PlanFormatError: the file cannot be read or has structural problems.
        """
        read = self.read(plan_path(path))
        if read.diagnostics:
            raise PlanFormatError(read.diagnostics)
        return read.document


def _unique(diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
    return sorted(set(diagnostics), key=lambda d: (d.span.file, d.span.line, d.span.column, d.message))


def plan_files(paths: Iterable[str | os.PathLike[str]]) -> tuple[list[Path], list[Diagnostic]]:
    """Expand files and folders into plan files (folders: every .yaml, .yml, .xml below)."""
    files: list[Path] = []
    problems: list[Diagnostic] = []
    for raw in paths:
        try:
            path = plan_path(raw)
        except PlanPathError as exc:
            problems.append(Diagnostic(SourceSpan(os.fspath(raw), 1, 1), str(exc), "check the path"))
            continue
        if path.is_dir():
            files.extend(sorted(p for p in path.rglob("*") if p.is_file() and format_of(p) is not None))
        elif path.is_file():
            files.append(path)
        else:
            problems.append(Diagnostic(SourceSpan(str(raw), 1, 1), "no such file or folder", "check the path"))
    return files, problems


def validate_paths(paths: Iterable[str | os.PathLike[str]], loader: Loader | None = None) -> list[Diagnostic]:
    """Validate every plan file under ``paths``, each as the entry of its document set."""
    loader = loader or Loader()
    files, diagnostics = plan_files(paths)
    for path in files:
        diagnostics.extend(loader.check(path)[1])
    return _unique(diagnostics)


def load_library(
    *paths: str | os.PathLike[str], skills: SkillRegistry | None = None, functions: Registry | None = None
) -> PlanLibrary:
    """Load and validate plan files into a :class:`PlanLibrary`.

    Args:
        paths: entry files (their imports are followed).
        skills: skill declarations; by default the installed plug-ins (the shipped catalogue among them).
            The skills the files declare are added to it (see :meth:`Loader.load`).
        functions: formula predicates and functions; the built-ins by default.

    Raises:
        PlanFormatError: with every problem found.
    """
    loader = Loader(skills or default_skills(), functions or default_registry())
    return loader.load(*paths)


def load_document(path: str | os.PathLike[str]) -> Document:
    """Read one file into a document without validating references.

    Raises:
        PlanFormatError: the file cannot be read or has structural problems.
    """
    return Loader().document(path)


def dump_document(document: Document, fmt: str = "yaml") -> str:
    """A document as YAML or XML text; reading it back gives an equal document."""
    from alica.io.dump import document_data

    data = document_data(document)
    if fmt == "xml":
        from alica.io.xml_format import write_xml

        return write_xml(data)
    from alica.io.yaml_format import write_yaml

    return write_yaml(data)
