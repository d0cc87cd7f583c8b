"""``alica solve``: a plan's constraints solved offline for a team, through the command line."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from alica.app.cli import main
from alica.io.loader import plans_dir

PLANS = plans_dir()
AGENTS = "scout:Scout,stummel:Stummel,s2:Stummel"
EXPLORING = ["--at", "scout=ExploreAfterMapping,stummel=ExploreFrontiers,s2=ExploreFrontiers"]


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def frontier_world(path: Path) -> dict[str, object]:
    """A test map: a 30 m field, explored within 9 m of the origin; frontier cells on the explored edge.

    Frontier cells are free cells next to unknown ones (every 4th, about 1 m apart); a cell's
    information gain is the number of unknown cells within 2 m of it.
    """
    res = 0.25
    n = int(30 / res)
    xs = (np.arange(n) + 0.5) * res - 15.0
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    known = np.hypot(gx + 1.0, gy) < 9.0  # the explored disc, off-centre
    known &= ~((gx > 3.0) & (gy > 3.0))  # a corner left unknown: more gain there
    unknown = ~known
    edge = known & (np.roll(unknown, 1, 0) | np.roll(unknown, -1, 0) | np.roll(unknown, 1, 1) | np.roll(unknown, -1, 1))
    cells = [(i, j) for i, j in zip(*np.nonzero(edge), strict=True)][::4]
    objects, pos, gain = [], {}, {}
    reach = int(2.0 / res)
    for k, (i, j) in enumerate(cells):
        name = f"f{k}"
        objects.append(name)
        pos[name] = [round(float(xs[i]), 3), round(float(xs[j]), 3)]
        window = unknown[max(0, i - reach) : i + reach + 1, max(0, j - reach) : j + reach + 1]
        gain[name] = int(window.sum())
    pos.update({"scout": [0.0, 0.0], "stummel": [-4.0, 2.0], "s2": [2.0, -5.0]})
    world = {"objects": {"Frontier": objects}, "values": {"Pos": pos, "gain": gain}}
    path.write_text(yaml.safe_dump(world), encoding="utf-8")
    return world


def test_the_formation_is_solved_for_the_team(capsys):
    code, out, _ = run(
        capsys,
        "solve",
        str(PLANS / "examples" / "formation.yaml"),
        "--agents",
        "r1:Robot,r2:Robot,r3:Robot,r4:Robot",
        "--json",
    )
    assert code == 0, out
    result = json.loads(out)
    assert result["status"] == "solved" and all(result["satisfied"].values())
    spots = {a: v["spot"] for a, v in result["values"].items() if a}
    centre = result["values"][""]["centre"]
    assert set(spots) == {"r1", "r2", "r3", "r4"}
    for a, b in itertools.combinations(spots, 2):
        assert math.dist(spots[a], spots[b]) >= 1.0 - 1e-9
    assert all(math.dist(p, centre) <= 3.0 + 1e-9 for p in spots.values())
    code, text, _ = run(capsys, "solve", str(PLANS / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot")
    assert code == 0 and "holds: Formation.KeepApart" in text and "r2 [Hold/TakeSpot]: spot = (" in text


def test_eq_7_8_each_explorer_gets_its_best_frontier(capsys, tmp_path):
    world = frontier_world(tmp_path / "map.yaml")
    args = ["solve", str(PLANS / "skills" / "explore.yaml"), "--plan", "Explore", "--agents", AGENTS]
    code, out, _ = run(capsys, *args, *EXPLORING, "--world", str(tmp_path / "map.yaml"), "--json")
    assert code == 0, out
    result = json.loads(out)
    assert result["status"] == "solved" and result["optimal"]
    chosen = {a: v["frontier"] for a, v in result["values"].items() if a}
    pos, gain = world["values"]["Pos"], world["values"]["gain"]  # type: ignore[index]
    for a, b in itertools.combinations(chosen, 2):
        assert math.dist(pos[chosen[a]], pos[chosen[b]]) > 4.0  # Eq. 7
    for a, f in chosen.items():
        assert math.dist(pos[f], pos[a]) < 15.0  # Eq. 8
    # the optimum (summed gain less each robot's travel), by enumeration over the frontiers each robot may take
    robots = sorted(chosen)
    near = {a: [f for f in gain if math.dist(pos[f], pos[a]) < 15.0] for a in robots}
    best = max(
        sum(gain[f] - math.dist(pos[f], pos[a]) for a, f in zip(robots, combo, strict=True))
        for combo in itertools.product(*(near[a] for a in robots))
        if all(math.dist(pos[p], pos[q]) > 4.0 for p, q in itertools.combinations(combo, 2))
    )
    assert result["utility"] == pytest.approx(best)


def test_no_frontier_far_enough_apart_is_infeasible(capsys, tmp_path):
    world = {
        "objects": {"Frontier": ["f1", "f2"]},
        "values": {"Pos": {"f1": [0, 0], "f2": [1, 0], "scout": [0, 0], "stummel": [0, 0]}, "gain": {"f1": 1, "f2": 1}},
    }
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(world), encoding="utf-8")
    args = ["solve", str(PLANS / "skills" / "explore.yaml"), "--agents", "scout:Scout,stummel:Stummel"]
    at = ["--at", "scout=ExploreAfterMapping,stummel=ExploreFrontiers"]
    code, out, _ = run(capsys, *args, *at, "--world", str(tmp_path / "w.yaml"), "--json")
    assert code == 3
    assert json.loads(out)["status"] == "infeasible"


def test_no_solution_within_the_time_limit_exits_4(capsys):
    args = ["solve", str(PLANS / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot,r3:Robot"]
    code, out, _ = run(capsys, *args, "--time-limit", "1e-9", "--json")
    assert code == 4
    assert json.loads(out)["status"] == "timeout"


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--plan", "Nope"], "has no plan named 'Nope'"),
        (["--at", "r9=TakeSpot"], "--at: 'r9' is not one of the agents"),
        (["--at", "r1=Nowhere"], "--at: plan 'Formation' has no state 'Nowhere'"),
        (["--world", "missing.yaml"], "cannot read the world file"),
    ],
)
def test_bad_input_is_a_clear_error(capsys, extra, message):
    args = ["solve", str(PLANS / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot"]
    code, _, err = run(capsys, *args, *extra)
    assert code == 1
    assert message in err and "Traceback" not in err


def test_a_bad_world_file_names_its_line(capsys, tmp_path):
    (tmp_path / "w.yaml").write_text("objects:\n  Frontier: [f1\n", encoding="utf-8")
    args = ["solve", str(PLANS / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot"]
    code, _, err = run(capsys, *args, "--world", str(tmp_path / "w.yaml"))
    assert code == 1 and "w.yaml:3:1: error: not valid YAML" in err


def test_the_formation_runs_and_the_trace_shows_the_solved_spots(capsys, tmp_path):
    trace = tmp_path / "run.jsonl"
    args = ["run", str(PLANS / "examples" / "formation.yaml"), "--agents", "r1:Robot,r2:Robot,r3:Robot"]
    code, out, _ = run(capsys, *args, "--stand-ins", "--trace", str(trace), "--time-limit", "60")
    assert code == 0, out
    events = [json.loads(line) for line in trace.read_text().splitlines()]
    solved = [e for e in events if e["event"] == "solve"]
    assert {e["agent"] for e in solved} == {"r1", "r2", "r3"}
    spots = [{a: v["spot"] for a, v in e["values"].items() if a} for e in solved]
    assert all(s == spots[0] for s in spots)  # every agent computed the same spots
    for a, b in itertools.combinations(sorted(spots[0]), 2):
        assert math.dist(spots[0][a], spots[0][b]) >= 1.0 - 1e-9
