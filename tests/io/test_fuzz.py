"""A few hundred seeded mutants of the shipped plans and the benchmark PDDL: no traceback (``bench/fuzz.py``)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

BENCH = Path(__file__).resolve().parents[2] / "bench" / "fuzz.py"


@pytest.fixture(scope="module")
def fuzz() -> ModuleType:
    spec = importlib.util.spec_from_file_location("alica_bench_fuzz", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # the workers unpickle jobs by module name
    spec.loader.exec_module(module)
    return module


def test_mutants_are_seeded(fuzz: ModuleType) -> None:
    first = [job.data for job in fuzz.jobs_of("yaml", 20, seed=3)]
    assert first == [job.data for job in fuzz.jobs_of("yaml", 20, seed=3)]
    assert first != [job.data for job in fuzz.jobs_of("yaml", 20, seed=4)]


def test_no_mutant_gives_a_traceback(fuzz: ModuleType) -> None:
    # 50 per corpus, 200 in all; a worker that does not answer within 30 s (a hang, not load) is counted.
    results = fuzz.fuzz(fuzz.CORPORA, 50, seed=14, workers=2, timeout=30.0, memory_mb=2048)
    for corpus, counts in results.items():
        assert sum(counts[o] for o in fuzz.OUTCOMES) == 50, corpus
        assert counts["rejected"] > 0, corpus  # the mutations do break files
        bad = [key for key in counts if key.split(":")[0] in ("traceback", "hang", "memory")]
        assert bad == [], f"{corpus}: {bad}"
