"""Plan files: YAML and XML, validation, loading and writing.

The usual entry point is :func:`load_library`; ``alica validate`` uses
:func:`validate_paths`.
"""

from alica.io.loader import (
    Loader,
    dump_document,
    format_of,
    load_document,
    load_library,
    plan_files,
    plans_dir,
    read_text,
    validate_paths,
)

__all__ = [
    "Loader",
    "dump_document",
    "format_of",
    "load_document",
    "load_library",
    "plan_files",
    "plans_dir",
    "read_text",
    "validate_paths",
]
