"""The control center: a token-protected web page that replays a trace or draws a plan file.

This first increment serves a recorded trace (``alica center --trace FILE``)
and the plan tree of a plan file (``alica center --plan FILE``). The live view
of a running team and the operator's goal and plan decisions come later.
"""
