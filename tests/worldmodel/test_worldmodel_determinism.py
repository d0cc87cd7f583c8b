"""The same writes give byte-identical dumps, deltas and digests in every process."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = r"""
from alica.worldmodel import WorldModel

team = [WorldModel(name) for name in ("scout", "rover", "lander")]
scout, rover, lander = team
names = ["alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta"]
for index, name in enumerate(names):
    scout.set("pos", name, value=(index * 0.5, -index))
    rover.assert_fact("found", name) if index % 2 else rover.retract_fact("found", name)
    lander.add_to_set("invalid_candidates", (name, index))
    rover.add_object(name, "Sample")
    lander.add_object(names[-1 - index], "Sample")
deltas = [wm.take_delta() for wm in team]
for wm in team:
    for delta in reversed(deltas):
        wm.merge(delta)
print(repr(deltas[0]))
print([entry.ident for entry in team[0].take_delta().writes])
for wm in team:
    print(wm.dumps())
    print(wm.digest().state_hash, wm.digest().buckets[:8])
    print(wm.objects("Sample"), wm.facts()[:5], sorted(wm.members("invalid_candidates"), key=repr)[:3])
    print(sorted(team[0].merge(team[1].snapshot()) | {k for d in deltas for k in d.sorted_keys()}))
"""


def run(seed: str) -> str:
    env = dict(os.environ, PYTHONHASHSEED=seed, PYTHONPATH=str(ROOT))
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], cwd=ROOT, env=env, capture_output=True, text=True, check=True, timeout=60
    )
    return done.stdout


def test_output_does_not_depend_on_hash_randomisation() -> None:
    outputs = {seed: run(seed) for seed in ("0", "1", "4242")}
    assert outputs["0"] == outputs["1"] == outputs["4242"]
    lines = outputs["0"].splitlines()
    dumps = [line for line in lines if line.startswith("{")]
    assert len(dumps) == 3 and len(set(dumps)) == 1  # all replicas identical too
