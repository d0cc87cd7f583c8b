"""The simulated world (pybullet): robots, objects, terrain, sensors, faults.

Built in its own issue; nothing here is imported by :mod:`alica`.
"""
