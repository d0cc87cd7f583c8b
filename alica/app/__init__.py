"""The application layer: the ``alica`` command and the demos.

It is the only code that wires the layers together: the language, the engine,
the planner (:mod:`alica.prophet`), the skills and the simulated world.
"""
