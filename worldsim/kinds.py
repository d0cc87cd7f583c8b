"""The world's object vocabularies: what kinds of objects and sample containers there are.

Pure data (no pybullet): skills read the sample kinds from here (through
:mod:`alica.worldsim.interface`) to name what they detect, and the world
builds its objects from them (:mod:`alica.worldsim.objects`).
"""

from __future__ import annotations

__all__ = ["OBJECT_KINDS", "SAMPLE_KINDS"]

#: The six IMPERA sample containers: upper and lower section green or red (unordered), middle black or white.
SAMPLE_KINDS: tuple[str, ...] = (
    "green-black-green",
    "green-black-red",
    "red-black-red",
    "green-white-green",
    "green-white-red",
    "red-white-red",
)

#: The ``kind`` values of the world's objects (:class:`~alica.worldsim.objects.WorldObject`).
OBJECT_KINDS: tuple[str, ...] = ("block", "sample", "rock", "table", "collection_point", "terrain")
