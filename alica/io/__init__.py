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
    read_text,
    validate_paths,
)
from alica.io.plan_paths import PlanPathError, import_reference, plan_path, plans_dir

__all__ = [
    "Loader",
    "PlanPathError",
    "dump_document",
    "format_of",
    "import_reference",
    "load_document",
    "load_library",
    "plan_files",
    "plan_path",
    "plans_dir",
    "read_text",
    "validate_paths",
]
