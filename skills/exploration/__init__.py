"""Coordinated exploration (IMPERA Section 6.4.1): frontiers, Algorithm 1, the ExploreFrontier skill."""

from __future__ import annotations

from alica.skills.exploration.frontiers import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    FrontierCandidate,
    GainMap,
    coverage,
    extract_frontiers,
    frontier_mask,
    information_gain,
)
from alica.skills.exploration.maps import MapView, current_map

__all__ = [
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "FrontierCandidate",
    "GainMap",
    "MapView",
    "coverage",
    "current_map",
    "extract_frontiers",
    "frontier_mask",
    "information_gain",
]
