"""ALICA for Python: teams of robots that carry out missions described as data.

``import alica`` needs none of the simulation back-ends (pybullet, OMPL, FCL).
"""

from alica.lang.fact import Fact
from alica.lang.skills import ParamSpec, SkillRegistry, SkillSpec

__version__ = "0.1.0"

__all__ = ["Fact", "ParamSpec", "SkillRegistry", "SkillSpec", "__version__"]
