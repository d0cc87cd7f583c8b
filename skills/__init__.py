"""Robot skills as py_trees behaviours.

Importing this package loads only the skill *declarations* (names and
parameters, :mod:`alica.skills.catalog`), never pybullet or OMPL; implementations
are imported by name when a skill is instantiated. The vocabulary itself
(:class:`ParamSpec`, :class:`SkillRegistry`) lives with the language, in
:mod:`alica.lang.skills`.
"""

from alica.lang.skill_plugins import default_registry
from alica.lang.skills import ParamSpec, SkillRegistry, SkillSpec

__all__ = ["ParamSpec", "SkillRegistry", "SkillSpec", "default_registry"]
