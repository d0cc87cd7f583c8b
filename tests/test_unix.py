"""Unix conventions: ``| head`` ends quietly, ``python -m alica`` works, make installs nothing outside the venv."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from alica import __version__

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    "argv", [["list-skills"], ["show", "alica:plans/lunar/mission.yaml"], ["validate", "alica:plans", "--help"]]
)
def test_a_reader_that_goes_away_ends_the_command_quietly(argv: list[str]) -> None:
    # the read end is closed before the command writes its first line: every write meets a broken pipe
    done = subprocess.Popen(
        [sys.executable, "-m", "alica", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT
    )
    assert done.stdout is not None and done.stderr is not None
    done.stdout.close()
    err = done.stderr.read().decode()
    assert done.wait(timeout=120) in (0, 141)  # 141 = 128 + SIGPIPE, what a shell shows
    assert err == ""  # no "Broken pipe" error, no "Exception ignored" at exit


def test_head_of_a_listing_gets_its_lines_and_no_error(tmp_path: Path) -> None:
    script = f"{sys.executable} -m alica list-skills | head -n 3"
    done = subprocess.run(["sh", "-c", script], capture_output=True, text=True, cwd=tmp_path, timeout=120, check=False)
    assert done.returncode == 0 and len(done.stdout.splitlines()) == 3 and done.stderr == ""


def test_python_dash_m_alica_is_the_alica_command(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "alica", "--version"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
        check=False,
    )
    assert (done.returncode, done.stdout.strip()) == (0, f"alica {__version__}")
    bad = subprocess.run(
        [sys.executable, "-m", "alica", "validate", "nowhere.yaml"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
        check=False,
    )
    assert bad.returncode == 1 and "nowhere.yaml:1:1: error: no such file or folder" in bad.stderr


def test_make_setup_and_test_install_nothing_outside_the_venv() -> None:
    for target in ("setup", "test", "demo", "test-fast"):
        plan = subprocess.run(
            ["make", "-n", "-B", target], capture_output=True, text=True, cwd=ROOT, timeout=60, check=False
        )
        assert plan.returncode == 0, plan.stderr
        assert "apt-get" not in plan.stdout and "sudo" not in plan.stdout, target
    # only when asked, and CI asks
    assert "apt-get" in subprocess.run(["make", "-n", "-B", "browser"], capture_output=True, text=True, cwd=ROOT).stdout
    assert "make browser" in (ROOT / ".ci" / "run").read_text(encoding="utf-8")
