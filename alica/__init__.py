"""ALICA for Python: teams of robots that carry out missions described as data.

``import alica`` needs none of the simulation back-ends (pybullet, OMPL, FCL).
"""

__version__ = "0.1.0"
