"""The planner registry: names, messages for unknown names, and why a back-end is unavailable."""

from __future__ import annotations

import pytest

from alica.errors import PlannerError
from alica.prophet.planner import Feature, Planner
from alica.prophet.planners import PLANNERS, available, fd, get_planner, planner_class
from alica.prophet.planners.fd import FastDownward


def test_names() -> None:
    assert PLANNERS == {
        "builtin": "alica.prophet.search.planner:BuiltinPlanner",
        "fd": "alica.prophet.planners.fd:FastDownward",
        "protap": "alica.prophet.protap.step_planner:ProtapStepPlanner",
        "temporal": "alica.prophet.planners.temporal:TemporalPlanner",
    }


def test_get_planner_by_name() -> None:
    builtin = get_planner("builtin")
    assert isinstance(builtin, Planner) and builtin.name == "builtin"
    fast = get_planner("fd", alias="seq-opt-lmcut")
    assert isinstance(fast, FastDownward) and fast.name == "fd" and fast.alias == "seq-opt-lmcut"
    assert planner_class("fd") is FastDownward


def test_unknown_name_lists_the_known_ones() -> None:
    with pytest.raises(PlannerError, match="unknown planner 'nope'; known planners: builtin, fd"):
        get_planner("nope")


def test_wrong_option_is_a_planner_error() -> None:
    with pytest.raises(PlannerError, match="planner 'builtin' does not take these options"):
        get_planner("builtin", no_such_option=1)


def test_fd_features_cover_the_builtin_ones() -> None:
    assert get_planner("builtin").features <= FastDownward.features == frozenset(Feature) - {Feature.DURATIVE_ACTIONS}
    assert get_planner("temporal").features == get_planner("builtin").features | {Feature.DURATIVE_ACTIONS}


def test_available_gives_a_reason_per_back_end() -> None:
    reasons = available()
    assert set(reasons) == set(PLANNERS)
    assert reasons["builtin"] == ""
    assert reasons["fd"] in ("", "Fast Downward is not installed: pip install 'alica-teams[fd]'")


def test_available_says_how_to_install_fd(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fd, "find_driver", lambda: None)
    assert available()["fd"] == "Fast Downward is not installed: pip install 'alica-teams[fd]'"


def test_available_reports_a_module_that_does_not_import(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(PLANNERS, "ghost", "prophet.no_such_module:Ghost")
    assert available()["ghost"].startswith("planner 'ghost' cannot be loaded (prophet.no_such_module)")


def test_not_a_planner_class(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(PLANNERS, "odd", "alica.prophet.planners.fd:find_driver")
    with pytest.raises(PlannerError, match="is not a Planner class"):
        get_planner("odd")


def test_fd_not_installed_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fd, "find_driver", lambda: None)
    with pytest.raises(PlannerError, match=r"Fast Downward is not installed: pip install 'alica-teams\[fd\]'"):
        FastDownward().solve("domain.pddl", "problem.pddl", time_limit=1)


def test_fd_options_are_checked() -> None:
    with pytest.raises(PlannerError, match="alias"):
        FastDownward(alias="lama; rm")
    with pytest.raises(PlannerError, match="positive"):
        FastDownward(time_limit=0)
    assert FastDownward().alias_for(anytime=False) == "lama-first"
    assert FastDownward().alias_for(anytime=True) == "lama"
    assert FastDownward("seq-opt-lmcut").alias_for(anytime=True) == "seq-opt-lmcut"
