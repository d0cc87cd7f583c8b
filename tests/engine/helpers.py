"""Small plan libraries for engine tests, written as YAML text."""

from __future__ import annotations

from pathlib import Path

from alica.engine import EngineConfig, SimulatedTeam, TraceRecorder
from alica.io import load_library
from alica.lang.skill_plugins import default_registry
from alica.lang.skills import ParamSpec
from alica.model import PlanLibrary

ROLES = """
alica: 1
tasks: [Default, Work, Help, Watch]
rolesets:
  - name: Crew
    roles:
      - name: Worker
        priorities: {Default: 0.5, Work: 0.9, Help: 0.4, Watch: 0.1}
      - name: Helper
        priorities: {Default: 0.5, Work: 0.3, Help: 0.8, Watch: 0.2}
      - name: Watcher
        priorities: {Default: 0.5, Work: -1, Help: -1, Watch: 0.9}
"""


def library(tmp_path: Path, plans: str) -> PlanLibrary:
    """Load ``plans`` (YAML text without imports) together with the test roles and skills."""
    (tmp_path / "roles.yaml").write_text(ROLES, encoding="utf-8")
    (tmp_path / "plans.yaml").write_text("alica: 1\nimports: [roles.yaml]\n" + plans, encoding="utf-8")
    skills = default_registry()
    for name in ("Work", "Wait", "Check"):
        skills.declare(name, ParamSpec("duration", "float", required=False, default=0.0), doc=f"test skill {name}")
    return load_library(tmp_path / "plans.yaml", skills=skills)


def team(
    lib: PlanLibrary, plan: str, agents: dict[str, str], skills: dict, **kwargs
) -> tuple[SimulatedTeam, TraceRecorder]:  # type: ignore[type-arg]
    """A simulated team with a trace recorder."""
    recorder = TraceRecorder()
    kwargs.setdefault(
        "config", EngineConfig(frequency=10.0, broadcast_interval=0.1, team_timeout=0.5, assignment_protection=0.3)
    )
    sim = SimulatedTeam(lib, plan, agents, skills=skills, observers=[recorder], **kwargs)
    return sim, recorder


def where(sim: SimulatedTeam, agent: str, depth: int = 0) -> tuple[str | None, str | None]:
    """(entry point, state) of ``agent`` in the plan at ``depth`` (0 = root) of its first branch."""
    node = sim.engines[agent].root
    for _ in range(depth):
        assert node is not None
        node = next(s.node for s in node.slots if s.node is not None)
    assert node is not None
    return node.ep, node.state
