"""The same seed gives the same deliveries in another process, whatever PYTHONHASHSEED is."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SCENARIO = """
import hashlib
from alica.clock import ManualClock
from alica.comm import Delay, QoS, SimNetwork

clock = ManualClock()
network = SimNetwork(clock, seed=5, loss=0.2, delay=Delay(0.01, 0.04))
names = [f"robot-{i}" for i in range(8)]
transports = [network.attach(name) for name in names]
for i, transport in enumerate(transports):
    for topic in ("pose", "plan", "task-" + str(i % 3)):
        transport.subscribe(topic)
log = []
for step in range(300):
    for i, transport in enumerate(transports):
        transport.publish("pose", (step, i))
        if step % 5 == i % 5:
            transport.publish("plan", step, QoS.RELIABLE)
            transport.publish("task-" + str(step % 3), step, QoS.RELIABLE)
    if step == 50:
        network.partition([set(names[:3]), {names[5], names[3]}], end=clock.now() + 1.0)
    if step == 120:
        network.crash(names[4], at=clock.now() + 0.3)
    if step == 200:
        network.recover(names[4])
    clock.advance(0.01)
    for transport in transports:
        for e in transport.poll():
            log.append((transport.agent_id, e.sender, e.topic, e.seq, round(clock.now(), 6)))
        log.append(tuple(sorted(transport.peers())))
print(len(log), hashlib.sha256(repr(log).encode()).hexdigest())
"""


def run(hash_seed: str) -> str:
    env = {**os.environ, "PYTHONHASHSEED": hash_seed}
    done = subprocess.run(
        [sys.executable, "-c", SCENARIO], cwd=ROOT, env=env, capture_output=True, text=True, timeout=120, check=True
    )
    return done.stdout.strip()


def test_deliveries_do_not_depend_on_the_hash_seed() -> None:
    first = run("1")
    assert first == run("2024")
    assert int(first.split()[0]) > 10_000
