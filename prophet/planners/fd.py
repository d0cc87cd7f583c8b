"""Fast Downward as a planner back-end: the planner runs as a subprocess on PDDL files.

Fast Downward comes from the optional extra ``fd`` (PyPI ``up-fast-downward``,
which ships the planner's driver script and search binary)::

    pip install 'alica-teams[fd]'

The driver is located inside that package without importing it (its Python
module needs ``unified-planning``, which this back-end does not use).

Search configurations are Fast Downward aliases: ``lama-first`` (the default:
greedy search, first plan), ``lama`` (anytime: the default with ``anytime=True``;
it writes ``sas_plan.1``, ``sas_plan.2``, ... and every new file becomes an
:class:`~alica.prophet.planner.Improved` event while the planner runs) and
``seq-opt-lmcut`` (A* with LM-cut: optimal plans).
"""

from __future__ import annotations

import copy
import importlib.util
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from alica.errors import PlannerError
from alica.prophet.planner import (
    Done,
    Feature,
    Improved,
    Limits,
    Plan,
    Planner,
    PlanResult,
    PlanStatus,
    Progress,
    SearchEvent,
)
from alica.prophet.planners.planfile import parse_plan

INSTALL_HINT = "pip install 'alica-teams[fd]'"
"""How to install the back-end, for messages."""

_EXPANDED = re.compile(rb"Expanded (\d+) state")
_PLAN_FILE = re.compile(r"^sas_plan(?:\.(\d+))?$")
_GRACE_S = 1.0
_TAIL_LINES = 12

# Fast Downward's exit codes (https://www.fast-downward.org, "Exit codes").
_PLAN_FOUND = frozenset({0, 1, 2, 3})
_UNSOLVABLE = frozenset({10, 11})
_INCOMPLETE = frozenset({12, 13})
_OUT_OF_TIME = frozenset({21, 23, 24})
_OUT_OF_MEMORY = frozenset({20, 22})

__all__ = ["INSTALL_HINT", "FastDownward", "find_driver"]


def find_driver() -> Path | None:
    """The ``fast-downward.py`` driver of the installed ``up-fast-downward``, or None."""
    try:
        spec = importlib.util.find_spec("up_fast_downward")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    for location in spec.submodule_search_locations:
        root = Path(location) / "downward"
        driver = root / "fast-downward.py"
        if driver.is_file() and (root / "builds" / "release" / "bin" / "downward").is_file():
            return driver
    return None


class _ExpansionCounter:
    """Sums Fast Downward's ``Expanded N state(s)`` lines of a log that is still growing."""

    def __init__(self, path: Path) -> None:
        self._path = path
        self._handle: IO[bytes] | None = None
        self._rest = b""
        self.total = 0

    def update(self) -> int:
        """Read what the log gained since the last call; the expansions so far."""
        if self._handle is None:
            if not self._path.exists():
                return self.total
            self._handle = self._path.open("rb")
        data = self._rest + self._handle.read()
        cut = data.rfind(b"\n") + 1
        self._rest = data[cut:]
        self.total += sum(int(m.group(1)) for m in _EXPANDED.finditer(data[:cut]))
        return self.total

    def close(self) -> None:
        """Close the log."""
        if self._handle is not None:
            self._handle.close()
            self._handle = None


class FastDownward(Planner):
    """Fast Downward (``up-fast-downward``) run as a subprocess.

    Args:
        alias: a Fast Downward alias; None picks ``lama-first``, or ``lama``
            for an anytime search.
        time_limit: wall seconds at most per run (None: only the limit that
            :meth:`solve` gets).
        driver: the ``fast-downward.py`` to run (default: the one of the
            installed ``up-fast-downward``).
        poll_interval: seconds between two looks at the running planner.

    Domains and problems may be given as paths of PDDL files (run as they
    are) or as parsed objects of :mod:`alica.prophet.pddl` (written into a
    temporary folder with ``write_domain``/``write_problem``).
    """

    name = "fd"
    features = frozenset(Feature) - {Feature.DURATIVE_ACTIONS}  # Fast Downward is a classical planner
    reads_files = True
    """The back-end runs on files: callers may hand it the original paths."""

    def __init__(
        self,
        alias: str | None = None,
        *,
        time_limit: float | None = None,
        driver: str | Path | None = None,
        poll_interval: float = 0.02,
    ) -> None:
        if alias is not None and not re.fullmatch(r"[A-Za-z0-9_\-]+", alias):
            raise PlannerError(f"Fast Downward alias '{alias}' is not a name like lama-first, lama or seq-opt-lmcut")
        if time_limit is not None and time_limit <= 0:
            raise PlannerError(f"time limit must be positive, not {time_limit}")
        self.alias = alias
        self.time_limit = time_limit
        self.driver = Path(driver) if driver is not None else None
        self.poll_interval = poll_interval

    @staticmethod
    def unavailable() -> str:
        """Why Fast Downward cannot run here, or ``""`` when it can."""
        if find_driver() is None:
            return f"Fast Downward is not installed: {INSTALL_HINT}"
        return ""

    def alias_for(self, anytime: bool) -> str:
        """The alias a run uses."""
        if self.alias is not None:
            return self.alias
        return "lama" if anytime else "lama-first"

    def _driver(self) -> Path:
        if self.driver is not None:
            if not self.driver.is_file():
                raise PlannerError(f"Fast Downward driver {self.driver} does not exist")
            return self.driver
        found = find_driver()
        if found is None:
            raise PlannerError(f"Fast Downward is not installed: {INSTALL_HINT}")
        return found

    def search(
        self, domain: object, problem: object, *, anytime: bool = True, limits: Limits | None = None
    ) -> Iterator[SearchEvent]:
        """The search as events (see :class:`~alica.prophet.planner.Planner`).

        Raises:
            PlannerError: Fast Downward is not installed, or the task needs
                features it lacks.
        """
        self._driver()
        return super().search(domain, problem, anytime=anytime, limits=limits)

    def solve(
        self,
        domain: object,
        problem: object,
        *,
        time_limit: float = 60.0,
        anytime: bool = False,
        limits: Limits | None = None,
    ) -> PlanResult:
        """Run Fast Downward for at most ``time_limit`` wall seconds (or what ``limits`` leave); the best plan wins."""
        left = limits.remaining() if limits is not None else None
        if left is not None:
            time_limit = max(left, 0.001)
        limit = time_limit if self.time_limit is None else min(time_limit, self.time_limit)
        run = copy.copy(self)
        run.time_limit = limit
        return Planner.solve(run, domain, problem, time_limit=limit + _GRACE_S, anytime=anytime)

    def _search(self, domain: object, problem: object, *, anytime: bool) -> Iterator[SearchEvent]:
        driver = self._driver()
        alias = self.alias_for(anytime)
        with tempfile.TemporaryDirectory(prefix="alica-fd-") as tmp:
            folder = Path(tmp)
            domain_file, problem_file = _inputs(domain, problem, folder)
            command = [sys.executable, str(driver), "--plan-file", "sas_plan", "--alias", alias]
            if self.time_limit is not None:
                command += ["--overall-time-limit", f"{max(1, math.ceil(self.time_limit))}s"]
            command += [str(domain_file), str(problem_file)]
            yield from self._run(command, folder, alias)

    def _run(self, command: list[str], folder: Path, alias: str) -> Iterator[SearchEvent]:
        log, errors = folder / "fd.log", folder / "fd.err"
        with log.open("wb") as out, errors.open("wb") as err:
            process = subprocess.Popen(
                command, cwd=folder, stdin=subprocess.DEVNULL, stdout=out, stderr=err, start_new_session=True
            )
        counter = _ExpansionCounter(log)
        deadline = None if self.time_limit is None else time.monotonic() + self.time_limit
        seen: set[str] = set()
        best = math.inf
        timed_out = False
        try:
            while True:
                code = process.poll()
                expansions = counter.update()
                for plan in _new_plans(folder, seen, finished=code is not None):
                    if plan.cost < best:
                        best = plan.cost
                        yield Improved(plan, expansions)
                if code is not None:
                    break
                if deadline is not None and time.monotonic() > deadline:
                    timed_out = True
                    _stop(process)
                    break
                yield Progress(expansions)
                time.sleep(self.poll_interval)
            expansions = counter.update()
            for plan in _new_plans(folder, seen, finished=True):
                if plan.cost < best:
                    best = plan.cost
                    yield Improved(plan, expansions)
            yield _done(process.returncode, timed_out, math.isfinite(best), alias, expansions, folder)
        finally:
            _stop(process)
            counter.close()


def _inputs(domain: object, problem: object, folder: Path) -> tuple[Path, Path]:
    """The PDDL files to run on: the given paths, or the objects written into ``folder``."""
    files: list[Path] = []
    for kind, item in (("domain", domain), ("problem", problem)):
        if isinstance(item, (str, os.PathLike)):
            path = Path(item)
            if not path.is_file():
                raise PlannerError(f"{kind} file {path} does not exist")
            files.append(path.resolve())
            continue
        from alica.prophet import pddl

        writer = pddl.write_domain if kind == "domain" else pddl.write_problem
        target = folder / f"{kind}.pddl"
        target.write_text(writer(item), encoding="utf-8")  # type: ignore[arg-type]
        files.append(target)
    return files[0], files[1]


def _plan_files(folder: Path) -> list[tuple[int, Path]]:
    found: list[tuple[int, Path]] = []
    for path in folder.iterdir():
        match = _PLAN_FILE.match(path.name)
        if match is not None:
            found.append((int(match.group(1) or 0), path))
    return sorted(found)


def _new_plans(folder: Path, seen: set[str], *, finished: bool) -> Iterator[Plan]:
    """Plans in files not read before; while the planner runs, only files it finished writing."""
    for _, path in _plan_files(folder):
        if path.name in seen:
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        if not finished and "; cost =" not in text:
            continue
        seen.add(path.name)
        yield parse_plan(text, path.name)


def _stop(process: subprocess.Popen[bytes]) -> None:
    """End the planner and its children (translator, search), politely first."""
    if process.poll() is not None:
        return
    for sig, wait in ((signal.SIGTERM, 2.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def _tail(folder: Path) -> str:
    for name in ("fd.err", "fd.log"):
        path = folder / name
        lines = path.read_text(encoding="utf-8", errors="replace").strip().splitlines() if path.exists() else []
        if lines:
            return "\n".join(lines[-_TAIL_LINES:])
    return "(no output)"


def _done(code: int | None, timed_out: bool, solved: bool, alias: str, expansions: int, folder: Path) -> Done:
    """The final event for Fast Downward's exit code."""
    if solved:
        optimal = alias.startswith("seq-opt") and code == 0
        note = "time limit reached" if timed_out or code in _OUT_OF_TIME or code in (2, 3) else ""
        return Done(PlanStatus.OPTIMAL if optimal else PlanStatus.SOLVED, expansions, note)
    if timed_out or code in _OUT_OF_TIME:
        return Done(PlanStatus.TIMEOUT, expansions, "time limit reached before Fast Downward found a plan")
    if code in _UNSOLVABLE:
        return Done(PlanStatus.UNSOLVABLE, expansions, "Fast Downward proved the task unsolvable")
    if code in _INCOMPLETE:
        return Done(PlanStatus.ERROR, expansions, f"Fast Downward's {alias} search is incomplete and found no plan")
    if code in _OUT_OF_MEMORY:
        return Done(PlanStatus.ERROR, expansions, "Fast Downward ran out of memory")
    if code in _PLAN_FOUND:
        return Done(PlanStatus.ERROR, expansions, f"Fast Downward exited with {code} but wrote no plan file")
    return Done(PlanStatus.ERROR, expansions, f"Fast Downward failed (exit code {code}):\n{_tail(folder)}")
