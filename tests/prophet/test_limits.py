"""Bounded planning cost: the deadline and the memory bound over reading, grounding and search; linear reading.

No test times anything: the clocks are injected (a deadline already past, or a clock that
advances one second per reading), memory is an estimate from counts or a resident size
the test sets, and the reader's speed is counted in calls (tests/prophet/planners/test_cli_memory.py
measures a real process against its bound).
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import FrameType
from typing import Any

import pytest

from alica.io import load_library
from alica.model import Condition, ConditionKind
from alica.prophet import plan_problem
from alica.prophet import planner as planner_module
from alica.prophet.ground import ground
from alica.prophet.pddl import Domain, Problem, parse_domain, parse_problem
from alica.prophet.pipeline import Found
from alica.prophet.planner import Done, LimitReached, Limits, PlanStatus
from alica.prophet.search import jit
from alica.prophet.search.gbfs import CHECK_EVERY
from alica.prophet.search.jit import (
    COMPILE_BYTES,
    NUMBA_BYTES,
    NUMBA_IMPORT_BYTES,
    kernels_cached,
    numba_bytes,
    room_for_numba,
)
from alica.prophet.search.planner import BuiltinPlanner
from alica.prophet.world import read_world
from tests.conftest import PLANS

BLOCKS = """(define (domain blocks)
  (:predicates (on ?x ?y) (ontable ?x) (clear ?x) (handempty) (holding ?x))
  (:action pick-up :parameters (?x)
    :precondition (and (clear ?x) (ontable ?x) (handempty))
    :effect (and (not (ontable ?x)) (not (clear ?x)) (not (handempty)) (holding ?x)))
  (:action stack :parameters (?x ?y)
    :precondition (and (holding ?x) (clear ?y))
    :effect (and (not (holding ?x)) (not (clear ?y)) (clear ?x) (handempty) (on ?x ?y))))
"""


def _blocks_problem(n: int) -> str:
    objects = " ".join(f"b{i}" for i in range(n))
    init = " ".join(f"(ontable b{i}) (clear b{i})" for i in range(n))
    return f"(define (problem p) (:domain blocks) (:objects {objects}) (:init (handempty) {init}) (:goal (on b0 b1)))"


def _task(n: int) -> tuple[Domain, Problem]:
    domain = parse_domain(BLOCKS)
    return domain, parse_problem(_blocks_problem(n), domain=domain)


def _past() -> Limits:
    """A deadline already past: the first check stops the work."""
    return Limits(deadline=0.0, clock=lambda: 1.0)


class _Ticking:
    """A clock that advances one second per reading."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        self.now += 1.0
        return self.now


def test_a_past_deadline_stops_reading_the_domain_and_the_problem() -> None:
    with pytest.raises(LimitReached, match="reached while reading the domain") as caught:
        parse_domain(BLOCKS, limits=_past())
    assert caught.value.stage == "reading the domain" and caught.value.status is PlanStatus.TIMEOUT
    with pytest.raises(LimitReached, match="reached while reading the problem"):
        parse_problem(_blocks_problem(3), domain=parse_domain(BLOCKS), limits=_past())


def test_reading_checks_the_deadline_every_so_many_objects() -> None:
    clock = _Ticking()
    limits = Limits(seconds=3.5, clock=clock)  # the deadline is 4.5: the third reading after the start passes it
    with pytest.raises(LimitReached, match=r"reading the problem \(2048 objects\)"):
        parse_problem(_blocks_problem(5000), domain=parse_domain(BLOCKS), limits=limits)


def test_reading_a_text_too_large_for_the_memory_bound_is_refused_before_parsing() -> None:
    with pytest.raises(LimitReached, match=r"reading the problem needs more than 0.5 MB") as caught:
        parse_problem(_blocks_problem(2000), domain=parse_domain(BLOCKS), limits=Limits(memory_mb=0.5))
    assert caught.value.status is PlanStatus.MEMORY


def test_a_past_deadline_stops_grounding_at_its_first_check() -> None:
    domain, problem = _task(50)
    with pytest.raises(LimitReached, match=r"reached while grounding \(0 ground actions, 0 facts so far\)"):
        ground(domain, problem, _past())


def test_grounding_stops_at_the_deadline_long_before_its_end() -> None:
    domain, problem = _task(200)  # 40,200 ground actions in all
    assert len(ground(domain, problem).operators) == 40200
    limits = Limits(seconds=4.5, clock=_Ticking())
    with pytest.raises(LimitReached, match="grounding") as caught:
        ground(domain, problem, limits)
    done = int(str(caught.value).split("(")[1].split(" ground actions")[0])
    assert done < 5 * 4096  # a check every 4096 steps; the fifth one stops it


def test_grounding_stops_when_its_estimated_size_passes_the_memory_bound() -> None:
    domain, problem = _task(200)  # about 80 MB at 2 KB per ground action
    with pytest.raises(LimitReached, match=r"^grounding needs more than 20 MB \(\d+ ground actions") as caught:
        ground(domain, problem, Limits(memory_mb=20))
    assert caught.value.kind == "memory"
    assert len(ground(domain, problem, Limits(memory_mb=500)).operators) == 40200  # within the bound: the same task


def test_the_search_ends_with_done_naming_the_stage_instead_of_raising() -> None:
    domain, problem = _task(20)
    events = list(BuiltinPlanner().search(domain, problem, limits=_past()))
    assert len(events) == 1 and isinstance(events[0], Done)
    assert events[0].status is PlanStatus.TIMEOUT and "while grounding" in events[0].message
    events = list(BuiltinPlanner().search(domain, problem, limits=Limits(memory_mb=0.05)))
    assert isinstance(events[-1], Done) and events[-1].status is PlanStatus.MEMORY
    result = BuiltinPlanner().solve(domain, problem, limits=Limits(memory_mb=0.05))
    assert result.status is PlanStatus.MEMORY and result.plan is None and "needs more than" in result.message


def test_the_search_stops_at_the_deadline_within_a_few_expansions() -> None:
    """The deadline is checked every CHECK_EVERY expansions, not only at Progress events (1,000 apart by default)."""
    domain = parse_domain(BLOCKS)
    # both towers at once: relaxed reachable, never reached, so the search runs until stopped
    problem = parse_problem(
        _blocks_problem(7).replace("(:goal (on b0 b1))", "(:goal (and (on b0 b1) (on b1 b0)))"), domain=domain
    )
    now = [0.0]
    limits = Limits(seconds=10.0, clock=lambda: now[0])
    events = BuiltinPlanner(progress_every=1).search(domain, problem, limits=limits)
    first = next(events)
    assert first.expansions == 1  # the search runs: one Progress per expansion
    now[0] = 11.0  # the deadline passes
    rest = list(events)
    assert isinstance(rest[-1], Done) and rest[-1].status is PlanStatus.TIMEOUT
    assert "reached while searching" in rest[-1].message
    assert CHECK_EVERY <= rest[-1].expansions <= CHECK_EVERY + 1  # the count the search reached, not the last event's


def test_a_deadline_for_the_grounding_only_leaves_the_search_to_its_caller() -> None:
    """The runtime plans a little every tick: the problem's wall-clock timeout bounds its grounding, not its search."""
    domain = parse_domain(BLOCKS)
    problem = parse_problem(
        _blocks_problem(7).replace("(:goal (on b0 b1))", "(:goal (and (on b0 b1) (on b1 b0)))"), domain=domain
    )
    now = [0.0]
    limits = Limits(seconds=10.0, clock=lambda: now[0], bounds_search=False)
    events = BuiltinPlanner(progress_every=1).search(domain, problem, limits=limits)
    next(events)
    now[0] = 11.0  # past the deadline: the search goes on while its caller takes events
    for _ in range(10 * CHECK_EVERY):
        event = next(events)
        assert not isinstance(event, Done)
    assert event.expansions > 10 * CHECK_EVERY


def test_the_runtimes_grounding_is_bounded_by_the_problems_timeout() -> None:
    library = load_library(PLANS / "blocksworld" / "mission.yaml")
    names = [f"b{i}" for i in range(30)]
    world_text = " and ".join(["handempty(r)", *(f"ontable({b}) and clear({b})" for b in names)])
    problem = replace(
        library.problems["StackBlocks"],
        world=Condition(ConditionKind.PRE, world_text),
        goal=Condition(ConditionKind.POST, "on(b0, b1)"),
        timeout=1e-9,  # no grounding fits: the search must end (the runtime then runs the AlternativePlan)
    )
    planning = plan_problem(problem, library, read_world(problem, library, (), ()))
    events = list(planning.search(anytime=True))
    assert not any(isinstance(e, Found) for e in events)
    assert isinstance(events[-1], Done) and events[-1].status is PlanStatus.TIMEOUT
    assert "while grounding" in events[-1].message
    found = list(plan_problem(replace(problem, timeout=60.0), library, planning.world).search(anytime=False))
    assert any(isinstance(e, Found) for e in found)  # the same problem plans within a real timeout


def _calls_in_parser(read: Callable[[], Any]) -> int:
    """Python calls (generator resumptions included) in the PDDL reader's own module while ``read`` runs."""
    count = 0

    def profile(frame: FrameType, event: str, _arg: object) -> None:
        nonlocal count
        if event == "call" and frame.f_code.co_filename.endswith("parser.py"):
            count += 1

    sys.setprofile(profile)
    try:
        read()
    finally:
        sys.setprofile(None)
    return count


@pytest.mark.parametrize(
    "make",
    [
        lambda n: "(define (domain w) (:predicates " + " ".join(f"(p{i} ?x)" for i in range(n)) + "))",
        lambda n: (
            "(define (domain w) (:predicates (p ?x)) (:action a :parameters ("
            + " ".join(f"?v{i}" for i in range(n))
            + ") :precondition (p ?v0) :effect (not (p ?v1))))"
        ),
        lambda n: (
            "(define (domain w) (:predicates (p ?x) (q ?x)) "
            + " ".join(f"(:action a{i} :parameters (?x) :precondition (p ?x) :effect (q ?x))" for i in range(n))
            + ")"
        ),
    ],
    ids=["predicates", "parameters", "actions"],
)
def test_reading_many_declarations_is_linear(make: Callable[[int], str]) -> None:
    small = _calls_in_parser(lambda: parse_domain(make(500)))
    large = _calls_in_parser(lambda: parse_domain(make(2000)))
    assert large <= 4 * small + 100, (small, large)  # quadratic duplicate checks made it about 16 times


def test_duplicates_are_still_found() -> None:
    with pytest.raises(Exception, match="duplicate predicate 'p'"):
        parse_domain("(define (domain w) (:predicates (p ?x) (q) (p)))")
    with pytest.raises(Exception, match="duplicate parameter '\\?x'"):
        parse_domain("(define (domain w) (:predicates (p ?x)) (:action a :parameters (?y ?x ?x) :effect (p ?x)))")
    with pytest.raises(Exception, match="duplicate action 'a'"):
        parse_domain(
            "(define (domain w) (:predicates (p)) (:action a :parameters () :effect (p)) "
            "(:action a :parameters () :effect (p)))"
        )


def test_a_bound_on_the_whole_process_counts_its_resident_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(planner_module, "resident_bytes", lambda: 300 << 20)
    estimates_only = Limits(memory_mb=200)
    estimates_only.check("searching", 100 << 20)  # the estimate fits: the process's size is not its business
    assert estimates_only.resident() == 0 and estimates_only.room_bytes() == 200 << 20
    whole = Limits(memory_mb=200, whole_process=True)
    with pytest.raises(LimitReached, match=r"^the process needs more than 200 MB while searching \(5 expansions\)"):
        whole.check("searching", 100 << 20, done="5 expansions")
    roomy = Limits(memory_mb=1000, whole_process=True)
    roomy.check("searching", 100 << 20)
    assert roomy.room_bytes() == 700 << 20


def test_numba_is_loaded_only_where_it_fits_under_a_bound_on_the_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(planner_module, "resident_bytes", lambda: 100 << 20)
    monkeypatch.delitem(sys.modules, "numba", raising=False)
    assert room_for_numba(None) and room_for_numba(Limits(memory_mb=150))  # estimates only: no rule
    assert not room_for_numba(Limits(memory_mb=150, whole_process=True))
    assert room_for_numba(Limits(memory_mb=100 + NUMBA_BYTES / 2**20, whole_process=True))
    monkeypatch.setitem(sys.modules, "numba", object())  # loaded already: the kernel's first call is left
    monkeypatch.setitem(sys.modules, "alica.prophet.search.ff_kernels", object())
    assert room_for_numba(Limits(memory_mb=150, whole_process=True))


def test_a_kernel_numba_must_compile_first_needs_more_room(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """A fresh install has no compiled kernels on disk: the first call compiles, and LLVM keeps what it
    compiled with (CI's first run passed a 300 MB bound by 35 MB that way)."""
    monkeypatch.setattr(planner_module, "resident_bytes", lambda: 100 << 20)
    monkeypatch.delitem(sys.modules, "numba", raising=False)
    monkeypatch.delitem(sys.modules, "alica.prophet.search.lama_kernels", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    source = tmp_path / "site" / "lama_kernels.py"  # an installed kernel module, its cache still empty
    (source.parent / "__pycache__").mkdir(parents=True)
    source.write_text("", encoding="utf-8")
    monkeypatch.setattr(jit, "kernel_source", lambda module: str(source))
    assert not kernels_cached("lama_kernels", "run")
    assert numba_bytes("lama_kernels", "run") == NUMBA_IMPORT_BYTES + COMPILE_BYTES
    room = Limits(memory_mb=100 + (NUMBA_BYTES >> 20), whole_process=True)  # room for a cached kernel
    assert not room_for_numba(room, "lama_kernels", "run")
    index = f"lama_kernels.run-46.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    beside = source.parent / "__pycache__" / index
    beside.write_bytes(b"")
    assert kernels_cached("lama_kernels", "run") and room_for_numba(room, "lama_kernels", "run")
    os.utime(beside, (0, 0))  # the source changed since: numba compiles again
    assert not kernels_cached("lama_kernels", "run")
    folder = str(source.parent.resolve())
    subpath = f"{source.parent.name}_{hashlib.sha1(folder.encode()).hexdigest()}"  # numba's own naming
    user = tmp_path / "cache" / "numba" / subpath  # where numba writes when the source's folder is read-only
    user.mkdir(parents=True)
    (user / index).write_bytes(b"")
    assert kernels_cached("lama_kernels", "run")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))  # numba looks only there
    assert not kernels_cached("lama_kernels", "run")
    (tmp_path / "elsewhere" / subpath).mkdir(parents=True)
    (tmp_path / "elsewhere" / subpath / index).write_bytes(b"")
    assert kernels_cached("lama_kernels", "run")
