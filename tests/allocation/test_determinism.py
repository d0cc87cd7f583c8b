"""The same view gives the same assignment: across agent orders, hash seeds and the docs."""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys

from tests.conftest import ROOT

_SCRIPT = """
import math
from alica.allocation import AllocationProblem, Assignment, allocate
from alica.model import EntryPoint, Plan, Priority, Role, RoleSet, State, UtilityFunction
roles = RoleSet("R", tuple(Role(n, (Priority("x", 0.5), Priority("y", 0.5), Priority("z", 0.25)))
                           for n in ("alpha", "beta", "gamma")))
plan = Plan("P", (EntryPoint("x", "x", "S", 1, 3), EntryPoint("y", "y", "S", 1, math.inf),
                  EntryPoint("z", "z", "S", 0, 2)), (State("S"),),
            utility=UtilityFunction(0.8, similarity_weight=0.2))
agents = tuple(f"robot-{c}" for c in "qwertyuiop")
old = Assignment.of("P", {a: ("x", "y", None)[i % 3] for i, a in enumerate(agents)}, 0.0)
problem = AllocationProblem(agents, {a: ("alpha", "beta", "gamma")[i % 3] for i, a in enumerate(agents)},
                            roles, (plan,), old=old)
print(allocate(problem).assignment)
"""


def _run(seed: str) -> str:
    env = {**os.environ, "PYTHONHASHSEED": seed}
    done = subprocess.run(
        [sys.executable, "-c", _SCRIPT], cwd=ROOT, env=env, capture_output=True, text=True, check=True
    )
    return done.stdout


def test_hash_seed_does_not_change_the_assignment() -> None:
    first = _run("1")
    assert first.startswith("P[")
    assert _run("2") == first == _run("12345")


def test_docs_example_prints_what_it_says() -> None:
    text = (ROOT / "docs" / "allocation.md").read_text(encoding="utf-8")
    block = re.search(r"```python\n(.*?)```", text, re.DOTALL)
    assert block is not None
    code = block.group(1)
    claimed = re.search(r"print\(result\.assignment\)\s+# (.*)", code)
    assert claimed is not None
    out = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)
        with contextlib.redirect_stdout(out):
            exec(compile(code, "docs/allocation.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert out.getvalue().splitlines()[0] == claimed.group(1)
