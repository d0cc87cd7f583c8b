"""Fuzzing the readers: seeded mutants of the shipped plans and the benchmark PDDL, each in a bounded worker.

Corpora: ``yaml`` and ``xml`` (the shipped plan files, :func:`alica.io.loader.plans_dir`),
``pddl-domain`` and ``pddl-problem`` (``pddl/*/`` of the benchmark sets, read in place from
``--benchmarks DIR``, else the environment variable ``ALICA_BENCHMARKS``, else ``../shared/benchmarks``
beside the checkout). Mutant ``i`` of a corpus is made by ``random.Random(f"{seed}:{corpus}:{i}")``
from one of its files with one to three mutations: byte flips, token swaps, deletions, duplications, deep nesting,
huge numbers and control characters.

Each mutant runs in a worker process (``--workers`` of them, each with an address
space limit of ``--memory`` MB, ``RLIMIT_AS``):

* plans: ``Loader().check`` of the mutant (placed where its original lies in a copy
  of the plans folder, so its imports resolve) and ``alica convert`` to the other format;
* PDDL: the parser, and grounding (with the original domain or problem as partner)
  when the problem has at most 30 objects.

Outcomes: ``ok`` (accepted), ``rejected`` (an error of the :class:`AlicaError` family,
which is how bad input must end), ``traceback`` (any other exception, or ``alica
convert`` exiting 70), ``hang`` (no answer within ``--timeout`` seconds: the worker is
killed and replaced), ``memory`` (``MemoryError`` or a worker that died). A table per
corpus is printed, then the first few tracebacks with the mutant's recipe.

Run: ``.venv/bin/python bench/fuzz.py [--mutants 10000] [--seed 0] [--workers 2] [--benchmarks DIR]``
"""

from __future__ import annotations

import argparse
import contextlib
import io
import multiprocessing
import os
import random
import re
import shutil
import sys
import tempfile
import threading
import time
import traceback
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench.benchmark_sets import add_benchmarks_option, benchmark_set, default_benchmarks

CORPORA = ("yaml", "xml", "pddl-domain", "pddl-problem")
OUTCOMES = ("ok", "rejected", "traceback", "hang", "memory")


# --------------------------------------------------------------------------- corpora and mutations


def pddl_folder(benchmarks: Path | None = None) -> Path:
    """The benchmark PDDL: ``pddl/`` of the benchmark sets ``benchmarks`` (default: ``default_benchmarks()``)."""
    return benchmark_set(benchmarks or default_benchmarks(), "pddl")


def corpus_files(corpus: str, benchmarks: Path | None = None) -> list[Path]:
    """The seed files of one corpus, sorted (the PDDL ones from the benchmark sets ``benchmarks``)."""
    if corpus in ("yaml", "xml"):
        from alica.io.loader import plans_dir

        endings = (".yaml", ".yml") if corpus == "yaml" else (".xml",)
        return sorted(p for p in plans_dir().rglob("*") if p.suffix in endings)
    files = sorted(pddl_folder(benchmarks).glob("*/*.pddl"))
    if corpus == "pddl-domain":
        return [p for p in files if p.name == "domain.pddl"]
    return [p for p in files if p.name != "domain.pddl"][::4]  # every fourth problem: the small and the big


_TOKEN = re.compile(rb"[A-Za-z0-9_.\-?]+|[^\sA-Za-z0-9_.\-?]")
_NUMBER = re.compile(rb"-?\d+(\.\d+)?")
_HUGE = (b"9" * 400, b"9" * 4301, b"9" * 5000, b"1e999", b"-1e999", b".nan", b".inf", b"NaN", b"0x" + b"f" * 300)
_CONTROL = [bytes([c]) for c in (*range(9), 11, 12, *range(14, 32), 127)] + [
    "\u0085".encode(),
    "\u2028".encode(),
    "\ufffe".encode(),
    b"\xff",
    b"\xc3",
]


def _span(rng: random.Random, data: bytes) -> tuple[int, int]:
    start = rng.randrange(len(data) + 1)
    return start, min(len(data), start + rng.choice((1, 2, 8, 40, 200)))


def _deep(rng: random.Random, kind: str) -> bytes:
    depth = rng.choice((50, 99, 101, 200, 480, 999, 3000))
    if kind == "pddl":
        head = rng.choice((b"(and ", b"(not ", b"(or (p) ", b"(", b"(imply (p) "))
        return head * depth + b"(p)" + b")" * depth
    if kind == "xml":
        return b"<a>" * depth + b"</a>" * depth
    return rng.choice((b"[" * depth + b"]" * depth, b"{a: " * depth + b"1" + b"}" * depth, b"- " * depth + b"x"))


def mutate(rng: random.Random, data: bytes, kind: str) -> tuple[bytes, list[str]]:
    """One to three seeded mutations of ``data``; returns the mutant and what was done."""
    done: list[str] = []
    for _ in range(rng.choice((1, 1, 2, 3))):
        what = rng.choice(("flip", "swap", "delete", "duplicate", "deep", "number", "control"))
        if what == "flip" and data:
            i = rng.randrange(len(data))
            data = data[:i] + bytes([data[i] ^ (1 << rng.randrange(8))]) + data[i + 1 :]
        elif what == "swap":
            tokens = list(_TOKEN.finditer(data))
            if len(tokens) >= 2:
                a, b = sorted(rng.sample(tokens, 2), key=lambda m: m.start())
                data = data[: a.start()] + b.group() + data[a.end() : b.start()] + a.group() + data[b.end() :]
        elif what == "delete":
            start, end = _span(rng, data)
            data = data[:start] + data[end:]
        elif what == "duplicate":
            start, end = _span(rng, data)
            data = data[:end] + data[start:end] * rng.choice((2, 10, 1000)) + data[end:]
        elif what == "deep":
            i = rng.randrange(len(data) + 1)
            data = data[:i] + _deep(rng, kind) + data[i:]
        elif what == "number":
            numbers = list(_NUMBER.finditer(data))
            if numbers:
                m = rng.choice(numbers)
                data = data[: m.start()] + rng.choice(_HUGE) + data[m.end() :]
        else:
            i = rng.randrange(len(data) + 1)
            data = data[:i] + rng.choice(_CONTROL) + data[i:]
        done.append(what)
    return data, done


# --------------------------------------------------------------------------- the worker


@dataclass
class Job:
    """One mutant to run: its corpus, the original's path and the mutated bytes."""

    corpus: str
    original: Path
    data: bytes
    recipe: str


def _run_plan(job: Job, plans: Path, shipped: Path, scratch: Path) -> str:
    from alica.app.cli import main
    from alica.errors import AlicaError
    from alica.io.loader import Loader

    target = plans / job.original.relative_to(shipped)
    backup = target.read_bytes()
    target.write_bytes(job.data)
    try:
        with contextlib.suppress(AlicaError):
            Loader(search_path=[plans]).check(target)
        out = scratch / ("out.xml" if job.corpus == "yaml" else "out.yaml")
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main(["convert", str(target), str(out), "--no-validate"])
        if code == 70:
            raise RuntimeError("alica convert: " + err.getvalue().strip()[:300])
        return "ok" if code == 0 else "rejected"
    finally:
        target.write_bytes(backup)


def _run_pddl(job: Job) -> str:
    from alica.prophet.ground import ground
    from alica.prophet.pddl import parse_domain, parse_problem, read_domain

    text = job.data.decode("utf-8")  # a UnicodeDecodeError is no reader bug: counted apart below
    if job.corpus == "pddl-domain":
        domain = parse_domain(text, str(job.original))
        problems = sorted(p for p in job.original.parent.glob("*.pddl") if p.name != "domain.pddl")
        problem = parse_problem(problems[0].read_text(encoding="utf-8"), str(problems[0]), domain)
    else:
        domain = read_domain(job.original.parent / "domain.pddl")
        problem = parse_problem(text, str(job.original), domain)
    if len(problem.objects) <= 30:
        ground(domain, problem)
    return "ok"


def _worker(conn: Connection, memory_mb: int) -> None:
    import resource

    from alica.errors import AlicaError
    from alica.io.loader import plans_dir

    limit = memory_mb * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    shipped = plans_dir()
    scratch = Path(tempfile.mkdtemp(prefix="alica-fuzz-"))
    plans = scratch / "plans"
    shutil.copytree(shipped, plans)
    import alica.app.cli
    import alica.prophet.ground  # noqa: F401 - imported before the first mutant's clock starts

    conn.send(("ready", ""))
    try:
        while True:
            job: Job | None = conn.recv()
            if job is None:
                return
            try:
                outcome = _run_pddl(job) if job.corpus.startswith("pddl") else _run_plan(job, plans, shipped, scratch)
                conn.send((outcome, ""))
            except AlicaError:
                conn.send(("rejected", ""))
            except UnicodeDecodeError:  # the PDDL API takes text: bytes that are no UTF-8 never reach it
                conn.send(("rejected", ""))
            except MemoryError:
                conn.send(("memory", "MemoryError"))
            except Exception as exc:  # counting what escapes is the point
                frame = traceback.extract_tb(exc.__traceback__)[-1]
                where = f"{Path(frame.filename).name}:{frame.lineno}"
                conn.send(("traceback", f"{type(exc).__name__}: {str(exc)[:200]} at {where}"))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


@dataclass
class Pool:
    """Worker processes, each driven by one thread; a worker that hangs or dies is replaced."""

    workers: int
    timeout: float
    memory_mb: int
    _context: Any = field(default_factory=lambda: multiprocessing.get_context("fork"))

    def _start(self) -> tuple[Any, Connection]:
        parent, child = self._context.Pipe()
        process = self._context.Process(target=_worker, args=(child, self.memory_mb), daemon=True)
        process.start()
        child.close()
        if not parent.poll(120):  # imports and the copy of the plans folder
            raise RuntimeError("a fuzz worker did not start within 120 s")
        parent.recv()
        return process, parent

    def run(self, jobs: Iterator[Job], report: Callable[[Job, str, str], None]) -> None:
        """Run every job, calling ``report(job, outcome, detail)`` from the worker threads."""
        lock = threading.Lock()

        def drive() -> None:
            process, conn = self._start()
            try:
                while True:
                    with lock:
                        job = next(jobs, None)
                    if job is None:
                        return
                    conn.send(job)
                    if conn.poll(self.timeout):
                        try:
                            outcome, detail = conn.recv()
                        except EOFError:
                            outcome, detail = "memory", f"worker died (exit {process.exitcode})"
                    else:
                        outcome, detail = "hang", f"no answer within {self.timeout:g} s"
                    if outcome in ("hang", "memory") and detail != "MemoryError":
                        process.kill()
                        process.join()
                        process, conn = self._start()
                    report(job, outcome, detail)
            finally:
                with contextlib.suppress(OSError, ValueError):
                    conn.send(None)
                process.join(5)
                if process.is_alive():
                    process.kill()

        threads = [threading.Thread(target=drive) for _ in range(self.workers)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()


def jobs_of(corpus: str, count: int, seed: int, benchmarks: Path | None = None) -> Iterator[Job]:
    """The ``count`` seeded mutants of one corpus."""
    files = corpus_files(corpus, benchmarks)
    contents = {path: path.read_bytes() for path in files}
    kind = "pddl" if corpus.startswith("pddl") else corpus
    for i in range(count):
        rng = random.Random(f"{seed}:{corpus}:{i}")
        original = rng.choice(files)
        data, done = mutate(rng, contents[original], kind)
        yield Job(corpus, original, data, f"seed {seed} {corpus} #{i} {original.name}: {'+'.join(done)}")


def fuzz(
    corpora: tuple[str, ...],
    count: int,
    seed: int,
    workers: int = 2,
    timeout: float = 10.0,
    memory_mb: int = 2048,
    benchmarks: Path | None = None,
) -> dict[str, Counter[str]]:
    """Outcome counts per corpus; the tracebacks' details are counted under ``traceback: ...`` keys."""
    results: dict[str, Counter[str]] = {c: Counter() for c in corpora}
    lock = threading.Lock()

    def report(job: Job, outcome: str, detail: str) -> None:
        with lock:
            results[job.corpus][outcome] += 1
            if outcome != "ok" and outcome != "rejected":
                results[job.corpus][f"{outcome}: {detail} [{job.recipe}]"] += 1

    pool = Pool(workers, timeout, memory_mb)
    for corpus in corpora:
        pool.run(jobs_of(corpus, count, seed, benchmarks), report)
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mutants", type=int, default=10_000, help="mutants per corpus")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=max(1, min(4, (os.cpu_count() or 2))))
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds before a mutant counts as a hang")
    parser.add_argument("--memory", type=int, default=2048, help="address space limit of a worker, MB")
    parser.add_argument("--corpus", choices=CORPORA, action="append", help="only these corpora (repeatable)")
    add_benchmarks_option(parser)
    args = parser.parse_args()
    corpora = tuple(args.corpus or CORPORA)
    start = time.perf_counter()
    if any(c.startswith("pddl") for c in corpora):
        benchmark_set(args.benchmarks, "pddl")  # before the workers start: a missing folder ends here, with a message
    results = fuzz(corpora, args.mutants, args.seed, args.workers, args.timeout, args.memory, args.benchmarks)
    seconds = time.perf_counter() - start
    print(f"{'corpus':<14} {'mutants':>8} " + " ".join(f"{o:>10}" for o in OUTCOMES))
    for corpus, counts in results.items():
        total = sum(counts[o] for o in OUTCOMES)
        print(f"{corpus:<14} {total:>8} " + " ".join(f"{counts[o]:>10}" for o in OUTCOMES))
    print(f"seed {args.seed}, {args.workers} workers, {seconds:.0f} s wall")
    for corpus, counts in results.items():
        details = [k for k in counts if ":" in k and k.split(":")[0] in OUTCOMES]
        for key in details[:10]:
            print(f"  {corpus}: {key}")


if __name__ == "__main__":
    main()
