"""Import ALICA Plan Designer files (the C++ engine's JSON format) as our plan files.

``alica import-designer SRC --out OUT`` runs :func:`import_designer` and
:func:`write_result`. The mapping, what has no counterpart and the notes
users see are described in ``docs/coming_from_cpp.md``.
"""

from alica.io.designer.importer import ImportResult, discover, import_designer, write_result
from alica.io.designer.names import Namespace, sanitize
from alica.io.designer.report import Construct, FileError, Note

__all__ = [
    "Construct",
    "FileError",
    "ImportResult",
    "Namespace",
    "Note",
    "discover",
    "import_designer",
    "sanitize",
    "write_result",
]
