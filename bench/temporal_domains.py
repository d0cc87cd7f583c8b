"""Durative domains written for the temporal bench, with seeded problems of growing size.

Three PDDL 2.1 domains (``:durative-actions``, fixed or function durations, ``at start`` /
``over all`` / ``at end`` conditions), in the spirit of the IPC's temporal tracks but written
here for this bench:

* ``rovers``: rovers drive between waypoints (a travel time per rover and road), take soil and
  rock samples (one store each, emptied by ``drop``), take images, and send the data to the
  lander over one shared channel (``channel-free``, held while a rover sends);
* ``satellite``: satellites slew between directions, switch instruments on (one at a time per
  satellite: ``power-avail``), calibrate on a target and take images in a mode;
* ``blocks``: blocks world with several robots (each with its own handling time), so towers can
  be taken apart and built by several hands at once.

:func:`problem` makes one problem (``size`` robots, rovers or satellites, and goals growing with
it) from a seed; :func:`suite` lists the bench's cases. The same seed gives the same text.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from itertools import pairwise

ROVERS = """(define (domain rovers-time)
  (:requirements :typing :durative-actions)
  (:types rover waypoint objective)
  (:predicates (at ?r - rover ?w - waypoint) (can-traverse ?r - rover ?a ?b - waypoint)
    (equipped-soil ?r - rover) (equipped-rock ?r - rover) (equipped-imaging ?r - rover)
    (store-empty ?r - rover) (store-full ?r - rover)
    (soil-sample ?w - waypoint) (rock-sample ?w - waypoint)
    (have-soil ?r - rover ?w - waypoint) (have-rock ?r - rover ?w - waypoint) (have-image ?r - rover ?o - objective)
    (visible-from ?o - objective ?w - waypoint) (lander-visible ?w - waypoint) (channel-free)
    (communicated-soil ?w - waypoint) (communicated-rock ?w - waypoint) (communicated-image ?o - objective))
  (:functions (travel-time ?r - rover ?a ?b - waypoint))
  (:durative-action navigate
    :parameters (?r - rover ?a ?b - waypoint)
    :duration (= ?duration (travel-time ?r ?a ?b))
    :condition (and (at start (at ?r ?a)) (over all (can-traverse ?r ?a ?b)))
    :effect (and (at start (not (at ?r ?a))) (at end (at ?r ?b))))
  (:durative-action sample-soil
    :parameters (?r - rover ?w - waypoint)
    :duration (= ?duration 10)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (equipped-soil ?r))
                    (at start (soil-sample ?w)) (at start (store-empty ?r)))
    :effect (and (at start (not (store-empty ?r))) (at start (not (soil-sample ?w)))
                 (at end (store-full ?r)) (at end (have-soil ?r ?w))))
  (:durative-action sample-rock
    :parameters (?r - rover ?w - waypoint)
    :duration (= ?duration 8)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (equipped-rock ?r))
                    (at start (rock-sample ?w)) (at start (store-empty ?r)))
    :effect (and (at start (not (store-empty ?r))) (at start (not (rock-sample ?w)))
                 (at end (store-full ?r)) (at end (have-rock ?r ?w))))
  (:durative-action drop
    :parameters (?r - rover)
    :duration (= ?duration 1)
    :condition (at start (store-full ?r))
    :effect (and (at start (not (store-full ?r))) (at end (store-empty ?r))))
  (:durative-action take-image
    :parameters (?r - rover ?o - objective ?w - waypoint)
    :duration (= ?duration 7)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (equipped-imaging ?r))
                    (at start (visible-from ?o ?w)))
    :effect (at end (have-image ?r ?o)))
  (:durative-action communicate-soil
    :parameters (?r - rover ?s ?w - waypoint)
    :duration (= ?duration 10)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (have-soil ?r ?s))
                    (at start (lander-visible ?w)) (at start (channel-free)))
    :effect (and (at start (not (channel-free))) (at end (channel-free)) (at end (communicated-soil ?s))))
  (:durative-action communicate-rock
    :parameters (?r - rover ?s ?w - waypoint)
    :duration (= ?duration 10)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (have-rock ?r ?s))
                    (at start (lander-visible ?w)) (at start (channel-free)))
    :effect (and (at start (not (channel-free))) (at end (channel-free)) (at end (communicated-rock ?s))))
  (:durative-action communicate-image
    :parameters (?r - rover ?o - objective ?w - waypoint)
    :duration (= ?duration 15)
    :condition (and (at start (at ?r ?w)) (over all (at ?r ?w)) (at start (have-image ?r ?o))
                    (at start (lander-visible ?w)) (at start (channel-free)))
    :effect (and (at start (not (channel-free))) (at end (channel-free)) (at end (communicated-image ?o)))))
"""

SATELLITE = """(define (domain satellite-time)
  (:requirements :typing :durative-actions :equality :negative-preconditions)
  (:types satellite direction instrument mode)
  (:predicates (on-board ?i - instrument ?s - satellite) (supports ?i - instrument ?m - mode)
    (pointing ?s - satellite ?d - direction) (power-avail ?s - satellite) (power-on ?i - instrument)
    (calibrated ?i - instrument) (have-image ?d - direction ?m - mode)
    (calibration-target ?i - instrument ?d - direction))
  (:functions (slew-time ?a ?b - direction) (calibration-time ?i - instrument))
  (:durative-action turn-to
    :parameters (?s - satellite ?to ?from - direction)
    :duration (= ?duration (slew-time ?from ?to))
    :condition (and (at start (pointing ?s ?from)) (at start (not (= ?to ?from))))
    :effect (and (at start (not (pointing ?s ?from))) (at end (pointing ?s ?to))))
  (:durative-action switch-on
    :parameters (?i - instrument ?s - satellite)
    :duration (= ?duration 2)
    :condition (and (at start (on-board ?i ?s)) (at start (power-avail ?s)))
    :effect (and (at start (not (power-avail ?s))) (at end (power-on ?i)) (at end (not (calibrated ?i)))))
  (:durative-action switch-off
    :parameters (?i - instrument ?s - satellite)
    :duration (= ?duration 1)
    :condition (and (at start (on-board ?i ?s)) (at start (power-on ?i)))
    :effect (and (at start (not (power-on ?i))) (at end (power-avail ?s))))
  (:durative-action calibrate
    :parameters (?s - satellite ?i - instrument ?d - direction)
    :duration (= ?duration (calibration-time ?i))
    :condition (and (at start (on-board ?i ?s)) (at start (calibration-target ?i ?d)) (at start (pointing ?s ?d))
                    (at start (power-on ?i)) (over all (pointing ?s ?d)) (over all (power-on ?i)))
    :effect (at end (calibrated ?i)))
  (:durative-action take-image
    :parameters (?s - satellite ?d - direction ?i - instrument ?m - mode)
    :duration (= ?duration 7)
    :condition (and (at start (calibrated ?i)) (at start (on-board ?i ?s)) (at start (supports ?i ?m))
                    (at start (power-on ?i)) (at start (pointing ?s ?d))
                    (over all (calibrated ?i)) (over all (power-on ?i)) (over all (pointing ?s ?d)))
    :effect (at end (have-image ?d ?m))))
"""

BLOCKS = """(define (domain blocks-robots)
  (:requirements :typing :durative-actions)
  (:types robot block)
  (:predicates (on ?x ?y - block) (ontable ?x - block) (clear ?x - block)
    (handempty ?r - robot) (holding ?r - robot ?x - block))
  (:functions (handling-time ?r - robot))
  (:durative-action pick-up
    :parameters (?r - robot ?x - block)
    :duration (= ?duration (handling-time ?r))
    :condition (and (at start (clear ?x)) (at start (ontable ?x)) (at start (handempty ?r)))
    :effect (and (at start (not (clear ?x))) (at start (not (ontable ?x))) (at start (not (handempty ?r)))
                 (at end (holding ?r ?x))))
  (:durative-action put-down
    :parameters (?r - robot ?x - block)
    :duration (= ?duration (handling-time ?r))
    :condition (at start (holding ?r ?x))
    :effect (and (at start (not (holding ?r ?x))) (at end (ontable ?x)) (at end (clear ?x)) (at end (handempty ?r))))
  (:durative-action stack
    :parameters (?r - robot ?x ?y - block)
    :duration (= ?duration (handling-time ?r))
    :condition (and (at start (holding ?r ?x)) (at start (clear ?y)))
    :effect (and (at start (not (holding ?r ?x))) (at start (not (clear ?y)))
                 (at end (on ?x ?y)) (at end (clear ?x)) (at end (handempty ?r))))
  (:durative-action unstack
    :parameters (?r - robot ?x ?y - block)
    :duration (= ?duration (handling-time ?r))
    :condition (and (at start (on ?x ?y)) (at start (clear ?x)) (at start (handempty ?r)))
    :effect (and (at start (not (on ?x ?y))) (at start (not (clear ?x))) (at start (not (handempty ?r)))
                 (at end (holding ?r ?x)) (at end (clear ?y)))))
"""

DOMAINS: dict[str, str] = {"rovers": ROVERS, "satellite": SATELLITE, "blocks": BLOCKS}
"""Domain name -> its PDDL text."""

DEFAULT_SIZES: tuple[int, ...] = (2, 3, 4, 6)
"""Robots (rovers, satellites) per problem in the bench's default suite."""


@dataclass(frozen=True, slots=True)
class Case:
    """One bench problem: its domain, size and seed, and the two PDDL texts."""

    domain: str
    size: int
    seed: int
    domain_text: str
    problem_text: str

    @property
    def name(self) -> str:
        """``rovers-3`` (the domain and the size)."""
        return f"{self.domain}-{self.size}"


def problem(domain: str, size: int, seed: int = 0) -> str:
    """The PDDL text of a problem of ``domain`` with ``size`` agents (see the module docstring).

    Raises:
        KeyError: an unknown domain.
    """
    rng = random.Random(f"{domain}-{size}-{seed}")
    return {"rovers": _rovers, "satellite": _satellite, "blocks": _blocks}[domain](size, rng)


def suite(
    sizes: tuple[int, ...] = DEFAULT_SIZES, domains: tuple[str, ...] = tuple(DOMAINS), seed: int = 0
) -> list[Case]:
    """The bench's cases: each domain at each size."""
    return [Case(d, n, seed, DOMAINS[d], problem(d, n, seed)) for d in domains for n in sizes]


def _text(name: str, domain: str, objects: dict[str, list[str]], init: list[str], goal: list[str]) -> str:
    typed = "\n    ".join(f"{' '.join(names)} - {kind}" for kind, names in objects.items() if names)
    facts = "\n    ".join(init)
    goals = "\n    ".join(goal)
    return (
        f"(define (problem {name}) (:domain {domain})\n  (:objects\n    {typed})\n  (:init\n    {facts})\n"
        f"  (:goal (and\n    {goals}))\n  (:metric minimize (total-time)))\n"
    )


def _rovers(size: int, rng: random.Random) -> str:
    rovers = [f"rover{i}" for i in range(size)]
    points = [f"w{i}" for i in range(size + 3)]
    objectives = [f"o{i}" for i in range(max(1, size // 2))]
    roads: set[tuple[str, str]] = set()
    for i in range(1, len(points)):  # a random tree, then a few more roads
        j = rng.randrange(i)
        roads |= {(points[i], points[j]), (points[j], points[i])}
    for _ in range(len(points) // 2):
        a, b = rng.sample(points, 2)
        roads |= {(a, b), (b, a)}
    lengths = {road: rng.randint(3, 12) for road in sorted(roads) if road[0] < road[1]}
    init = ["(channel-free)"]
    for k, r in enumerate(rovers):
        init += [f"(at {r} {rng.choice(points)})", f"(store-empty {r})"]
        kinds = {kind for kind in ("soil", "rock", "imaging") if rng.random() < 0.6}
        if k < 3 or not kinds:  # the first rovers cover every kind
            kinds.add(("soil", "rock", "imaging")[k % 3])
        init += [f"(equipped-{kind} {r})" for kind in sorted(kinds)]
        speed = rng.choice((1.0, 1.5, 2.0))
        for a, b in sorted(roads):
            length = lengths[(a, b) if a < b else (b, a)]
            init += [f"(can-traverse {r} {a} {b})", f"(= (travel-time {r} {a} {b}) {length * speed:g})"]
    soil = sorted(rng.sample(points, max(1, len(points) // 2)))
    rock = sorted(rng.sample(points, max(1, len(points) // 2)))
    init += [f"(soil-sample {w})" for w in soil] + [f"(rock-sample {w})" for w in rock]
    init += [f"(lander-visible {w})" for w in sorted(rng.sample(points, 2))]
    for o in objectives:
        init += [f"(visible-from {o} {w})" for w in sorted(rng.sample(points, 2))]
    if not any(fact.startswith("(equipped-imaging") for fact in init):  # fewer than three rovers
        init.append(f"(equipped-imaging {rovers[-1]})")
    wanted = [f"(communicated-soil {w})" for w in soil] + [f"(communicated-rock {w})" for w in rock]
    wanted += [f"(communicated-image {o})" for o in objectives]
    goal = sorted(rng.sample(wanted, min(len(wanted), size + 1)))
    objects = {"rover": rovers, "waypoint": points, "objective": objectives}
    return _text(f"rovers-{size}", "rovers-time", objects, init, goal)


def _satellite(size: int, rng: random.Random) -> str:
    sats = [f"sat{i}" for i in range(size)]
    directions = [f"d{i}" for i in range(size + 4)]
    modes = ["thermal", "infrared", "spectrograph"]
    init: list[str] = []
    instruments: list[str] = []
    supported: set[str] = set()
    for s in sats:
        init += [f"(pointing {s} {rng.choice(directions)})", f"(power-avail {s})"]
        for k in range(rng.choice((1, 2))):
            i = f"{s}-i{k}"
            instruments.append(i)
            kinds = sorted(rng.sample(modes, rng.choice((1, 2))))
            supported |= set(kinds)
            init += [f"(on-board {i} {s})", f"(calibration-target {i} {rng.choice(directions)})"]
            init += [f"(supports {i} {m})" for m in kinds]
            init.append(f"(= (calibration-time {i}) {rng.randint(3, 8)})")
    for a in directions:
        for b in directions:
            if a < b:
                t = rng.randint(5, 20)
                init += [f"(= (slew-time {a} {b}) {t})", f"(= (slew-time {b} {a}) {t})"]
    pairs = [f"(have-image {d} {m})" for d in directions for m in sorted(supported)]
    goal = sorted(rng.sample(pairs, min(len(pairs), 2 * size)))
    objects = {"satellite": sats, "instrument": instruments, "mode": modes, "direction": directions}
    return _text(f"satellite-{size}", "satellite-time", objects, init, goal)


def _towers(blocks: list[str], rng: random.Random) -> list[list[str]]:
    order = blocks[:]
    rng.shuffle(order)
    towers: list[list[str]] = []
    for b in order:
        if towers and rng.random() < 0.6:
            rng.choice(towers).append(b)
        else:
            towers.append([b])
    return towers


def _blocks(size: int, rng: random.Random) -> str:
    robots = [f"robot{i}" for i in range(size)]
    blocks = [f"b{i}" for i in range(2 * size + 2)]
    init = [f"(handempty {r})" for r in robots]
    init += [f"(= (handling-time {r}) {rng.choice((1, 1.5, 2, 3))})" for r in robots]
    for tower in _towers(blocks, rng):
        init.append(f"(ontable {tower[0]})")
        init += [f"(on {above} {below})" for below, above in pairwise(tower)]
        init.append(f"(clear {tower[-1]})")
    goal: list[str] = []
    for tower in _towers(blocks, rng):
        goal += [f"(on {above} {below})" for below, above in pairwise(tower)]
    if not goal:
        goal = [f"(on {blocks[0]} {blocks[1]})"]
    return _text(f"blocks-{size}", "blocks-robots", {"robot": robots, "block": blocks}, init, sorted(goal))


__all__ = ["DEFAULT_SIZES", "DOMAINS", "Case", "problem", "suite"]
