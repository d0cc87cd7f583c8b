"""Planning cost on large inputs: parse times of wide domains, and ``alica plan`` under its limits.

Cases (each in a fresh process with a wall timeout; peak memory is that process's
``ru_maxrss`` from ``os.wait4``, the resource usage of that child alone):

* ``predicates``: a domain declaring 20,000 predicates (parse the domain);
* ``parameters``: one action with 20,000 parameters (parse the domain);
* ``actions``: 20,000 actions (parse the domain);
* ``objects``: a blocks-world problem with 10^5 blocks (parse domain and problem);
* ``plan-10^5``: ``alica plan DOMAIN PROBLEM --time-limit 10`` on that problem (its grounding
  has 10^10 actions: the limit must end it, exit 4);
* ``plan-10^5-time``: the same with ``--memory-limit 4000``, so that the time limit ends it;
* ``plan-10^5-mem``: ``--time-limit 60 --memory-limit 500``.

Before the fixes (at commit 6d4e984, which added this bench): predicates 4.5 s, parameters 3.0 s, actions 7.1 s,
objects 1.4 s; ``plan-10^5`` was still grounding when killed at 285 s, at 23.6 GB.

Run: ``.venv/bin/python bench/planning_limits.py [--timeout 120] [--cases a,b]``; prints a markdown
table (case, wall s, peak MB, exit code, last stderr line).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
N_WIDE = 20_000
N_OBJECTS = 100_000

BLOCKS_DOMAIN = """(define (domain blocks)
  (:requirements :strips)
  (:predicates (on ?x ?y) (ontable ?x) (clear ?x) (handempty) (holding ?x))
  (:action pick-up :parameters (?x)
    :precondition (and (clear ?x) (ontable ?x) (handempty))
    :effect (and (not (ontable ?x)) (not (clear ?x)) (not (handempty)) (holding ?x)))
  (:action put-down :parameters (?x)
    :precondition (holding ?x)
    :effect (and (not (holding ?x)) (clear ?x) (handempty) (ontable ?x)))
  (:action stack :parameters (?x ?y)
    :precondition (and (holding ?x) (clear ?y))
    :effect (and (not (holding ?x)) (not (clear ?y)) (clear ?x) (handempty) (on ?x ?y)))
  (:action unstack :parameters (?x ?y)
    :precondition (and (on ?x ?y) (clear ?x) (handempty))
    :effect (and (holding ?x) (clear ?y) (not (clear ?x)) (not (handempty)) (not (on ?x ?y)))))
"""


def wide_predicates(n: int) -> str:
    """A domain with ``n`` predicates and one action."""
    preds = " ".join(f"(p{i} ?x)" for i in range(n))
    return f"(define (domain wide) (:predicates {preds}) (:action a :parameters (?x) :precondition (p0 ?x) :effect (p1 ?x)))"


def wide_parameters(n: int) -> str:
    """A domain with one action of ``n`` parameters."""
    params = " ".join(f"?v{i}" for i in range(n))
    return f"(define (domain wide) (:predicates (p ?x)) (:action a :parameters ({params}) :precondition (p ?v0) :effect (not (p ?v1))))"


def wide_actions(n: int) -> str:
    """A domain with ``n`` actions."""
    actions = " ".join(
        f"(:action a{i} :parameters (?x) :precondition (p ?x) :effect (and (q ?x) (not (p ?x))))" for i in range(n)
    )
    return f"(define (domain wide) (:predicates (p ?x) (q ?x)) {actions})"


def blocks_problem(n: int) -> str:
    """``n`` blocks on the table; the goal stacks the first two."""
    objects = " ".join(f"b{i}" for i in range(n))
    init = " ".join(f"(ontable b{i}) (clear b{i})" for i in range(n))
    return f"(define (problem big) (:domain blocks) (:objects {objects}) (:init (handempty) {init}) (:goal (on b0 b1)))"


PARSE = """
import sys
from alica.prophet.pddl import read_domain, read_problem
domain = read_domain(sys.argv[1])
if len(sys.argv) > 2:
    read_problem(sys.argv[2], domain)
"""


def cases(folder: Path) -> dict[str, list[str]]:
    """Every case's command line, its files written into ``folder``."""
    files = {
        "predicates.pddl": wide_predicates(N_WIDE),
        "parameters.pddl": wide_parameters(N_WIDE),
        "actions.pddl": wide_actions(N_WIDE),
        "blocks.pddl": BLOCKS_DOMAIN,
        "big.pddl": blocks_problem(N_OBJECTS),
    }
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    py = [sys.executable, "-c", PARSE]
    plan = [sys.executable, "-m", "alica.app.cli", "plan", str(folder / "blocks.pddl"), str(folder / "big.pddl")]
    return {
        "predicates": [*py, str(folder / "predicates.pddl")],
        "parameters": [*py, str(folder / "parameters.pddl")],
        "actions": [*py, str(folder / "actions.pddl")],
        "objects": [*py, str(folder / "blocks.pddl"), str(folder / "big.pddl")],
        "plan-10^5": [*plan, "--time-limit", "10"],
        "plan-10^5-time": [*plan, "--time-limit", "10", "--memory-limit", "4000"],
        "plan-10^5-mem": [*plan, "--time-limit", "60", "--memory-limit", "500"],
    }


SAFETY_CAP_MB = 6000
"""An address-space cap on every case (a safety net for the machine, not the limit under test)."""


def _cap_memory() -> None:
    cap = SAFETY_CAP_MB * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def run(command: list[str], timeout: float) -> tuple[float, float, str, str]:
    """Wall seconds, peak MB, exit code (or 'timeout') and the last stderr line of one process."""
    start = time.perf_counter()
    with (
        tempfile.TemporaryFile("w+") as err,
        subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err, cwd=ROOT) as proc,
    ):
        proc.returncode = 0  # reaped here with os.wait4 (its own rusage), not by Popen
        code = "timeout"
        usage = None
        while time.perf_counter() - start < timeout:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                code = str(os.waitstatus_to_exitcode(status))
                break
            time.sleep(0.02)
        else:
            proc.kill()
            _, _, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
        err.seek(0)
        lines = [line for line in err.read().splitlines() if line.strip()]
    peak = usage.ru_maxrss / 1024 if usage is not None else float("nan")  # Linux: KiB
    return wall, peak, code, lines[-1][:100] if lines else ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=120.0, help="wall seconds per case (default 120)")
    parser.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        table = cases(Path(tmp))
        chosen = [c for c in args.cases.split(",") if c] or list(table)
        print("| case | wall s | peak MB | exit | stderr (last line) |")
        print("|---|---:|---:|---|---|")
        for name in chosen:
            wall, peak, code, err = run(table[name], args.timeout)
            err = err.replace(tmp, "TMP")
            print(f"| {name} | {wall:.2f} | {peak:.0f} | {code} | {err} |", flush=True)


if __name__ == "__main__":
    main()
