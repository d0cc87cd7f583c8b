"""A few hundred seeded mutants of the shipped plans and the benchmark PDDL: no traceback (``bench/fuzz.py``)."""

from __future__ import annotations

import importlib.util
import random
import sys
from pathlib import Path
from types import ModuleType

import pytest

from tests.conftest import benchmark_set

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
    benchmark_set("pddl")  # the PDDL corpora: the bench reads the same folder (bench/benchmark_sets.py)
    # 50 per corpus, 200 in all; a worker that does not answer within 30 s (a hang, not load) is counted.
    results = fuzz.fuzz(fuzz.CORPORA, 50, seed=14, workers=2, timeout=30.0, memory_mb=2048)
    for corpus, counts in results.items():
        assert sum(counts[o] for o in fuzz.OUTCOMES) == 50, corpus
        assert counts["rejected"] > 0, corpus  # the mutations do break files
        bad = [key for key in counts if key.split(":")[0] in ("traceback", "hang", "memory")]
        assert bad == [], f"{corpus}: {bad}"


#: Seeds for the skill catalogue written as data (the shipped plans have no ``skills:`` section).
SKILL_SEEDS = {
    "catalogue.yaml": """\
alica: 1
skills:
  - name: Attack
    doc: "imported from the ALICA Plan Designer"
    capabilities: [arm]
    params:
      - {name: goal, type: str, required: false, default: "", doc: "where to go"}
      - {name: times, type: int}
      - {name: corner, type: position, default: [0, 1.5]}
behaviours:
  - {name: Strike, skill: Attack, params: {times: 2, corner: [1, 2]}}
""",
    "catalogue.xml": """\
<?xml version="1.0" encoding="UTF-8"?>
<alica version="1">
  <skill name="Attack" doc="imported from the ALICA Plan Designer">
    <capability>arm</capability>
    <parameter name="goal" type="str" required="false" default="" doc="where to go"/>
    <parameter name="times" type="int"/>
    <parameter name="corner" type="position"><default><item>0</item><item>1.5</item></default></parameter>
  </skill>
  <behaviour name="Strike" skill="Attack"><param name="times" value="2"/></behaviour>
</alica>
""",
}


@pytest.mark.parametrize("name", sorted(SKILL_SEEDS))
def test_mutants_of_a_skill_catalogue_give_no_traceback(
    fuzz: ModuleType, name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from alica.app.cli import main
    from alica.errors import AlicaError
    from alica.io import Loader

    kind = name.rpartition(".")[2]
    path, out = tmp_path / name, tmp_path / ("out.xml" if kind == "yaml" else "out.yaml")
    path.write_text(SKILL_SEEDS[name], encoding="utf-8")
    assert Loader().check(path)[1] == []  # the seed itself is valid
    loader_rejected = 0
    for i in range(60):
        data, done = fuzz.mutate(random.Random(f"skills:{name}:{i}"), SKILL_SEEDS[name].encode(), kind)
        path.write_bytes(data)
        try:
            problems = Loader().check(path)[1]
        except AlicaError:
            problems = ["rejected"]
        loader_rejected += bool(problems)
        code = main(["convert", str(path), str(out), "--no-validate"])
        err = capsys.readouterr().err
        assert code != 70 and "Traceback" not in err, f"mutant {i} ({'+'.join(done)}): {err}"
    assert loader_rejected > 0  # the mutations do break files
