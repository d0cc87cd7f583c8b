"""Robot skills as py_trees behaviours.

Importing this package loads only the skill *declarations* (names and
parameters, :mod:`alica.skills.catalog`), never pybullet or OMPL; implementations
are imported by name when a skill is instantiated.
"""

from alica.skills.registry import ParamSpec, SkillRegistry, SkillSpec, default_registry

__all__ = ["ParamSpec", "SkillRegistry", "SkillSpec", "default_registry"]
