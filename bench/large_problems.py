"""Large planning problems for the planners' bench (issue 41): seeded, sized well beyond the IPC suite's.

Four classic domains, each problem written against the domain file of the IPC suite
(``ipc/<domain>/domain.pddl``, read in place from the benchmark folder):

* ``gripper``: one robot with two grippers moves ``n`` balls from room A to room B (IPC-1998's
  shape; the optimum is known: ``3n/2 - 1`` moves plus ``2n`` picks and drops for even ``n``).
* ``logistics``: ``n`` packages over ``n / 2`` cities of four places each (one an airport), a
  truck per city and ``max(2, n / 12)`` airplanes, start and goal places drawn at random
  (IPC-2000's shape; 50 packages ground to about 23,000 actions).
* ``miconic``: an elevator serving ``n`` passengers over ``n / 2`` floors, origins and
  destinations drawn at random (IPC-2000's STRIPS elevator).
* ``satellite``: ``n`` satellites with one to three instruments each over three modes and
  ``5 n`` directions, a picture of about half the targets wanted, and some satellites' final
  pointing (IPC-2002's STRIPS shape).

``generate(domain, size, seed)`` gives the problem's text; ``write_set(folder, ...)`` writes a
whole set and returns its problems. The same seed gives the same file.

Run alone to write the default set: ``.venv/bin/python bench/large_problems.py [--out DIR]``.
"""

from __future__ import annotations

import argparse
import random
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from bench.benchmark_sets import add_benchmarks_option, benchmark_set

DOMAIN_FOLDERS = {"gripper": "gripper", "logistics": "logistics00", "miconic": "miconic", "satellite": "satellite"}
"""Each generated domain's folder in the IPC suite (its ``domain.pddl`` is the one the problems use)."""

DEFAULT_SET: tuple[tuple[str, int], ...] = (
    ("gripper", 40),
    ("gripper", 80),
    ("gripper", 120),
    ("logistics", 30),
    ("logistics", 40),
    ("logistics", 50),
    ("logistics", 60),
    ("miconic", 40),
    ("miconic", 60),
    ("miconic", 80),
    ("satellite", 6),
    ("satellite", 8),
    ("satellite", 10),
)
"""The bench's set: (domain, size), each with seeds 0 and 1 (gripper with one; see :func:`write_set`)."""


@dataclass(frozen=True, slots=True)
class LargeProblem:
    """A generated problem: its domain's name, size and seed, and both files."""

    domain: str
    size: int
    seed: int
    domain_file: Path
    problem_file: Path

    @property
    def name(self) -> str:
        """The problem's name in the tables, e.g. ``logistics-50-s0``."""
        return f"{self.domain}-{self.size}-s{self.seed}"


def _facts(facts: Sequence[str], indent: str = "  ") -> str:
    return "\n".join(f"{indent}({fact})" for fact in facts)


def _problem(name: str, domain: str, objects: Sequence[str], init: Sequence[str], goal: Sequence[str]) -> str:
    lines = [f"(define (problem {name})", f" (:domain {domain})", " (:objects"]
    lines += [f"  {' '.join(objects[i : i + 12])}" for i in range(0, len(objects), 12)]
    lines += [" )", " (:init", _facts(init), " )", " (:goal (and", _facts(goal), " ))", ")", ""]
    return "\n".join(lines)


def gripper(n: int, rng: random.Random) -> str:
    """``n`` balls from room A to room B (the seed does not change gripper: it has one shape per size)."""
    balls = [f"ball{i}" for i in range(1, n + 1)]
    init = ["room rooma", "room roomb", "gripper left", "gripper right", "at-robby rooma", "free left", "free right"]
    init += [f"ball {b}" for b in balls] + [f"at {b} rooma" for b in balls]
    goal = [f"at {b} roomb" for b in balls]
    return _problem(f"gripper-{n}", "gripper-strips", ["rooma", "roomb", "left", "right", *balls], init, goal)


def logistics(n: int, rng: random.Random) -> str:
    """``n`` packages over ``n / 2`` cities of four places each (see the module docstring)."""
    n_cities = max(2, n // 2)
    n_planes = max(2, n // 12)
    cities = [f"cit{c}" for c in range(1, n_cities + 1)]
    places: list[str] = []
    init: list[str] = []
    objects: list[str] = list(cities)
    for c, city in enumerate(cities, 1):
        here = [f"apt{c}"] + [f"pos{c}-{k}" for k in range(1, 4)]
        places += here
        init += [f"city {city}", f"airport apt{c}", f"truck tru{c}", f"at tru{c} {rng.choice(here)}"]
        init += [f"location {p}" for p in here] + [f"in-city {p} {city}" for p in here]
        objects += [*here, f"tru{c}"]
    for a in range(1, n_planes + 1):
        objects.append(f"apn{a}")
        init += [f"airplane apn{a}", f"at apn{a} apt{rng.randint(1, n_cities)}"]
    goal: list[str] = []
    for p in range(1, n + 1):
        start, end = rng.sample(places, 2)
        objects.append(f"obj{p}")
        init += [f"package obj{p}", f"at obj{p} {start}"]
        goal.append(f"at obj{p} {end}")
    return _problem(f"logistics-{n}", "logistics", objects, init, goal)


def miconic(n: int, rng: random.Random) -> str:
    """An elevator serving ``n`` passengers over ``max(4, n / 2)`` floors (see the module docstring)."""
    n_floors = max(4, n // 2)
    floors = [f"f{k}" for k in range(n_floors)]
    people = [f"p{k}" for k in range(n)]
    init = [f"floor {f}" for f in floors] + [f"passenger {p}" for p in people]
    init += [f"above {floors[i]} {floors[j]}" for i in range(n_floors) for j in range(i + 1, n_floors)]
    for p in people:
        origin, destination = rng.sample(floors, 2)
        init += [f"origin {p} {origin}", f"destin {p} {destination}"]
    init.append(f"lift-at {rng.choice(floors)}")
    goal = [f"served {p}" for p in people]
    return _problem(f"miconic-{n}", "miconic", [*people, *floors], init, goal)


def satellite(n: int, rng: random.Random) -> str:
    """``n`` satellites, three modes, ``5 n`` directions (see the module docstring)."""
    modes = ["image", "infrared", "spectrograph"]
    directions = [f"star{k}" for k in range(n)] + [f"target{k}" for k in range(4 * n)]
    objects: list[str] = [*modes, *directions]
    init = [f"mode {m}" for m in modes] + [f"direction {d}" for d in directions]
    instrument = 0
    for s in range(n):
        sat = f"sat{s}"
        objects.append(sat)
        init += [f"satellite {sat}", f"power_avail {sat}", f"pointing {sat} {rng.choice(directions)}"]
        for _ in range(rng.randint(1, 3)):
            name = f"inst{instrument}"
            instrument += 1
            objects.append(name)
            init += [
                f"instrument {name}",
                f"on_board {name} {sat}",
                f"calibration_target {name} star{rng.randrange(n)}",
            ]
            init += [f"supports {name} {m}" for m in rng.sample(modes, rng.randint(1, 2))]
    supported = {fact.split()[2] for fact in init if fact.startswith("supports ")}
    goal = [f"have_image {d} {rng.choice(sorted(supported))}" for d in directions[n:] if rng.random() < 0.5]
    goal += [f"pointing sat{s} {rng.choice(directions[n:])}" for s in range(n) if rng.random() < 0.3]
    return _problem(f"satellite-{n}", "satellite", objects, init, goal)


SEEDLESS = frozenset({"gripper"})
"""Domains with one problem per size (the seed changes nothing): written for the first seed only."""

GENERATORS: dict[str, Callable[[int, random.Random], str]] = {
    "gripper": gripper,
    "logistics": logistics,
    "miconic": miconic,
    "satellite": satellite,
}


def generate(domain: str, size: int, seed: int) -> str:
    """The problem file's text: ``domain`` (a key of :data:`GENERATORS`) at ``size`` from ``seed``."""
    return GENERATORS[domain](size, random.Random(f"{domain}-{size}-{seed}"))


def write_set(
    folder: Path,
    ipc: Path,
    sizes: Sequence[tuple[str, int]] = DEFAULT_SET,
    seeds: Sequence[int] = (0, 1),
    domains: Sequence[str] | None = None,
) -> list[LargeProblem]:
    """Write each (domain, size) for each seed below ``folder/<domain>/``; the problems, in that order.

    ``ipc`` is the IPC suite's folder, whose domain files the problems use (read in place).
    ``domains`` keeps only those domains.
    """
    out: list[LargeProblem] = []
    for domain, size in sizes:
        if domains is not None and domain not in domains:
            continue
        domain_file = ipc / DOMAIN_FOLDERS[domain] / "domain.pddl"
        for seed in seeds[:1] if domain in SEEDLESS else seeds:
            path = folder / domain / f"{domain}-{size}-s{seed}.pddl"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(generate(domain, size, seed), encoding="utf-8")
            out.append(LargeProblem(domain, size, seed, domain_file, path))
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "bench" / "large", help="where to write the set")
    add_benchmarks_option(parser)
    args = parser.parse_args(argv)
    for problem in write_set(args.out, benchmark_set(args.benchmarks, "ipc")):
        print(f"{problem.name:<20} {problem.problem_file}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
