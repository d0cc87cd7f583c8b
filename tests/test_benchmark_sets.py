"""Where the benchmark sets are read in place: ALICA_BENCHMARKS moves them, the bench scripts take --benchmarks DIR."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

import tests.conftest as conftest

ROOT = Path(__file__).resolve().parent.parent


def _bench(name: str) -> ModuleType:
    """``bench/NAME.py`` as a module (the bench folder is no package); loaded once per test run."""
    key = f"bench_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, ROOT / "bench" / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        spec.loader.exec_module(module)
    return sys.modules[key]


def _fake_sets(folder: Path) -> Path:
    """A folder of benchmark sets with one blocks problem and one IPC domain of two problems."""
    for sub, problems in (("pddl/blocks", ["probBLOCKS-4-0"]), ("ipc/gripper", ["prob02", "prob01"])):
        (folder / sub).mkdir(parents=True)
        (folder / sub / "domain.pddl").write_text("(define (domain d))\n", encoding="utf-8")
        for problem in problems:
            (folder / sub / f"{problem}.pddl").write_text("(define (problem p) (:domain d))\n", encoding="utf-8")
    return folder


def test_the_default_is_shared_benchmarks_beside_the_checkout(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ALICA_BENCHMARKS", raising=False)
    expected = ROOT / ".." / "shared" / "benchmarks"
    assert conftest.benchmarks_folder() == expected
    assert _bench("benchmark_sets").default_benchmarks().resolve() == expected.resolve()
    monkeypatch.setenv("ALICA_BENCHMARKS", "")  # empty counts as unset
    assert conftest.benchmarks_folder() == expected


def test_alica_benchmarks_moves_the_folder_for_the_tests_and_the_bench(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("ALICA_BENCHMARKS", str(tmp_path))
    assert conftest.benchmarks_folder() == tmp_path
    assert _bench("benchmark_sets").default_benchmarks() == tmp_path
    parser = argparse.ArgumentParser()
    _bench("benchmark_sets").add_benchmarks_option(parser)
    assert parser.parse_args([]).benchmarks == tmp_path


def test_a_missing_set_fails_the_test_naming_the_folder_and_the_variable(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(conftest, "BENCHMARKS", tmp_path / "nowhere")
    with pytest.raises(pytest.fail.Exception) as failed:
        conftest.benchmark_set("pddl")
    message = str(failed.value)
    assert str((tmp_path / "nowhere").resolve()) in message and "pddl/" in message
    assert "../shared" in message and "ALICA_BENCHMARKS" in message
    monkeypatch.setattr(conftest, "BENCHMARKS", _fake_sets(tmp_path / "sets"))
    assert conftest.benchmark_set("ipc") == tmp_path / "sets" / "ipc"


def test_the_bench_option_parses_and_a_missing_folder_ends_with_a_message(tmp_path: Path) -> None:
    sets = _bench("benchmark_sets")
    parser = argparse.ArgumentParser()
    sets.add_benchmarks_option(parser)
    assert parser.parse_args(["--benchmarks", str(tmp_path)]).benchmarks == tmp_path
    assert "--benchmarks DIR" in parser.format_help() and "ALICA_BENCHMARKS" in parser.format_help()
    with pytest.raises(SystemExit, match="ALICA_BENCHMARKS or pass --benchmarks DIR") as ended:
        sets.benchmark_set(tmp_path, "ipc")
    assert str(tmp_path.resolve()) in str(ended.value)


def test_planners_reads_the_sets_named_by_benchmarks(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    planners = _bench("planners")
    monkeypatch.setattr(planners, "BENCHMARKS", planners.BENCHMARKS)  # restored after the test
    monkeypatch.setattr(planners, "IPC", planners.IPC)
    with pytest.raises(SystemExit, match="--benchmarks DIR"):
        planners.main(["--benchmarks", str(tmp_path / "nowhere"), "--quick"])
    planners.use_benchmarks(_fake_sets(tmp_path))
    assert [j.problem for j in planners.problems("blocks", None, False)] == ["probBLOCKS-4-0"]
    assert planners.ipc_domains() == ["gripper"]
    assert [j.problem for j in planners.ipc_problems("gripper", None)] == ["prob01", "prob02"]


def test_search_ipc_fuzz_and_magic_take_the_folder(tmp_path: Path) -> None:
    sets = _fake_sets(tmp_path)
    assert [(j.domain, j.problem) for j in _bench("search_ipc").jobs(["gripper", "blocks"], sets)] == [
        ("gripper", "prob01"),
        ("gripper", "prob02"),
        ("blocks", "probBLOCKS-4-0"),
    ]
    assert _bench("fuzz").corpus_files("pddl-domain", sets) == [sets / "pddl" / "blocks" / "domain.pddl"]
    with pytest.raises(SystemExit, match="--benchmarks DIR"):
        _bench("magic").main(["--benchmarks", str(tmp_path / "nowhere")])
