"""Allocation with the IMPERA role set and the shipped LunarMission plan (IMPERA Fig. 3 and 6).

Expected utilities are computed from the shipped priorities and weights, so
the tests say *why* an assignment wins rather than repeating numbers.
"""

from __future__ import annotations

import dataclasses

import pytest

from alica.allocation import AgentSpec, AllocationProblem, Assignment, allocate, assign_roles, exhaustive, utility
from alica.io import load_library
from alica.model import Plan, RoleSet
from tests.conftest import PLANS

ROLES = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo"}


@dataclasses.dataclass(frozen=True)
class Lunar:
    roleset: RoleSet
    plan: Plan

    def pref(self, agent: str, task: str) -> float:
        return self.roleset.priority(ROLES[agent.rstrip("0123456789")], task)

    def problem(self, agents: tuple[str, ...], **extra: object) -> AllocationProblem:
        roles = {a: ROLES[a.rstrip("0123456789")] for a in agents}
        return AllocationProblem(agents, roles, self.roleset, (self.plan,), **extra)  # type: ignore[arg-type]

    def priority_utility(self, entries: dict[str, str]) -> float:
        """U without similarity: w0 * sum of priorities / N over the weight sum (N = team size here)."""
        u = self.plan.utility
        total = sum(self.pref(a, e) for a, e in entries.items() if e is not None)
        return u.priority_weight * total / len(entries) / u.weight_sum


@pytest.fixture(scope="module")
def lunar() -> Lunar:
    library = load_library(PLANS / "lunar" / "mission.yaml")
    return Lunar(library.rolesets["Impera"], library.plans["LunarMission"])


def _solve(problem: AllocationProblem) -> Assignment | None:
    found = allocate(problem)
    expected = exhaustive(problem)
    assert found.assignment == expected.assignment
    assert found.why == expected.why
    return found.assignment


def test_shipped_priorities_have_the_shape_the_tests_rely_on(lunar: Lunar) -> None:
    assert lunar.pref("scout", "Transport1") < 0 and lunar.pref("scout", "Transport2") < 0
    assert lunar.pref("amparo", "Explore") < 0
    assert lunar.pref("amparo", "Transport1") > lunar.pref("amparo", "Transport2") > lunar.pref("stummel", "Transport1")
    assert lunar.pref("stummel", "Transport2") > lunar.pref("stummel", "Explore") > 0
    assert lunar.plan.entry_point("Explore").min == 1
    assert lunar.plan.entry_point("Transport1").min == 1


def test_roles_from_capabilities(lunar: Lunar) -> None:
    specs = {
        "scout": AgentSpec(capabilities=frozenset({"base", "lidar2d", "camera"})),
        "stummel": AgentSpec(capabilities=frozenset({"base", "arm", "gripper", "lidar2d", "camera"})),
        "amparo": AgentSpec(capabilities=frozenset({"base", "arm", "gripper", "lidar3d", "stereo_camera"})),
    }
    assert assign_roles(specs, lunar.roleset) == ROLES


def test_full_team_matches_fig_3(lunar: Lunar) -> None:
    assignment = _solve(lunar.problem(("stummel", "amparo", "scout")))
    assert assignment is not None
    # Scout can only explore (it cannot transport). Transport1 needs one robot:
    # Amparo (0.9) rather than Stummel (0.5). Stummel then prefers Transport2
    # (0.55) to exploring (0.5); Transport2 takes at most one robot.
    expected = {"amparo": "Transport1", "scout": "Explore", "stummel": "Transport2"}
    assert assignment.as_dict() == expected
    assert assignment.utility == pytest.approx(lunar.priority_utility(expected))


def test_without_scout_stummel_explores_and_amparo_transports(lunar: Lunar) -> None:
    # Explore needs one robot and Amparo cannot explore, so Stummel must; Transport1
    # needs one robot: Amparo. N = min(inf, 2) = 2.
    assignment = _solve(lunar.problem(("stummel", "amparo")))
    assert assignment is not None
    expected = {"amparo": "Transport1", "stummel": "Explore"}
    assert assignment.as_dict() == expected
    assert assignment.utility == pytest.approx(lunar.priority_utility(expected))


def test_without_amparo_stummel_transports_and_scout_explores(lunar: Lunar) -> None:
    # Scout cannot transport, so Stummel takes Transport1 (needed) and Scout explores.
    assignment = _solve(lunar.problem(("scout", "stummel")))
    assert assignment is not None
    expected = {"scout": "Explore", "stummel": "Transport1"}
    assert assignment.as_dict() == expected
    assert assignment.utility == pytest.approx(lunar.priority_utility(expected))


def test_a_lone_robot_cannot_start_the_mission(lunar: Lunar) -> None:
    result = allocate(lunar.problem(("amparo",)))
    assert result.assignment is None
    assert result.why == (
        "no valid assignment: plan 'LunarMission' needs at least 2 agents (minimum per entry point, "
        "after successes: Explore 1, Transport1 1) but only 1 is available (amparo); add agents or lower the minima"
    )


@pytest.mark.parametrize("missing", ["scout", "amparo", "stummel"])
def test_two_robots_and_three_required_tasks(lunar: Lunar, missing: str) -> None:
    # The plan as first written (Fig. 3 with every task 1..n): with two robots no
    # assignment is valid, whoever is missing.
    strict = dataclasses.replace(
        lunar.plan, entry_points=tuple(dataclasses.replace(ep, min=1) for ep in lunar.plan.entry_points)
    )
    agents = tuple(a for a in ROLES if a != missing)
    problem = AllocationProblem(agents, {a: ROLES[a] for a in agents}, lunar.roleset, (strict,))
    result = allocate(problem)
    assert result.assignment is None
    assert "plan 'LunarMission' needs at least 3 agents" in result.why
    assert "Explore 1, Transport1 1, Transport2 1" in result.why
    assert "but only 2 are available" in result.why
    assert result.why == exhaustive(problem).why


def test_when_both_transports_are_done_amparo_idles(lunar: Lunar) -> None:
    # One success each leaves Transport1 and Transport2 no places (max 1 - 1 = 0);
    # Amparo cannot explore, so it idles; Stummel explores (0.5 beats idling).
    done = {"LunarMission": {"Transport1": 1, "Transport2": 1}}
    assignment = _solve(lunar.problem(("scout", "stummel", "amparo"), successes=done))
    assert assignment is not None
    assert assignment.as_dict() == {"amparo": None, "scout": "Explore", "stummel": "Explore"}


def test_veto_is_explained(lunar: Lunar) -> None:
    done = {"LunarMission": {"Transport1": 1, "Transport2": 1}}
    result = allocate(lunar.problem(("amparo",), successes=done))
    assert result.assignment is None
    assert "entry point 'Explore' (task Explore) needs 1 agent(s) but only 0 can take it" in result.why
    assert "vetoed: amparo (Amparo): priority -1" in result.why


def test_a_second_scout_explores_too(lunar: Lunar) -> None:
    assignment = _solve(lunar.problem(("scout", "scout2", "stummel", "amparo")))
    assert assignment is not None
    assert assignment.as_dict() == {
        "amparo": "Transport1",
        "scout": "Explore",
        "scout2": "Explore",
        "stummel": "Transport2",
    }


def test_the_current_assignment_wins_through_similarity(lunar: Lunar) -> None:
    # The team runs the transports swapped. Keeping all three robots scores the full
    # similarity weight; the priority optimum keeps only Scout (1/3 of it), which
    # does not make up for it.
    old = Assignment.of("LunarMission", {"scout": "Explore", "stummel": "Transport1", "amparo": "Transport2"}, 0.0)
    problem = lunar.problem(("scout", "stummel", "amparo"), old=old)
    assignment = _solve(problem)
    assert assignment is not None
    assert assignment.as_dict() == old.as_dict()
    u = lunar.plan.utility
    kept = lunar.priority_utility(old.as_dict()) + u.similarity_weight / u.weight_sum  # type: ignore[arg-type]
    assert assignment.utility == pytest.approx(kept)
    # The engine applies the threshold; it needs utility() to agree with allocate().
    assert utility(problem, lunar.plan, old.as_dict()) == assignment.utility
    fresh = {"scout": "Explore", "stummel": "Transport2", "amparo": "Transport1"}
    moved = lunar.priority_utility(fresh) + u.similarity_weight / 3 / u.weight_sum
    assert utility(problem, lunar.plan, fresh) == pytest.approx(moved)
    assert moved < kept


def test_vetoed_assignment_has_utility_minus_one(lunar: Lunar) -> None:
    problem = lunar.problem(("scout", "stummel", "amparo"))
    entries = {"scout": "Transport1", "stummel": "Explore", "amparo": "Transport2"}
    assert utility(problem, lunar.plan, entries) == -1.0
