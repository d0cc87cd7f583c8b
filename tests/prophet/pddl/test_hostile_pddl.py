"""Hostile PDDL ends in one ``FILE:LINE:COL: error:`` line from ``alica plan``, never a traceback (issue 14)."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.app.cli import main

MAX_DEPTH = 100  # alica.prophet.pddl.sexpr.MAX_DEPTH, written out so the test runs without the fix

DOMAIN = """(define (domain d) (:requirements :strips :action-costs :negative-preconditions :disjunctive-preconditions)
 (:predicates (p) (q)) (:functions (total-cost) - number)
 (:action a :parameters () :precondition {pre} :effect (and (q) (increase (total-cost) {cost}))))
"""
PROBLEM = (
    "(define (problem x) (:domain d) (:init (p) (= (total-cost) 0)) (:goal (q)) (:metric minimize (total-cost)))\n"
)


def nested(head: str, depth: int) -> str:
    return f"({head} " * depth + "(p)" + ")" * depth


def plan(tmp_path: Path, capsys: pytest.CaptureFixture[str], domain: str | bytes) -> tuple[int, str]:
    path = tmp_path / "domain.pddl"
    path.write_bytes(domain if isinstance(domain, bytes) else domain.encode("utf-8"))
    (tmp_path / "problem.pddl").write_text(PROBLEM, encoding="utf-8")
    code = main(["plan", str(path), str(tmp_path / "problem.pddl"), "--time-limit", "20"])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err and "internal error" not in err, err
    return code, err


@pytest.mark.parametrize("head", ["not", "and", "or (q)", "imply (q)", "exists (?x)"])
def test_deep_formula_is_a_located_error(head: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = plan(tmp_path, capsys, DOMAIN.format(pre=nested(head, 480), cost="1"))
    assert code == 1
    assert "domain.pddl:3:" in err and f"error: lists are nested more than {MAX_DEPTH} deep" in err


@pytest.mark.parametrize("head", ["and", "or (q)", "imply (q)"])
def test_formula_just_under_the_limit_is_planned(head: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = plan(tmp_path, capsys, DOMAIN.format(pre=nested(head, MAX_DEPTH - 5), cost="1"))
    assert code == 0, err


@pytest.mark.parametrize("cost", ["9" * 5000, "9" * 400, "1e999", "-1e999"])
def test_huge_cost_is_a_located_error(cost: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = plan(tmp_path, capsys, DOMAIN.format(pre="(p)", cost=cost))
    assert code == 1
    assert "domain.pddl:3:86: error: number '" in err and "for the cost is too large" in err


def test_not_utf8_names_line_and_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = plan(tmp_path, capsys, b"(define (domain d)\n ; caf\xe9\n)")
    assert code == 1
    assert "domain.pddl:2:7: error: the file is not UTF-8 text (byte 0xe9)" in err
