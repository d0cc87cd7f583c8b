"""ALICA for Python: teams of robots that carry out missions described as data.

``import alica`` needs none of the simulation back-ends (pybullet, OMPL, FCL),
and loads its public names only when they are first used, so that a command
such as ``alica plan`` starts fast.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from alica.lang.fact import Fact
    from alica.lang.skills import ParamSpec, SkillRegistry, SkillSpec

__version__ = "0.1.0"

_LAZY = {
    "Fact": "alica.lang.fact",
    "ParamSpec": "alica.lang.skills",
    "SkillRegistry": "alica.lang.skills",
    "SkillSpec": "alica.lang.skills",
}

__all__ = ["Fact", "ParamSpec", "SkillRegistry", "SkillSpec", "__version__"]


def __getattr__(name: str) -> object:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'alica' has no attribute '{name}'")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
