"""The trace loader, and clear errors for bad input: a missing trace, a bad line, a bad plan file, a port in use."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.app.center.trace_file import load_trace
from alica.app.cli import main
from alica.errors import AlicaError


def test_a_recorded_trace_loads_in_time_order(recorded_trace: Path) -> None:
    trace = load_trace(recorded_trace)
    assert trace.meta["version"] == 2 and trace.roles  # alica run writes the header with the agents' roles
    assert trace.events
    times = [e["t"] for e in trace.events]
    assert times == sorted(times)


def test_the_header_line_is_meta_not_an_event(written_trace: Path) -> None:
    trace = load_trace(written_trace)
    assert trace.meta["version"] == 2
    assert all(e["event"] != "trace" for e in trace.events)
    assert sum(e["event"] == "pose" for e in trace.events) == 2


def test_a_line_that_is_not_json_names_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.jsonl"
    path.write_text('{"t": 0, "agent": "a", "event": "x"}\n{not json\n', encoding="utf-8")
    with pytest.raises(AlicaError, match=r"bad\.jsonl:2: error: not JSON"):
        load_trace(path)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("[1, 2]", "not an object"),
        ('{"t": 1}', "without agent, event"),
        ('{"event": "x", "agent": "a", "t": "soon"}', "not a number of seconds"),
    ],
)
def test_lines_without_the_needed_fields_are_refused(tmp_path: Path, line: str, message: str) -> None:
    path = tmp_path / "odd.jsonl"
    path.write_text(line + "\n", encoding="utf-8")
    with pytest.raises(AlicaError, match=rf"odd\.jsonl:1: error: .*{message}"):
        load_trace(path)


def test_the_command_reports_a_missing_trace_without_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["center", "--trace", str(tmp_path / "none.jsonl"), "--port", "0"]) == 1
    err = capsys.readouterr().err
    assert "none.jsonl: error: no such file" in err
    assert "Traceback" not in err


def test_the_command_reports_a_bad_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.jsonl"
    path.write_text("oops\n", encoding="utf-8")
    assert main(["center", "--trace", str(path), "--port", "0"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:1: error: not JSON")
    assert "Traceback" not in err


def test_the_command_reports_a_bad_plan_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("plans:\n  - name: P\n    states: [\n", encoding="utf-8")
    assert main(["center", "--plan", str(path), "--port", "0"]) == 1
    err = capsys.readouterr().err
    assert "broken.yaml:" in err
    assert "Traceback" not in err


def test_a_port_in_use_is_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    import socket

    from alica.io import plans_dir

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        plan = str(plans_dir() / "examples" / "formation.yaml")
        assert main(["center", "--plan", plan, "--port", str(port)]) == 1
    err = capsys.readouterr().err
    assert f"cannot listen on 127.0.0.1:{port}" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("port", ["70000", "-1", "http"])
def test_a_port_out_of_range_is_a_usage_error(port: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["center", "--plan", "plan.yaml", "--port", port]) == 2
    assert "is not a port" in capsys.readouterr().err
