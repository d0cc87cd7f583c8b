"""Long chains of operators and deep nesting: what validation passes, the run never crashes on.

Chains (``1 + 1 + ...``, ``p.x.x...``, ``a <-> b <-> ...``, ``not not ...``)
parse, check, evaluate and unparse by loops, whatever their length; nesting by
parentheses, call arguments and quantifiers is capped by the parser with an
error at the opening that goes too deep.
"""

from __future__ import annotations

import shutil
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from alica.app.cli import main
from alica.errors import FormulaError
from alica.lang import FactBase, check, evaluate, holds, parse, unparse
from alica.lang.parser import MAX_DEPTH, _parse_cached
from alica.lang.prelude import default_registry
from tests.conftest import PLANS

N = 20_000  # far beyond the interpreter's recursion limit (1,000 frames)


def chain(op: str, operand: str, count: int = N) -> str:
    return op.join([operand] * count)


CHAINS = [
    (chain(" + ", "1") + " > 0", True),
    (chain(" - ", "1") + " < 0", True),
    (chain(" * ", "1") + " == 1", True),
    (chain(" ^ ", "1") + " == 1", True),
    ("p" + ".x" * N + " == p", True),
    (chain(" <-> ", "true"), True),
    (chain(" -> ", "true"), True),
    (chain(" and ", "true"), True),
    (chain(" or ", "false"), False),
    ("not " * N + "true", True),
    ("-" * N + "1 > 0", True),
    ("1 ^ " + chain(" ^ ", "-1", N - 1) + " == 1", True),
]


@pytest.mark.parametrize(("text", "truth"), CHAINS, ids=lambda t: t[:12] if isinstance(t, str) else str(t))
def test_chains_of_20000_operands_parse_check_evaluate_and_unparse(text: str, truth: bool) -> None:
    loop: dict[str, object] = {}
    loop["x"] = loop
    node = parse(text)
    assert check(node, default_registry(), text=text, boolean=True) == []
    assert holds(node, FactBase(), {"p": loop}) is truth
    again = unparse(node)
    assert unparse(parse(again)) == again


def test_an_evaluation_error_deep_in_a_chain_names_its_column() -> None:
    text = chain(" + ", "1", 1000) + ' + "a" > 0'
    with pytest.raises(Exception, match="cannot apply '\\+'") as caught:
        evaluate(text, FactBase())
    assert caught.value.column == 1  # type: ignore[attr-defined]


def test_a_chain_keeps_its_order_and_associativity() -> None:
    assert evaluate(chain(" - ", "1", 5), FactBase()) == -3
    assert evaluate("2 ^ 3 ^ 2", FactBase()) == 512
    assert evaluate("2 ^ -1 ^ 2", FactBase()) == 0.5
    assert evaluate("- - - 2", FactBase()) == -2
    assert holds("false -> false -> false", FactBase()) is True
    assert holds("true -> true -> false", FactBase()) is False
    assert holds("false <-> false <-> false", FactBase()) is False
    assert str(parse("a -> b -> c")) == "a -> b -> c"
    assert str(parse("(a -> b) -> c")) == "(a -> b) -> c"
    assert str(parse("(a <-> b) <-> c")) == "a <-> b <-> c"


def _worst(levels: int) -> str:
    """Every layer of the grammar at each of ``levels`` nesting levels (call arguments)."""
    text = "1"
    for _ in range(levels):
        text = "false <-> true -> false or true and not 1 < 1 + 1 * -1 ^ abs(" + text + ").real"
    return text


@pytest.fixture
def stack_budget() -> Iterator[Callable[[int], None]]:
    """Lower Python's recursion limit to ``frames`` above the current stack, for the test's duration."""
    limit = sys.getrecursionlimit()

    def budget(frames: int) -> None:
        depth = 0
        frame = sys._getframe()
        while frame is not None:
            depth += 1
            frame = frame.f_back  # type: ignore[assignment]
        sys.setrecursionlimit(depth + frames)

    yield budget
    sys.setrecursionlimit(limit)


def test_the_deepest_formula_the_parser_accepts_runs_in_700_frames(stack_budget: Callable[[int], None]) -> None:
    text = _worst(MAX_DEPTH)
    _parse_cached.cache_clear()
    registry = default_registry()
    stack_budget(700)
    node = parse(text)
    check(node, registry, text=text, boolean=True)
    assert holds(node, FactBase(), registry=registry) is False
    assert unparse(node) == text
    with pytest.raises(FormulaError, match="nested deeper than"):
        parse(_worst(MAX_DEPTH + 1))


OPS = st.sampled_from(["+", "-", "*", "/", "%", "^", "and", "or", "->", "<->", "<", "=="])
OPERANDS = st.sampled_from(["a", "1", "2.5", '"s"', "f(x)", "p.x.y", "(not b)", "- -c", "(a or b)", "true"])


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(OPS, OPERANDS), min_size=1, max_size=3000), OPERANDS, st.integers(0, 3000))
def test_random_long_chains_parse_and_round_trip(links: list[tuple[str, str]], first: str, nots: int) -> None:
    # at most one comparison (they do not chain), then the text is a formula
    text = "not " * nots + first
    compared = False
    for op, operand in links:
        if op in ("<", "=="):
            if compared:
                op = "+"
            compared = True
        text += f" {op} {operand}"
    node = parse(text)
    canonical = unparse(node)
    assert unparse(parse(canonical)) == canonical
    check(node, text=text)


# -- through the command line --------------------------------------------------


def _plans_with(tmp_path: Path, condition: str) -> Path:
    """A copy of the shipped plans whose lunar mission has ``condition`` for SamplesFound."""
    root = tmp_path / "plans"
    shutil.copytree(PLANS, root)
    (root / ".alica-project").write_text("", encoding="utf-8")  # the copy is a project: its files import each other
    mission = root / "lunar" / "mission.yaml"
    text = mission.read_text(encoding="utf-8")
    old = '{to: SamplesFound, condition: "found(a) and found(b)"}'
    assert old in text
    mission.write_text(text.replace(old, f'{{to: SamplesFound, condition: "{condition}"}}'), encoding="utf-8")
    return mission


def test_a_long_chain_validates_and_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    mission = _plans_with(tmp_path, "found(a) and found(b) and " + chain(" + ", "1", 5000) + " > 0")
    assert main(["validate", str(mission)]) == 0, capsys.readouterr().err
    argv = ["run", str(mission), "--stand-ins", "--agents", "scout,stummel,amparo", "--ticks", "3"]
    code = main([*argv, "--fact", "found(a) and found(b)"])
    err = capsys.readouterr().err
    assert code in (0, 1) and "Traceback" not in err and "internal error" not in err


def test_nesting_too_deep_is_rejected_by_validate_at_its_line_and_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    deep = "(" * (MAX_DEPTH + 5) + "found(a)" + ")" * (MAX_DEPTH + 5)
    mission = _plans_with(tmp_path, "found(b) and " + deep)
    line_no, line = next((i, t) for i, t in enumerate(mission.read_text().splitlines(), 1) if deep in t)
    column = line.index(deep) + MAX_DEPTH + 1
    assert main(["validate", str(mission)]) == 1
    err = capsys.readouterr().err
    assert f"mission.yaml:{line_no}:{column}: error: " in err
    assert f"formula nested deeper than {MAX_DEPTH} levels; simplify it" in err


@pytest.mark.parametrize(
    "fact",
    [
        "found(a) and " + chain(" + ", "1", 5000) + " > 0",
        "found(a) and p" + ".x" * 5000 + " == 1",
        "found(a) and " + chain(" <-> ", "b", 5000),
        chain(" and ", "found(a)", 5000),
    ],
    ids=["plus", "attr", "iff", "and"],
)
def test_long_chains_in_run_fact_and_plan_world_are_clear_errors_or_work(
    fact: str, capsys: pytest.CaptureFixture[str]
) -> None:
    lunar = str(PLANS / "lunar" / "mission.yaml")
    code = main(["run", lunar, "--stand-ins", "--agents", "scout", "--ticks", "1", "--fact", fact + "@0"])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err
    literal = fact.startswith("found(a) and found(a)")
    assert code == 1  # unfinished after one tick, or the fact is no literal
    if not literal:
        assert err.startswith("alica: error: "), err[:300]
    mission = str(PLANS / "blocksworld" / "mission.yaml")
    world = fact.replace("found(a)", "ontable(a)") + " and clear(a) and handempty(r)"
    code = main(["plan", mission, "--world", world, "--goal", "holding(r, a)"])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err
    if literal:
        assert code == 0, err[:300]
    else:
        assert code == 1 and err.startswith("alica: error: "), err[:300]
