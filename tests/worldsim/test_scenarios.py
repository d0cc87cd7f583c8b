"""The blocks world, the lunar field and lunar sites: defaults that run, IPC facts, layout rules, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from alica.worldsim.errors import WorldError
from alica.worldsim.objects import SAMPLE_KINDS
from alica.worldsim.scenarios import blocks_facts, blocksworld, lunar, lunar_sites, sample_names


def test_blocksworld_defaults() -> None:
    with blocksworld() as w:
        assert sorted(w.robots) == ["r1", "r2"]
        assert all(r.spec.kind == "manipulator" for r in w.robots.values())
        assert sorted(n for n, o in w.objects.items() if o.kind == "block") == ["a", "b", "c"]
        assert blocks_facts(w) == {
            ("on", "c", "a"),
            ("ontable", "a"),
            ("ontable", "b"),
            ("clear", "c"),
            ("clear", "b"),
            ("handempty", "r1"),
            ("handempty", "r2"),
        }
        # robots face the row of stacks and stand clear of it
        for r in w.robots.values():
            _x, y, yaw = r.pose
            assert abs(y) > 1.0 and math.cos(yaw - math.atan2(-y, 0.0)) > 0.99


def test_blocks_facts_of_a_three_block_stack() -> None:
    with blocksworld([["c", "b", "a"]], agents=1) as w:
        w.step(1.0)
        assert blocks_facts(w) == {
            ("ontable", "c"),
            ("on", "b", "c"),
            ("on", "a", "b"),
            ("clear", "a"),
            ("handempty", "r1"),
        }


def test_blocks_facts_while_holding() -> None:
    with blocksworld([["a", "b"]], agents=1) as w:
        arm = w.robots["r1"].arm
        top = w.objects["b"]
        # move the top block into the open gripper, then grasp it
        w.client.resetBasePositionAndOrientation(top.body_id, arm.ee_pose()[0].tolist(), (0, 0, 0, 1))
        assert arm.attach(top)
        assert blocks_facts(w) == {("holding", "r1", "b"), ("ontable", "a"), ("clear", "a")}


def test_blocksworld_many_stacks_and_agents() -> None:
    stacks = [["a"], ["b", "c"], ["d", "e", "f"], ["g"]]
    with blocksworld(stacks, agents=5, seed=3, block_size=0.04) as w:
        assert len(w.robots) == 5
        facts = blocks_facts(w)
        assert {("on", "c", "b"), ("on", "f", "e"), ("on", "e", "d"), ("ontable", "g")} <= facts
        assert w.objects["a"].size == 0.04


def test_blocksworld_errors() -> None:
    with pytest.raises(WorldError, match="unique"):
        blocksworld([["a", "b"], ["a"]])
    with pytest.raises(WorldError, match="at least one block"):
        blocksworld([["a"], []])


def test_lunar_defaults() -> None:
    with lunar() as w:
        assert w.bounds == (-20.0, -20.0, 20.0, 20.0)
        assert sorted(w.robots) == ["amparo", "scout", "stummel"]
        kinds = {n: r.spec.kind for n, r in w.robots.items()}
        assert kinds == {"amparo": "amparo", "scout": "scout", "stummel": "stummel"}
        rocks = [o for o in w.objects.values() if o.kind == "rock"]
        assert len(rocks) == 60
        assert all(0.2 <= o.radius <= 1.0 and o.mesh is not None for o in rocks)
        assert w.objects["g"].kind == "collection_point"
        samples = {n: o for n, o in w.objects.items() if o.kind == "sample"}
        assert sorted(samples) == ["a", "b"]
        assert all(o.sample_kind in SAMPLE_KINDS for o in samples.values())
        g = w.objects["g"].position()
        for rock in rocks:
            p = rock.position()
            assert math.hypot(p[0] - g[0], p[1] - g[1]) >= 3.0 + rock.radius
            for s in samples.values():
                assert math.dist(p[:2], s.position()[:2]) >= rock.radius + 0.8
        for r in w.robots.values():
            assert math.hypot(r.pose[0] - g[0], r.pose[1] - g[1]) < 2.0
        # the obstacles the planners get are exactly the rocks
        assert {o.name for o in w.ground_truth_obstacles()} == {o.name for o in rocks}


def test_lunar_is_deterministic_and_seeded() -> None:
    def layout(seed: int) -> list[tuple[str, tuple[float, ...]]]:
        with lunar(seed=seed, rocks=15, samples=3, size=20.0) as w:
            return [(n, tuple(np.round(o.position(), 6))) for n, o in sorted(w.objects.items())]

    assert layout(5) == layout(5)
    assert layout(5) != layout(6)


def test_lunar_sample_names_skip_the_collection_point() -> None:
    assert sample_names(8) == ["a", "b", "c", "d", "e", "f", "h", "i"]
    with lunar(rocks=5, samples=7, size=30.0) as w:
        assert w.objects["g"].kind == "collection_point"
        assert len({o.sample_kind for o in w.objects.values() if o.kind == "sample"}) == 6


def test_lunar_errors() -> None:
    with pytest.raises(WorldError, match="rocks and samples must be >= 0"):
        lunar(rocks=-1)
    with pytest.raises(WorldError, match="size must be at least"):
        lunar(size=5.0)
    with pytest.raises(WorldError, match="could only place"):
        lunar(rocks=500, size=12.0)


def _sites(**overrides: object):
    arguments: dict[str, object] = {
        "bounds": (-6.0, -6.0, 6.0, 6.0),
        "robots": [("r1", "stummel", (-3.0, -2.0, 0.0)), ("r2", "stummel", (2.0, 3.0, math.pi))],
        "samples": [("g1", SAMPLE_KINDS[0], (-3.0, -3.0)), ("g2", SAMPLE_KINDS[1], (3.0, 3.0))],
        "rocks": 6,
        "keep_clear": [(x, y, 1.6) for x in (-3.0, 0.0, 3.0) for y in (-3.0, 0.0, 3.0)],
    }
    arguments.update(overrides)
    return lunar_sites(1, **arguments)  # type: ignore[arg-type]


def test_lunar_sites_put_robots_and_samples_where_asked_and_rocks_clear_of_them() -> None:
    with _sites() as w:
        assert w.bounds == (-6.0, -6.0, 6.0, 6.0)
        assert {n: r.spec.kind for n, r in w.robots.items()} == {"r1": "stummel", "r2": "stummel"}
        assert w.robots["r1"].pose == pytest.approx((-3.0, -2.0, 0.0))
        assert np.allclose(w.objects["g2"].position()[:2], (3.0, 3.0), atol=0.01)
        rocks = [o for o in w.objects.values() if o.kind == "rock"]
        assert len(rocks) == 6
        for rock in rocks:
            x, y = rock.position()[:2]
            assert all(math.hypot(x - cx, y - cy) >= 1.6 + rock.radius - 1e-9 for cx in (-3, 0, 3) for cy in (-3, 0, 3))
            assert all(
                math.hypot(x - r.pose[0], y - r.pose[1]) > r.spec.radius + rock.radius for r in w.robots.values()
            )
        layout = sorted(tuple(np.round(o.position()[:2], 6)) for o in rocks)
    with _sites() as again:
        assert (
            sorted(tuple(np.round(o.position()[:2], 6)) for o in again.objects.values() if o.kind == "rock") == layout
        )


def test_lunar_sites_errors() -> None:
    with pytest.raises(WorldError, match="could only place"):
        _sites(rocks=40, keep_clear=[(0.0, 0.0, 5.5)])
    with pytest.raises(WorldError, match="rocks must be >= 0"):
        _sites(rocks=-1)
    with pytest.raises(WorldError, match="off the field"):
        _sites(robots=[("r1", "stummel", (9.0, 0.0, 0.0))], rocks=0)
    with pytest.raises(WorldError, match="overlap"):
        _sites(robots=[("r1", "stummel", (0.0, 0.0, 0.0)), ("r2", "stummel", (0.2, 0.0, 0.0))], rocks=0)
