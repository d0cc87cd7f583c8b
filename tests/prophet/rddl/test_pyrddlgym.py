"""pyRDDLGym, an independent RDDL implementation, reads and grounds what write_rddl prints.

pyRDDLGym is a test-only checker (the ``test`` extra); the tests skip, saying
why, when it cannot be imported (as those of the ProTaP domain do).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.prophet.rddl import parse_rddl, read_rddl, write_domain, write_instance, write_non_fluents
from tests.prophet.rddl.test_parse import FULL

DATA = Path(__file__).parent / "data"
pytestmark = pytest.mark.optional
gym = pytest.importorskip(
    "pyRDDLGym", reason="pyRDDLGym cannot be imported; install the 'test' extra to run this check"
)


def test_pyrddlgym_grounds_the_written_paper_files(tmp_path: Path) -> None:
    domain = read_rddl(DATA / "multi_ros_robot_mdp.rddl").domain
    assert domain is not None
    blocks = read_rddl(DATA / "multi_ros_robot_inst_mdp__1.rddl", domain=domain)
    assert blocks.non_fluents is not None and blocks.instance is not None
    domain_path, instance_path = tmp_path / "domain.rddl", tmp_path / "instance.rddl"
    domain_path.write_text(write_domain(domain), encoding="utf-8")
    instance_path.write_text(
        write_non_fluents(blocks.non_fluents) + "\n" + write_instance(blocks.instance), encoding="utf-8"
    )
    env = gym.make(str(domain_path), str(instance_path))
    assert env.horizon == 10
    assert env.max_allowed_actions == 4
    state, _ = env.reset(seed=0)
    assert sorted(name for name, value in state.items() if value) == ["robotAt___r1__x4__y1", "robotAt___r2__x1__y2"]
    # r1 does a2 (cost 1) and goes from (x4, y1) to (x4, y2) (cost 1).
    _, reward, *_ = env.step({"goto___r1__x4__y2": True, "do___r1__a2": True})
    assert reward == pytest.approx(-2.0)


def test_pyrddlgym_reads_the_written_constructs(tmp_path: Path) -> None:
    # pyRDDLGym takes neither sub types of object types nor objects declared in an instance: leave them out here.
    text = (
        FULL.replace("room : cell;", "room : object;")
        .replace("WEIGHT(kitchen)", "WEIGHT(c2)")
        .replace("heat(?r) = Normal(WEIGHT(?r)", "heat(?r) = Normal(1.0")
        .replace("    objects {\n        cell : {c3};\n    };\n", "")
        .replace("~lit(c3)", "~lit(c1)")
    )
    blocks = parse_rddl(text)
    assert blocks.domain is not None and blocks.non_fluents is not None and blocks.instance is not None
    domain_path, instance_path = tmp_path / "domain.rddl", tmp_path / "instance.rddl"
    domain_path.write_text(write_domain(blocks.domain), encoding="utf-8")
    instance_path.write_text(
        write_non_fluents(blocks.non_fluents) + "\n" + write_instance(blocks.instance), encoding="utf-8"
    )
    env = gym.make(str(domain_path), str(instance_path))
    assert env.horizon == 40
    env.reset(seed=0)
    observation, reward, *_ = env.step({})
    assert set(observation) == {"seen___c1", "seen___c2"}
    assert isinstance(float(reward), float)
