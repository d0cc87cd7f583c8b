"""ALICA for Python: teams of robots that carry out missions described as data.

``import alica`` needs none of the simulation back-ends (pybullet, OMPL, FCL).
"""

from alica.lang.fact import Fact

__version__ = "0.1.0"

__all__ = ["Fact", "__version__"]
