"""The skill registry: declarations readable without the simulation back-ends."""

from __future__ import annotations

import subprocess
import sys

import pytest

from alica.errors import UnknownSkillError
from alica.lang.skill_plugins import default_registry
from alica.lang.skills import ParamSpec, SkillRegistry, SkillSpec


def test_validation_imports_no_simulation_backend() -> None:
    code = (
        "import sys, alica, alica.io, alica.lang, alica.app.cli, skills;"
        "from alica.io import validate_paths; from alica.skills import default_registry; default_registry();"
        "heavy = {'pybullet', 'ompl', 'fcl', 'trimesh', 'py_trees', 'numpy'} & set(sys.modules);"
        "print(sorted(heavy)); sys.exit(1 if heavy else 0)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stdout + done.stderr


def test_catalog_declares_the_issue_skills() -> None:
    registry = default_registry()
    for name in ("MoveToPosition", "Pickup", "Putdown", "Stack", "Unstack", "Explore"):
        assert name in registry
    goal = registry.get("MoveToPosition").param("goal")
    assert goal is not None and goal.required and goal.type == "position"


def test_every_declared_parameter_has_a_known_type() -> None:
    for spec in default_registry():
        assert spec.doc, spec.name
        for p in spec.params:
            if not p.required and p.default is not None:
                value = tuple(p.default) if isinstance(p.default, list) else p.default
                assert p.check(value) is None, (spec.name, p.name)


def test_param_checks() -> None:
    assert ParamSpec("x", "float").check(1) is None
    assert ParamSpec("x", "float").check(True) is not None
    assert ParamSpec("x", "int").check(1.5) is not None
    assert ParamSpec("x", "position").check((1.0, 2.0)) is None
    assert ParamSpec("x", "position").check((1.0,)) is not None
    assert ParamSpec("x", "position").check("pos(a)") is None
    assert ParamSpec("x", "pose").check((1, 2, 0.5)) is None
    assert ParamSpec("x", "object").check("") is not None
    assert ParamSpec("x", "bool").check("$flag") is None


def test_bad_declarations_raise() -> None:
    with pytest.raises(ValueError, match="unknown type"):
        ParamSpec("x", "vector")
    with pytest.raises(ValueError, match="no default"):
        ParamSpec("x", "float", required=True, default=1.0)
    registry = SkillRegistry()
    registry.declare("A")
    with pytest.raises(ValueError, match="already registered"):
        registry.declare("A")
    with pytest.raises(ValueError, match="twice"):
        registry.register(SkillSpec("B", (ParamSpec("x"), ParamSpec("x"))))


def test_unknown_and_unimplemented_skills() -> None:
    registry = SkillRegistry()
    registry.declare("Later")
    registry.declare("Broken", implementation="no_such_module_xyz:Thing")
    with pytest.raises(UnknownSkillError, match="no skill named 'Nope'"):
        registry.get("Nope")
    with pytest.raises(UnknownSkillError, match="no implementation yet"):
        registry.load("Later")
    with pytest.raises(UnknownSkillError, match="cannot be imported"):
        registry.load("Broken")


def test_load_imports_by_name() -> None:
    registry = SkillRegistry()
    registry.declare("Json", implementation="json:dumps")
    import json

    assert registry.load("Json") is json.dumps


def test_load_completes_params_with_the_declared_defaults() -> None:
    seen: list[dict[str, object]] = []

    def build(name: str, params: dict[str, object], context: object) -> str:
        seen.append(dict(params))
        return name

    registry = SkillRegistry()
    registry.declare(
        "Turn",
        ParamSpec("angle", "float"),
        ParamSpec("tolerance", "float", required=False, default=0.05),
        ParamSpec("target", "object", required=False),
        implementation=build,
    )
    factory = registry.load("Turn")
    assert factory("a", {"angle": 1.0}, None) == "a"
    assert factory("b", {"angle": 1.0, "tolerance": 0.2}, None) == "b"
    assert seen == [{"angle": 1.0, "tolerance": 0.05}, {"angle": 1.0, "tolerance": 0.2}]
    registry.declare("Plain", ParamSpec("angle", "float"), implementation=build)
    assert registry.load("Plain") is build  # nothing to complete: the implementation itself
